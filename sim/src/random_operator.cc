#include "rms/sim/random_operator.h"

#include <algorithm>

namespace rms::sim {

RandomOperator::RandomOperator(const InputCalibrations& cal, std::uint64_t seed,
                               const RandomOperatorOptions& options)
    : cal_(cal), options_(options), rng_(seed), in_(wire::InitialInputs(cal)) {}

wire::OperatorInputs RandomOperator::Next() {
  std::uniform_real_distribution<double> u01(0, 1);
  std::normal_distribution<double> step(0, options_.step_fraction);
  wire::OperatorInputs out;
  for (int i = 0; i < kNumAnalogInputs; ++i) {
    const double lo = cal_[i].min, hi = cal_[i].max, range = hi - lo;
    double& v = in_.value[i];
    if (u01(rng_) < options_.jump_probability)
      v = lo + u01(rng_) * range;
    else
      v = std::clamp(v + step(rng_) * range, lo, hi);
    out.value[i] = v;
    if (u01(rng_) < options_.outside_probability)
      out.value[i] = (u01(rng_) < 0.5 ? lo : hi) + (u01(rng_) - 0.5) * 0.2 * range;
  }
  if (u01(rng_) < 0.001) in_.camera_station = 1 + static_cast<int>(u01(rng_) * 8) % 8;
  out.camera_station = in_.camera_station;
  out.reset = u01(rng_) < options_.reset_probability;
  out.overlay = true;
  return out;
}

}  // namespace rms::sim
