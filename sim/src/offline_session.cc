#include "rms/sim/offline_session.h"

#include "rms/dcp_frame_t.hpp"

namespace rms::sim {

OfflineSession::OfflineSession(const LabConfig& config, operator_station::Timeline timeline)
    : config_(config), timeline_(std::move(timeline)), program_(config) {
  for (int s = 0; s < kNumCameraStations; ++s)
    scenes_.push_back(std::make_unique<scene_proc::VisualSceneProgram>(config));
}

bool OfflineSession::Next() {
  t_ = static_cast<double>(frame_) / config_.session.frame_rate_hz;
  if (t_ > timeline_.end_time() + 1e-9) return false;
  inputs_ = timeline_.Sample(t_);
  inputs_.reset = timeline_.ResetIn(prev_t_, t_);
  prev_t_ = t_;
  wire::DcpFrameData out = program_.Step(inputs_);
  out.frame = frame_;
  dcp_frame_t wire;
  wire::PackDcpFrame(out, &wire, nullptr);
  dcp_ = wire::UnpackDcpFrame(wire);
  for (int s = 1; s <= kNumCameraStations; ++s) {
    wire::DcpFrameData d = dcp_;
    d.control.camera_station = s;
    esg_[s - 1] = wire::UnpackEsgWords(wire::PackEsgWords(
        scenes_[s - 1]->Step(d, static_cast<std::uint32_t>(frame_ & 0xFFFFFF), &scene_counters_),
        nullptr));
  }
  ++frame_;
  return true;
}

}  // namespace rms::sim
