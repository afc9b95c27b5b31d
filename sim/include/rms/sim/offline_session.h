#pragma once
// A session without a network: the Dynamic Collision Program and the Visual
// Scene Program run in process over a timeline, frame by frame, exactly as
// the processes would (the same libraries, the words packed and read back).
// One Visual Scene Program per camera station, so every frame can be seen
// from all eight. For tools (visibility, snapshots) and benchmarks.
#include <array>
#include <memory>

#include "rms/base/config.h"
#include "rms/base/counters.h"
#include "rms/dcp_model/dynamic_collision_program.h"
#include "rms/operator_station/timeline.h"
#include "rms/scene_proc/visual_scene_program.h"
#include "rms/wire/word_blocks.h"

namespace rms::sim {

class OfflineSession {
 public:
  OfflineSession(const LabConfig& config, operator_station::Timeline timeline);
  // The next frame; false after the timeline's end.
  bool Next();
  double t_s() const { return t_; }
  std::int64_t frame() const { return frame_ - 1; }
  const wire::OperatorInputs& inputs() const { return inputs_; }
  const wire::DcpFrameData& dcp() const { return dcp_; }
  const dcp_model::DcpStatus& status() const { return program_.status(); }
  // This frame's ESG frame from camera station s (1..8), as the ESG reads it.
  const wire::EsgFrameData& esg(int station) const { return esg_[station - 1]; }
  // ... from the station the timeline selected.
  const wire::EsgFrameData& esg() const { return esg(inputs_.camera_station); }
  // The Visual Scene Program that computes station s's frames.
  const scene_proc::VisualSceneProgram& scene(int station) const { return *scenes_[station - 1]; }
  // The Visual Scene Programs' counters, all eight stations summed
  // (e.g. "priority.unresolved": pairs no plane separated, 8 a frame).
  const Counters& scene_counters() const { return scene_counters_; }

 private:
  const LabConfig& config_;
  operator_station::Timeline timeline_;
  dcp_model::DynamicCollisionProgram program_;
  std::vector<std::unique_ptr<scene_proc::VisualSceneProgram>> scenes_;
  std::int64_t frame_ = 0;
  double t_ = 0, prev_t_ = -1;
  wire::OperatorInputs inputs_;
  wire::DcpFrameData dcp_;
  std::array<wire::EsgFrameData, kNumCameraStations> esg_{};
  Counters scene_counters_;
};

}  // namespace rms::sim
