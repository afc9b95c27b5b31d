#include "visual_scene.h"

#include <algorithm>
#include <spdlog/spdlog.h>

#include "rms/channels.h"
#include "rms/check.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/frame_receiver.h"
#include "rms/message_io.h"

namespace rms::scene {

VisualScene::VisualScene(const LabConfig& config)
    : config_(config), model_(BuildSceneModel(config)), planner_(model_),
      dt_s_(1.0 / config.session.frame_rate_hz) {}

namespace {
double Toward(double current, double target, double max_step) {
  return current + std::clamp(target - current, -max_step, max_step);
}
}  // namespace

EsgFrameData VisualScene::Step(const DcpFrameData& dcp, std::uint32_t frame_count, Counters* counters) {
  const int station = dcp.control.camera_station;
  const CameraStationConfig& cam = config_.cameras[station - 1];
  // The selected station's drive slews toward the command, clamped to its limits.
  double pan_cmd = dcp.camera_pan_deg, tilt_cmd = dcp.camera_tilt_deg;
  ClampPanTilt(cam, &pan_cmd, &tilt_cmd, counters);
  Drive& drv = drives_[station - 1];
  drv.pan_deg = Toward(drv.pan_deg, pan_cmd, cam.pan_rate_deg_s * dt_s_);
  drv.tilt_deg = Toward(drv.tilt_deg, tilt_cmd, cam.tilt_rate_deg_s * dt_s_);
  drv.zoom = Toward(drv.zoom, std::clamp(dcp.camera_zoom, 0.0, 1.0), cam.zoom_rate_per_s * dt_s_);

  const ArmPose arm = ComputeArmPose(config_.arm, dcp.arm, dcp.shoulder_height_ft);
  const CameraView view = ComputeCameraView(config_, station, drv.pan_deg, drv.tilt_deg, drv.zoom, arm, nullptr);
  EsgFrameData e;
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
  // Visual priority from the words as the ESG will read them.
  const EsgFrameData sent = UnpackEsgWords(PackEsgWords(e, nullptr));
  const ClusterPoses poses = ComputeClusterPoses(config_, sent);
  const PriorityBits bits = planner_.Compute(poses, sent.p_RoEye_R_ft, dcp.planes, dcp.plane_valid, counters);
  PackPriority(bits, &e.control, &e.priority_words);
  return e;
}

namespace {
// dcp_frame_t is fixed-size: 8 + 4 x 8 + (12 + 1 + 12 + 1 + 17) x 4.
constexpr int kMaxDcpSize = 8 + kSenderBytes + 32 + 43 * 4;
}  // namespace

SceneNode::SceneNode(const LabConfig& config, LcmInterface* lcm)
    : config_(config), lcm_(lcm), scene_(config) {
  lcm_->Subscribe(channels::kDcpFrame,
                  [this](const void* d, int n, std::int64_t t) { OnDcpFrame(d, n, t); });
}

void SceneNode::EnableLiveChecks(double frame_rate_hz) {
  dcp_frames_.SetClock(SessionFrameClock(frame_rate_hz));
  late_ = LateFrameFilter(frame_rate_hz);
}

void SceneNode::OnDcpFrame(const void* data, int size, std::int64_t recv_time_us) {
  const std::int64_t now_us = late_.enabled() ? lcm_->NowUs() : recv_time_us;
  auto got = ReceiveFrame<dcp_frame_t>(
      data, size, kMaxDcpSize, &dcp_frames_, &counters_, [](const dcp_frame_t& m) { return UnpackDcpFrame(m); },
      now_us, &late_);
  if (!got) return;
  const auto& [msg, dcp] = *got;
  counters_.Set("dcp.missing", dcp_frames_.missing());
  latencies_["dcp_to_scene"].Add(now_us - msg.send_time_us);
  RecordEndToEnd(now_us - msg.input_send_time_us, config_.session.frame_rate_hz, &latencies_["input_to_scene"],
                 &counters_);

  // An ESG frame is numbered as the DCP frame it answers (one to one), so
  // the numbering survives a restart of either process and the ESG counts
  // exactly the frames lost on the way (docs/protocol.md "Frame numbers").
  const std::int64_t frame = msg.frame;
  next_frame_ = frame + 1;
  const EsgFrameData e = scene_.Step(dcp, static_cast<std::uint32_t>(frame & 0xFFFFFF), &counters_);
  esg_frame_t out;
  out.frame = frame;
  out.dcp_frame = msg.frame;
  out.input_frame = msg.input_frame;
  out.input_send_time_us = msg.input_send_time_us;
  out.words = PackEsgWords(e, &counters_);
  RMS_CHECK(out.words.size() <= static_cast<std::size_t>(kEsgMaxWords));
  out.num_words = static_cast<std::int16_t>(out.words.size());
  out.send_time_us = lcm_->NowUs();
  if (PublishMessage(*lcm_, channels::kEsgFrame, out)) counters_.Add("published");
  else counters_.Add("publish_failed");
}

int RunSceneProc(const LabConfig& config, LcmInterface& lcm, const std::string& stats_path,
                 const std::string& ready_path) {
  SceneNode node(config, &lcm);
  node.EnableLiveChecks(config.session.frame_rate_hz);
  if (!ready_path.empty()) WriteReadyFile(ready_path);
  spdlog::info("ready: {} -> {}", lcm.FullChannel(channels::kDcpFrame),
               lcm.FullChannel(channels::kEsgFrame));
  RunNodeLoop(lcm, "scene_proc", node.counters(), node.latencies(),
              [&] { return node.last_frame(); }, nullptr, stats_path);
  spdlog::info("published {} ESG frames; DCP frames missing {}, late {}, dropped {}",
               node.counters().Get("published"), node.counters().Get("dcp.missing"),
               node.counters().Get("frames.late"), node.counters().SumPrefix("dropped."));
  return 0;
}

}  // namespace rms::scene
