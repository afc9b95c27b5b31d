#pragma once
// scene_proc's LCM side: RMS_DCP_FRAME in, RMS_ESG_FRAME out, one ESG frame
// per DCP frame, counters and latency (docs/scene.md, docs/protocol.md).
#include <cstdint>
#include <string>

#include "rms/base/config.h"
#include "rms/base/counters.h"
#include "rms/scene_proc/visual_scene_program.h"
#include "rms/transport/lcm_interface.h"
#include "rms/transport/process.h"
#include "rms/wire/frame_receiver.h"

namespace rms::scene_proc {

class SceneProc {
 public:
  SceneProc(const LabConfig& config, transport::LcmInterface* lcm);
  void OnDcpFrame(const void* data, int size, std::int64_t recv_time_us);
  const Counters& counters() const { return counters_; }
  Counters& counters() { return counters_; }
  const transport::LatencyMap& latencies() const { return latencies_; }
  std::int64_t last_frame() const { return next_frame_ - 1; }
  // A live session's receive checks (as DynamicsProc::EnableLiveChecks);
  // with late_drops false (a replay) a late frame is answered all the same.
  void EnableLiveChecks(double frame_rate_hz, bool late_drops = true);

 private:
  const LabConfig& config_;
  transport::LcmInterface* lcm_;
  VisualSceneProgram scene_;
  Counters counters_;
  transport::LatencyMap latencies_;
  wire::SequenceTracker dcp_frames_;
  wire::LateFrameFilter late_;
  std::int64_t next_frame_ = 0;
};

// every_frame: no DCP frame is dropped as late (scene_proc --every-frame).
int RunSceneProc(const LabConfig& config, transport::LcmInterface& lcm,
                 const std::string& stats_path, const std::string& ready_path,
                 bool every_frame = false);

}  // namespace rms::scene_proc
