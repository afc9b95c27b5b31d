#include "rms/base/analog_inputs.h"

namespace rms {

int AnalogInputIndex(std::string_view name) {
  for (int i = 0; i < kNumAnalogInputs; ++i) {
    if (kAnalogInputNames[i] == name) return i;
  }
  return -1;
}

}  // namespace rms
