#include "offline_session.h"

#include "rms/dcp_frame_t.hpp"

namespace rms::offline {

OfflineSession::OfflineSession(const LabConfig& config, op::Timeline timeline)
    : config_(config), timeline_(std::move(timeline)), program_(config) {
  for (int s = 0; s < kNumCameraStations; ++s) scenes_.push_back(std::make_unique<scene::VisualScene>(config));
}

bool OfflineSession::Next() {
  t_ = static_cast<double>(frame_) / config_.session.frame_rate_hz;
  if (t_ > timeline_.end_time() + 1e-9) return false;
  inputs_ = timeline_.Sample(t_);
  inputs_.reset = timeline_.ResetIn(prev_t_, t_);
  prev_t_ = t_;
  DcpFrameData out = program_.Step(inputs_);
  out.frame = frame_;
  dcp_frame_t wire;
  PackDcpFrame(out, &wire, nullptr);
  dcp_ = UnpackDcpFrame(wire);
  for (int s = 1; s <= kNumCameraStations; ++s) {
    DcpFrameData d = dcp_;
    d.control.camera_station = s;
    esg_[s - 1] = UnpackEsgWords(PackEsgWords(scenes_[s - 1]->Step(d, static_cast<std::uint32_t>(frame_ & 0xFFFFFF), &scene_counters_), nullptr));
  }
  ++frame_;
  return true;
}

}  // namespace rms::offline
