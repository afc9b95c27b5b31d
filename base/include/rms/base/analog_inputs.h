#pragma once
// The operator station's analog inputs (the report's Table I, reconstructed)
// and their calibrations, config [inputs.NAME]: the channels the input block
// carries (rms/wire/input_block.h) and the configuration calibrates
// (docs/config.md "[inputs.NAME]"; docs/protocol.md "RMS_OPERATOR_INPUT").
#include <array>
#include <string>
#include <string_view>

namespace rms {

enum AnalogInput : int {
  kShoulderYaw = 0,  // theta1, deg
  kShoulderPitch,    // theta2, deg
  kElbowPitch,       // theta3, deg
  kWristPitch,       // theta4, deg
  kWristYaw,         // theta5, deg
  kWristRoll,        // theta6, deg
  kFinger,           // finger lever, 0 = fully open .. 1 = fully closed
  kShoulderHeight,   // vertical fixed arm length, ft
  kCameraPan,        // deg
  kCameraTilt,       // deg
  kCameraZoom,       // zoom lever, 0 = widest .. 1 = narrowest
  kNumAnalogInputs
};

// Names used in config [inputs.NAME], timelines and counters.
inline constexpr std::array<std::string_view, kNumAnalogInputs> kAnalogInputNames = {
    "shoulder_yaw", "shoulder_pitch",  "elbow_pitch", "wrist_pitch", "wrist_yaw",  "wrist_roll",
    "finger",       "shoulder_height", "camera_pan",  "camera_tilt", "camera_zoom"};

// The arm's joints: the first six inputs, in the report's order (theta1 ..
// theta6). Their count and names live here once; the wire's malfunctions,
// the report and the pages use these.
inline constexpr int kNumJoints = kWristRoll + 1;
inline constexpr std::array<std::string_view, kNumJoints> kJointNames = {
    "shoulder yaw", "shoulder pitch", "elbow pitch", "wrist pitch", "wrist yaw", "wrist roll"};

// Whether each joint's name is its input's with a space for the '_'.
constexpr bool JointNamesMatchInputs() {
  for (int j = 0; j < kNumJoints; ++j) {
    const std::string_view a = kJointNames[j], b = kAnalogInputNames[j];
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (a[i] != (b[i] == '_' ? ' ' : b[i])) return false;
  }
  return true;
}
static_assert(JointNamesMatchInputs(), "kJointNames must follow kAnalogInputNames");

// Returns the index of the named input, or -1.
int AnalogInputIndex(std::string_view name);

// One analog channel's calibration (config [inputs.NAME]).
struct InputCalibration {
  std::string unit;              // "deg", "ft" or "1"
  double units_per_count = 1.0;  // scale, unit per ADC count (non-zero)
  double zero_count = 0.0;       // counts that read as value 0
  double min = 0.0, max = 0.0;   // accepted range; values outside are clamped and reported
  double initial = 0.0;          // value a timeline starts from when it never sets the channel
};
using InputCalibrations = std::array<InputCalibration, kNumAnalogInputs>;

}  // namespace rms
