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
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "rms/base/analog_inputs.h"
#include "rms/base/counters.h"

namespace rms::wire {

inline constexpr int kInputWords = 12;
inline constexpr int kDiscreteWordIndex = 11;

// Discrete word (word 11) bits. Bits 6-23 are reserved and must be zero.
inline constexpr std::uint32_t kDiscreteCameraMask = 0x7;  // bits 0-2: camera station - 1
inline constexpr std::uint32_t kDiscreteReset = 1u << 3;   // reset pushbutton (momentary)
inline constexpr std::uint32_t kDiscreteOverlay =
    1u << 4;  // overlay switch (frame counter, indicators)
inline constexpr std::uint32_t kDiscreteCrosshairs =
    1u << 5;  // crosshairs switch (wrist and port cameras)
inline constexpr std::uint32_t kDiscreteReservedMask = 0xFFFFC0u;

// The operator's inputs in engineering units.
struct OperatorInputs {
  std::array<double, kNumAnalogInputs> value{};  // units of each channel's calibration
  int camera_station = 1;                        // 1..8
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

// The inputs as JSON (checkpoints, the DCP's delayed inputs): each channel
// by its name, the camera station, the reset, overlay and crosshairs
// switches; doubles exact. InputsFromJson throws rms::InputError naming a
// missing or bad key (an absent switch reads as off; the overlay as on).
nlohmann::ordered_json InputsJson(const OperatorInputs& in);
OperatorInputs InputsFromJson(const nlohmann::json& j);

}  // namespace rms::wire
