// RMS_DCP_FRAME into scene_proc's node (SafeDecode, UnpackDcpFrame's word
// checks, frame numbers, the Visual Scene Program's step and the ESG
// frame's packing).
#include "rms/scene_proc/scene_proc.h"
#include "rms/wire/channels.h"

#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const rms::LabConfig& config = rms::fuzz::Config();
  // One node for the run (building the scene model is slow): its frame
  // numbers and drives carry over from input to input, as in a session.
  static rms::transport::LogLcm lcm("", "");
  static rms::scene_proc::SceneProc node(config, &lcm);
  node.OnDcpFrame(data, static_cast<int>(size), 0);
  node.OnDcpFrame(data, static_cast<int>(size), 0);  // the same again: a duplicate
  lcm.HandleSubscriptions(0);                        // what it published, discarded
  return 0;
}
