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
