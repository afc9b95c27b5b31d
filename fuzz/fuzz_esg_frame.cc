// RMS_ESG_FRAME into esg_renderer's node (SafeDecode, the word count,
// UnpackEsgWords's checks, frame numbers). Rendering is not fuzzed: the
// node queues the unpacked frame and the renderer draws only what passed.
#include "rms/esg_renderer/esg_renderer.h"

#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const rms::LabConfig& config = rms::fuzz::Config();
  rms::transport::LogLcm lcm("", "");
  rms::esg_renderer::EsgRenderer node(config, &lcm, nullptr, {}, nullptr, nullptr);
  node.OnFrame(data, static_cast<int>(size), 0);
  return 0;
}
