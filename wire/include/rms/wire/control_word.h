#pragma once
// The scene generator control word: the report's Table II, reconstructed.
// docs/protocol.md "The control word" is the one description.
//
//  bits 0-2   CAMERA    camera station - 1                        (DCP, from the inputs)
//  bit  3     RESET     reset pushbutton seen this frame          (DCP, from the inputs)
//  bit  4     OVERLAY   draw frame counter and indicators         (DCP, from the inputs)
//  bit  5     CROSSHAIRS draw the wrist and port cameras' crosshairs (DCP, from the inputs)
//  bit  6     NO VIDEO  the selected camera station is lost: no picture (DCP, a malfunction)
//  bit  7     reserved, zero
//  bits 8-9   MODE      1 acquisition, 2 extraction, 3 manoeuvring (DCP-generated)
//  bit  10    COLLISION a detrimental collision this frame         (DCP-generated)
//  bit  11    RECPT     end effector in collision with the receptacle (DCP-generated)
//  bit  12    ACQUIRED  the six acquisition conditions hold        (DCP-generated)
//  bit  13    DOCKED    probe in the docking envelope and aligned  (DCP-generated)
//  bits 14-16 PRIORITY_DYNAMIC  viewpoint side of dynamic planes 1-3 (scene_proc)
//  bits 17-23 PRIORITY_FIXED    viewpoint side of fixed planes 1-7   (scene_proc)
#include <cstdint>

#include "rms/base/config.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/word_codec.h"

namespace rms::wire {

// The fields' widths, tied to the quantities they carry: a ninth camera
// station or a fourth mode does not fit the word as the report drew it
// (docs/architecture.md "Adding a camera station").
inline constexpr int kCameraStationBits = 3;
inline constexpr int kModeBits = 2;
static_assert(kNumCameraStations <= (1 << kCameraStationBits),
              "the control word's CAMERA field (bits 0-2) carries station - 1");
static_assert(kNumDcpModes < (1 << kModeBits), "the MODE field (bits 8-9) carries 1..3");

struct ControlWord {
  int camera_station = 1;  // 1..8
  bool reset = false;
  bool overlay = false;
  bool crosshairs = false;
  bool no_video = false;  // docs/sessions.md "Malfunctions": camera station lost
  int mode = 1;           // 1..3
  bool collision = false;
  bool receptacle_collision = false;
  bool acquired = false;
  bool docked = false;
  std::uint32_t priority_dynamic = 0;  // 3 bits
  std::uint32_t priority_fixed = 0;    // 7 bits

  bool operator==(const ControlWord&) const = default;
};

namespace control_bits {
inline constexpr std::uint32_t kCameraShift = 0, kCameraMask = (1u << kCameraStationBits) - 1;
inline constexpr std::uint32_t kReset = 1u << 3;
inline constexpr std::uint32_t kOverlay = 1u << 4;
inline constexpr std::uint32_t kCrosshairs = 1u << 5;
inline constexpr std::uint32_t kNoVideo = 1u << 6;
inline constexpr std::uint32_t kReservedMask = 0x1u << 7;
inline constexpr std::uint32_t kModeShift = 8, kModeMask = (1u << kModeBits) - 1;
inline constexpr std::uint32_t kCollision = 1u << 10;
inline constexpr std::uint32_t kReceptacle = 1u << 11;
inline constexpr std::uint32_t kAcquired = 1u << 12;
inline constexpr std::uint32_t kDocked = 1u << 13;
inline constexpr std::uint32_t kPriorityDynamicShift = 14, kPriorityDynamicMask = 0x7;
inline constexpr std::uint32_t kPriorityFixedShift = 17, kPriorityFixedMask = 0x7F;
}  // namespace control_bits

// Packs; an out-of-range field is an invariant breach (RMS_CHECK).
wire::Word PackControlWord(const ControlWord& cw);
// Unpacks; throws rms::InputError for bits above 23, reserved bits set or mode 0.
ControlWord UnpackControlWord(std::int32_t carried);

}  // namespace rms::wire
