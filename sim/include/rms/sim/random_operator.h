#pragma once
// A random operator for soaks and stress (docs/performance.md "Numerical
// stability"): each frame every analog channel takes a random step (a random
// walk whose step is step_fraction of the channel's range, with a jump to a
// random value now and then), sometimes pushed past its limits (to be
// clamped), the camera station changes, reset is pressed rarely. Seeded, no
// global generator.
#include <cstdint>
#include <random>

#include "rms/wire/input_block.h"

namespace rms::sim {

struct RandomOperatorOptions {
  double step_fraction = 0.01;  // a frame's step, standard deviation, as a fraction of the range
  double jump_probability = 0.002;     // a channel jumps to a uniform random value
  double outside_probability = 0.001;  // a channel is sent past its range by up to 10 %
  double reset_probability = 0.0005;   // the reset pushbutton
};

class RandomOperator {
 public:
  RandomOperator(const InputCalibrations& cal, std::uint64_t seed,
                 const RandomOperatorOptions& options = {});
  wire::OperatorInputs Next();

 private:
  InputCalibrations cal_;
  RandomOperatorOptions options_;
  std::mt19937_64 rng_;
  wire::OperatorInputs in_;
};

}  // namespace rms::sim
