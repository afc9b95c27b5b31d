#include "rms/wire/input_block.h"

#include <algorithm>
#include <cmath>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/wire/word_codec.h"

namespace rms::wire {

// The input block's camera field (bits 0-2 of the discrete word) carries
// station - 1: the stations' one count must fit it (docs/architecture.md
// "Adding a camera station").
static_assert(kNumCameraStations <= static_cast<int>(kDiscreteCameraMask) + 1,
              "the input block's camera field is 3 bits");

OperatorInputs InitialInputs(const InputCalibrations& cal) {
  OperatorInputs in;
  for (int i = 0; i < kNumAnalogInputs; ++i) in.value[i] = cal[i].initial;
  return in;
}

namespace {

double ClampCounted(double v, double lo, double hi, Counter counter, Counters* c) {
  if (v < lo || v > hi) {
    if (c) c->Add(counter);
    return std::clamp(v, lo, hi);
  }
  return v;
}

}  // namespace

std::array<std::int32_t, kInputWords> EncodeInputs(const OperatorInputs& in,
                                                   const InputCalibrations& cal,
                                                   Counters* counters) {
  std::array<std::int32_t, kInputWords> words{};
  for (int i = 0; i < kNumAnalogInputs; ++i) {
    double v = in.value[i];
    if (!std::isfinite(v))
      throw InputError("input '" + std::string(kAnalogInputNames[i]) + "' is not a finite number");
    v = ClampCounted(v, cal[i].min, cal[i].max, ClampedCounter(i), counters);
    const double counts = v / cal[i].units_per_count + cal[i].zero_count;
    const wire::Encoded e = wire::Encode(wire::kADC16, counts);
    if (e.saturated && counters) counters->Add(ClampedAdcCounter(i));
    words[i] = static_cast<std::int32_t>(e.word);
  }
  int station = in.camera_station;
  if (station < 1 || station > kNumCameraStations) {
    if (counters) counters->Add(Counter::kClampedCameraStation);
    station = std::clamp(station, 1, kNumCameraStations);
  }
  std::uint32_t d = static_cast<std::uint32_t>(station - 1) & kDiscreteCameraMask;
  if (in.reset) d |= kDiscreteReset;
  if (in.overlay) d |= kDiscreteOverlay;
  if (in.crosshairs) d |= kDiscreteCrosshairs;
  words[kDiscreteWordIndex] = static_cast<std::int32_t>(d);
  return words;
}

OperatorInputs DecodeInputs(const std::array<std::int32_t, kInputWords>& words,
                            const InputCalibrations& cal, Counters* counters) {
  const int bad = wire::FirstInvalidWord(words);
  if (bad >= 0) {
    throw InputError("input word " + std::to_string(bad) + " = " + wire::FormatWord(words[bad]) +
                     " has bits above bit 23 set");
  }
  const std::uint32_t d = static_cast<std::uint32_t>(words[kDiscreteWordIndex]);
  if (d & kDiscreteReservedMask) {
    throw InputError("input discrete word " + wire::FormatWord(words[kDiscreteWordIndex]) +
                     " has reserved bits 6-23 set");
  }
  OperatorInputs in;
  for (int i = 0; i < kNumAnalogInputs; ++i) {
    std::int32_t counts = wire::ToSigned(static_cast<wire::Word>(words[i]));
    if (counts < wire::kADC16.raw_min || counts > wire::kADC16.raw_max) {
      if (counters) counters->Add(ClampedAdcCounter(i));
      counts = std::clamp(counts, wire::kADC16.raw_min, wire::kADC16.raw_max);
    }
    const double v = (counts - cal[i].zero_count) * cal[i].units_per_count;
    // Half a count of slack: a value encoded at the range's end reads back
    // within rounding of it and is not a clamp.
    const double slack = 0.5 * std::abs(cal[i].units_per_count);
    if (v < cal[i].min - slack || v > cal[i].max + slack) {
      if (counters) counters->Add(ClampedCounter(i));
    }
    in.value[i] = std::clamp(v, cal[i].min, cal[i].max);
  }
  in.camera_station = static_cast<int>(d & kDiscreteCameraMask) + 1;
  in.reset = (d & kDiscreteReset) != 0;
  in.overlay = (d & kDiscreteOverlay) != 0;
  in.crosshairs = (d & kDiscreteCrosshairs) != 0;
  return in;
}

nlohmann::ordered_json InputsJson(const OperatorInputs& in) {
  nlohmann::ordered_json j;
  for (int i = 0; i < kNumAnalogInputs; ++i) j[std::string(kAnalogInputNames[i])] = in.value[i];
  j["camera_station"] = in.camera_station;
  j["reset"] = in.reset;
  j["overlay"] = in.overlay;
  j["crosshairs"] = in.crosshairs;
  return j;
}

OperatorInputs InputsFromJson(const nlohmann::json& j) {
  OperatorInputs in;
  try {
    for (int i = 0; i < kNumAnalogInputs; ++i) {
      in.value[i] = j.at(std::string(kAnalogInputNames[i])).get<double>();
      if (!std::isfinite(in.value[i])) {
        throw InputError("input '" + std::string(kAnalogInputNames[i]) + "' is not finite");
      }
    }
    in.camera_station = j.at("camera_station").get<int>();
    in.reset = j.value("reset", false);  // absent in checkpoints before the delayed inputs
    in.overlay = j.value("overlay", true);
    in.crosshairs = j.value("crosshairs", false);  // absent before the crosshairs switch
  } catch (const nlohmann::json::exception& e) {
    std::string why = e.what();
    if (why.rfind("[json.exception.", 0) == 0 && why.find("] ") != std::string::npos)
      why = why.substr(why.find("] ") + 2);
    throw InputError("operator inputs: " + why);
  }
  if (in.camera_station < 1 || in.camera_station > kNumCameraStations)
    throw InputError("operator inputs: camera_station must be 1.." +
                     std::to_string(kNumCameraStations));
  return in;
}

}  // namespace rms::wire
