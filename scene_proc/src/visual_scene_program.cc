#include "rms/scene_proc/visual_scene_program.h"

#include <algorithm>
#include <spdlog/spdlog.h>

#include "rms/base/check.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/wire/channels.h"
#include "rms/wire/frame_receiver.h"
#include "rms/wire/message_io.h"
#include "rms/wire/priority_words.h"

namespace rms::scene_proc {

VisualSceneProgram::VisualSceneProgram(const LabConfig& config)
    : config_(config),
      model_(scene_model::BuildSceneModel(config)),
      planner_(model_),
      dt_s_(1.0 / config.session.frame_rate_hz) {}

namespace {
double Toward(double current, double target, double max_step) {
  return current + std::clamp(target - current, -max_step, max_step);
}
}  // namespace

int VisualSceneProgram::DriveSteps(std::int64_t dcp_frame) {
  const std::int64_t since = last_frame_ ? dcp_frame - *last_frame_ : 1;
  last_frame_ = dcp_frame;
  // A restore or a restart that numbers afresh (backward, or further on
  // than a drive could take to slew anywhere): one frame's.
  const auto most = static_cast<std::int64_t>(kMostCatchUp_s / dt_s_);
  return since >= 1 && since <= most ? static_cast<int>(since) : 1;
}

void VisualSceneProgram::Slew(const CameraStationConfig& cam, double pan_cmd, double tilt_cmd,
                              double zoom_cmd, int steps, Drive* drv) const {
  for (int k = 0; k < steps; ++k) {
    if (drv->pan_deg == pan_cmd && drv->tilt_deg == tilt_cmd && drv->zoom == zoom_cmd) return;
    drv->pan_deg = Toward(drv->pan_deg, pan_cmd, cam.pan_rate_deg_s * dt_s_);
    drv->tilt_deg = Toward(drv->tilt_deg, tilt_cmd, cam.tilt_rate_deg_s * dt_s_);
    drv->zoom = Toward(drv->zoom, zoom_cmd, cam.zoom_rate_per_s * dt_s_);
  }
}

wire::EsgFrameData VisualSceneProgram::Step(const wire::DcpFrameData& dcp,
                                            std::uint32_t frame_count, Counters* counters) {
  const int station = dcp.control.camera_station;
  const CameraStationConfig& cam = config_.cameras[station - 1];
  // The selected station's drive slews toward the command, clamped to its limits.
  double pan_cmd = dcp.camera_pan_deg, tilt_cmd = dcp.camera_tilt_deg;
  ClampPanTilt(cam, &pan_cmd, &tilt_cmd, counters);
  // The drive runs in session time: a DCP frame that never came (lost on
  // the way, refused as late) is a frame's slew made up with the next one's
  // command, step by step as if it had come with it, so a scene that missed
  // frames (live, or in a replay) agrees with one that had them all once the
  // command holds (docs/scene.md "Camera drives").
  Drive& drv = drives_[station - 1];
  Slew(cam, pan_cmd, tilt_cmd, std::clamp(dcp.camera_zoom, 0.0, 1.0), DriveSteps(dcp.frame), &drv);

  const arm::ArmPose arm = arm::ComputeArmPose(config_.arm, dcp.arm, dcp.shoulder_height_ft);
  const CameraView view =
      ComputeCameraView(config_, station, drv.pan_deg, drv.tilt_deg, drv.zoom, arm, nullptr);
  wire::EsgFrameData e;
  e.frame_count = frame_count;
  e.control = dcp.control;
  e.arm = dcp.arm;
  e.shoulder_height_ft = dcp.shoulder_height_ft;
  e.finger_gap_ft = dcp.finger_gap_ft;
  e.p_RoEye_R_ft = view.p_RoEye_R_ft;
  e.R_RE = view.R_RE;
  e.fov_deg = view.fov_deg;
  e.p_RoPo_R_ft = dcp.p_RoPo_R_ft;
  e.R_RP = dcp.R_RP;
  // A lost station (NO VIDEO, docs/sessions.md "Malfunctions") shows no
  // picture: no priority to compute.
  if (e.control.no_video) return e;
  // Visual priority from the words as the ESG will read them.
  const wire::EsgFrameData sent = wire::UnpackEsgWords(wire::PackEsgWords(e, nullptr));
  const scene_model::ClusterPoses poses =
      scene_model::ComputeClusterPoses(config_, sent.scene_pose());
  const scene_model::PriorityBits bits =
      planner_.Compute(poses, sent.p_RoEye_R_ft, dcp.planes, dcp.plane_valid, counters);
  wire::PackPriority(bits, &e.control, &e.priority_words);
  return e;
}

}  // namespace rms::scene_proc
