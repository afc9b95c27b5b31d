#pragma once
// The VISUAL SCENE PROGRAM (the report's lost Section V; docs/scene.md): from
// each DCP frame it computes the selected camera's view and packs the ESG
// frame (at most 64 twenty-four-bit words).
#include <cstdint>
#include <string>

#include "camera_stations.h"
#include "rms/config.h"
#include "rms/priority.h"
#include "rms/scene_model.h"
#include "rms/counters.h"
#include "rms/frame_receiver.h"
#include "rms/lcm_interface.h"
#include "rms/process.h"
#include "rms/word_blocks.h"

namespace rms::scene {

// The Visual Scene Program's state: each station's camera drive (pan, tilt,
// zoom slewing toward the operator's command at the station's rates) and the
// separating planes of visual priority.
class VisualScene {
 public:
  explicit VisualScene(const LabConfig& config);
  // One frame: the ESG frame's content for this DCP frame, priority bits
  // included. Deterministic: the drives advance 1 / frame_rate a frame.
  EsgFrameData Step(const DcpFrameData& dcp, std::uint32_t frame_count, Counters* counters);

  struct Drive {
    double pan_deg = 0, tilt_deg = 0, zoom = 0;
  };
  const Drive& drive(int station) const { return drives_[station - 1]; }
  const SceneModel& model() const { return model_; }
  const PriorityPlanner& planner() const { return planner_; }

 private:
  const LabConfig& config_;
  SceneModel model_;
  PriorityPlanner planner_;
  std::array<Drive, kNumCameraStations> drives_{};
  double dt_s_;
};

class SceneNode {
 public:
  SceneNode(const LabConfig& config, LcmInterface* lcm);
  void OnDcpFrame(const void* data, int size, std::int64_t recv_time_us);
  const Counters& counters() const { return counters_; }
  Counters& counters() { return counters_; }
  const LatencyMap& latencies() const { return latencies_; }
  std::int64_t last_frame() const { return next_frame_ - 1; }
  // A live session's receive checks (as DcpNode::EnableLiveChecks).
  void EnableLiveChecks(double frame_rate_hz);

 private:
  const LabConfig& config_;
  LcmInterface* lcm_;
  VisualScene scene_;
  Counters counters_;
  LatencyMap latencies_;
  SequenceTracker dcp_frames_;
  LateFrameFilter late_;
  std::int64_t next_frame_ = 0;
};

int RunSceneProc(const LabConfig& config, LcmInterface& lcm, const std::string& stats_path,
                 const std::string& ready_path);

}  // namespace rms::scene
