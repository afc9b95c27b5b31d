#include "rms/wire/control_word.h"

#include "rms/base/check.h"

namespace rms::wire {

using namespace control_bits;

wire::Word PackControlWord(const ControlWord& cw) {
  RMS_CHECK(cw.camera_station >= 1 && cw.camera_station <= kNumCameraStations);
  RMS_CHECK(DcpModeOf(cw.mode) != nullptr);
  RMS_CHECK(cw.priority_dynamic <= kPriorityDynamicMask);
  RMS_CHECK(cw.priority_fixed <= kPriorityFixedMask);
  std::uint32_t w = static_cast<std::uint32_t>(cw.camera_station - 1) << kCameraShift;
  if (cw.reset) w |= kReset;
  if (cw.overlay) w |= kOverlay;
  if (cw.crosshairs) w |= kCrosshairs;
  if (cw.no_video) w |= kNoVideo;
  w |= static_cast<std::uint32_t>(cw.mode) << kModeShift;
  if (cw.collision) w |= kCollision;
  if (cw.receptacle_collision) w |= kReceptacle;
  if (cw.acquired) w |= kAcquired;
  if (cw.docked) w |= kDocked;
  w |= cw.priority_dynamic << kPriorityDynamicShift;
  w |= cw.priority_fixed << kPriorityFixedShift;
  return w;
}

ControlWord UnpackControlWord(std::int32_t carried) {
  if (!wire::IsValidWord(carried)) {
    throw InputError("control word " + wire::FormatWord(carried) + " has bits above bit 23 set");
  }
  const auto w = static_cast<std::uint32_t>(carried);
  if (w & kReservedMask) {
    throw InputError("control word " + wire::FormatWord(carried) + " has reserved bit 7 set");
  }
  ControlWord cw;
  cw.camera_station = static_cast<int>((w >> kCameraShift) & kCameraMask) + 1;
  cw.reset = w & kReset;
  cw.overlay = w & kOverlay;
  cw.crosshairs = w & kCrosshairs;
  cw.no_video = w & kNoVideo;
  cw.mode = static_cast<int>((w >> kModeShift) & kModeMask);
  if (cw.mode == 0) {
    throw InputError("control word " + wire::FormatWord(carried) + " has mode 0 (must be 1-3)");
  }
  cw.collision = w & kCollision;
  cw.receptacle_collision = w & kReceptacle;
  cw.acquired = w & kAcquired;
  cw.docked = w & kDocked;
  cw.priority_dynamic = (w >> kPriorityDynamicShift) & kPriorityDynamicMask;
  cw.priority_fixed = (w >> kPriorityFixedShift) & kPriorityFixedMask;
  return cw;
}

}  // namespace rms::wire
