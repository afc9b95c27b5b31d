// RMS_OPERATOR_INPUT into dynamics_proc's node (SafeDecode, the input
// block's checks, frame numbers, the DCP's step). The fuzzer's bytes are
// split into up to four messages at 0xFF 0xFE separators, so sequences
// (stale frame numbers, duplicates) are explored too.
#include <cstring>

#include "rms/dynamics_proc/dynamics_proc.h"
#include "rms/wire/channels.h"

#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const rms::LabConfig& config = rms::fuzz::Config();
  rms::transport::LogLcm lcm("", "");
  rms::dynamics_proc::DynamicsProc node(config, &lcm);
  std::size_t start = 0;
  for (int k = 0; k < 4 && start <= size; ++k) {
    std::size_t end = start;
    while (end + 1 < size && !(data[end] == 0xFF && data[end + 1] == 0xFE)) ++end;
    if (end + 1 >= size) end = size;
    lcm.Publish(rms::wire::channels::kOperatorInput, data + start, static_cast<int>(end - start));
    lcm.HandleSubscriptions(0);
    start = end + 2;
  }
  return 0;
}
