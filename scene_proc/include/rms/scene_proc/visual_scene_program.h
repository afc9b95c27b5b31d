#pragma once
// The VISUAL SCENE PROGRAM (the report's lost Section V; docs/scene.md): from
// each DCP frame it computes the selected camera's view and packs the ESG
// frame (at most 64 twenty-four-bit words).
#include <array>
#include <cstdint>
#include <optional>
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
  // included. Deterministic: the drive advances 1 / frame_rate for each
  // frame number since the last frame stepped (a frame lost on the way is
  // made up), one step after a restore or a restart that numbers afresh.
  wire::EsgFrameData Step(const wire::DcpFrameData& dcp, std::uint32_t frame_count,
                          Counters* counters);

  struct Drive {
    double pan_deg = 0, tilt_deg = 0, zoom = 0;
  };
  const Drive& drive(int station) const { return drives_[station - 1]; }
  const scene_model::SceneModel& model() const { return model_; }
  const PriorityPlanner& planner() const { return planner_; }

 private:
  // Frames since the last one stepped further on than this are a fresh
  // numbering, not a gap: a drive slews anywhere in less.
  static constexpr double kMostCatchUp_s = 60.0;
  // The drive's steps for DCP frame `dcp_frame` (and it is the last one).
  int DriveSteps(std::int64_t dcp_frame);
  // `steps` frames of slew toward the commands, clamped at the station's rates.
  void Slew(const CameraStationConfig& cam, double pan_cmd, double tilt_cmd, double zoom_cmd,
            int steps, Drive* drv) const;

  const LabConfig& config_;
  scene_model::SceneModel model_;
  PriorityPlanner planner_;
  std::array<Drive, kNumCameraStations> drives_{};
  double dt_s_;
  std::optional<std::int64_t> last_frame_;  // the DCP frame last stepped
};

}  // namespace rms::scene_proc
