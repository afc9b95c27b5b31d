#pragma once
// The operator station's input block: the report's Table I, reconstructed.
// docs/protocol.md "RMS_OPERATOR_INPUT" is the one description.
//
// Words 0-10 are analog inputs as ADC counts (format ADC16); the DCP scales
// them with each channel's calibration (config [inputs.NAME]):
//   value = (counts - zero_count) * units_per_count, clamped to [min, max].
// Word 11 holds the discrete inputs.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "rms/counters.h"

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

inline constexpr int kInputWords = 12;
inline constexpr int kDiscreteWordIndex = 11;

// Names used in config [inputs.NAME], timelines and counters.
inline constexpr std::array<std::string_view, kNumAnalogInputs> kAnalogInputNames = {
    "shoulder_yaw", "shoulder_pitch", "elbow_pitch", "wrist_pitch", "wrist_yaw", "wrist_roll",
    "finger",       "shoulder_height", "camera_pan", "camera_tilt", "camera_zoom"};

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

// Discrete word (word 11) bits. Bits 6-23 are reserved and must be zero.
inline constexpr std::uint32_t kDiscreteCameraMask = 0x7;  // bits 0-2: camera station - 1
inline constexpr std::uint32_t kDiscreteReset = 1u << 3;    // reset pushbutton (momentary)
inline constexpr std::uint32_t kDiscreteOverlay = 1u << 4;  // overlay switch (frame counter, indicators)
inline constexpr std::uint32_t kDiscreteCrosshairs = 1u << 5;  // crosshairs switch (wrist and port cameras)
inline constexpr std::uint32_t kDiscreteReservedMask = 0xFFFFC0u;

// The operator's inputs in engineering units.
struct OperatorInputs {
  std::array<double, kNumAnalogInputs> value{};  // units of each channel's calibration
  int camera_station = 1;                         // 1..8
  bool reset = false;
  bool overlay = true;
  bool crosshairs = false;
};

// The initial inputs: each channel's calibration.initial, camera 1.
OperatorInputs InitialInputs(const InputCalibrations& cal);

// Engineering units -> words (operator_station). Values outside a channel's
// [min, max] are clamped and counted in "clamped.NAME"; the camera station
// outside 1..8 is clamped and counted in "clamped.camera_station".
std::array<std::int32_t, kInputWords> EncodeInputs(const OperatorInputs& in,
                                                   const InputCalibrations& cal,
                                                   Counters* counters);

// Words -> engineering units (dynamics_proc). Throws rms::InputError for a
// word with bits above bit 23 or reserved discrete bits set (the block is
// malformed). Counts outside ADC16 are clamped ("clamped.adc.NAME"); values
// outside [min, max] are clamped ("clamped.NAME").
OperatorInputs DecodeInputs(const std::array<std::int32_t, kInputWords>& words,
                            const InputCalibrations& cal, Counters* counters);

}  // namespace rms
