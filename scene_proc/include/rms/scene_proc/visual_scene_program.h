#pragma once
// The VISUAL SCENE PROGRAM (the report's lost Section V; docs/scene.md): from
// each DCP frame it computes the selected camera's view and packs the ESG
// frame (at most 64 twenty-four-bit words).
#include <cstdint>
#include <string>

#include "rms/base/config.h"
#include "rms/base/counters.h"
#include "rms/scene_model/scene_model.h"
#include "rms/scene_proc/camera_stations.h"
#include "rms/scene_proc/priority_planner.h"
#include "rms/wire/word_blocks.h"

namespace rms::scene_proc {

// The Visual Scene Program's state: each station's camera drive (pan, tilt,
// zoom slewing toward the operator's command at the station's rates) and the
// separating planes of visual priority.
class VisualSceneProgram {
 public:
  explicit VisualSceneProgram(const LabConfig& config);
  // One frame: the ESG frame's content for this DCP frame, priority bits
  // included. Deterministic: the drives advance 1 / frame_rate a frame.
  wire::EsgFrameData Step(const wire::DcpFrameData& dcp, std::uint32_t frame_count,
                          Counters* counters);

  struct Drive {
    double pan_deg = 0, tilt_deg = 0, zoom = 0;
  };
  const Drive& drive(int station) const { return drives_[station - 1]; }
  const scene_model::SceneModel& model() const { return model_; }
  const PriorityPlanner& planner() const { return planner_; }

 private:
  const LabConfig& config_;
  scene_model::SceneModel model_;
  PriorityPlanner planner_;
  std::array<Drive, kNumCameraStations> drives_{};
  double dt_s_;
};

}  // namespace rms::scene_proc
