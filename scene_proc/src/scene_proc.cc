#include "rms/scene_proc/scene_proc.h"

#include <spdlog/spdlog.h>

#include "rms/base/check.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/wire/channels.h"
#include "rms/wire/frame_receiver.h"
#include "rms/wire/message_io.h"

namespace rms::scene_proc {

SceneProc::SceneProc(const LabConfig& config, transport::LcmInterface* lcm)
    : config_(config), lcm_(lcm), scene_(config) {
  lcm_->Subscribe(wire::channels::kDcpFrame,
                  [this](const void* d, int n, std::int64_t t) { OnDcpFrame(d, n, t); });
}

void SceneProc::EnableLiveChecks(double frame_rate_hz, bool late_drops) {
  dcp_frames_.SetClock(transport::SessionFrameClock(frame_rate_hz));
  if (late_drops) late_ = wire::LateFrameFilter(frame_rate_hz);
}

void SceneProc::OnDcpFrame(const void* data, int size, std::int64_t recv_time_us) {
  const std::int64_t now_us = late_.enabled() ? lcm_->NowUs() : recv_time_us;
  auto got = wire::ReceiveFrame<dcp_frame_t>(
      data, size, &dcp_frames_, &counters_,
      [](const dcp_frame_t& m) { return wire::UnpackDcpFrame(m); }, now_us, &late_);
  if (!got) return;
  const auto& [msg, dcp] = *got;
  counters_.Set(Counter::kDcpMissing, dcp_frames_.missing());
  latencies_["dcp_to_scene"].Add(now_us - msg.send_time_us);
  RecordEndToEnd(now_us - msg.input_send_time_us, config_.session.frame_rate_hz,
                 &latencies_["input_to_scene"], &counters_);

  // An ESG frame is numbered as the DCP frame it answers (one to one), so
  // the numbering survives a restart of either process and the ESG counts
  // exactly the frames lost on the way (docs/protocol.md "Frame numbers").
  const std::int64_t frame = msg.frame;
  next_frame_ = frame + 1;
  const wire::EsgFrameData e =
      scene_.Step(dcp, static_cast<std::uint32_t>(frame & 0xFFFFFF), &counters_);
  esg_frame_t out;
  out.frame = frame;
  out.dcp_frame = msg.frame;
  out.input_frame = msg.input_frame;
  out.input_send_time_us = msg.input_send_time_us;
  out.words = wire::PackEsgWords(e, &counters_);
  RMS_CHECK(out.words.size() <= static_cast<std::size_t>(wire::kEsgMaxWords));
  out.num_words = static_cast<std::int16_t>(out.words.size());
  out.send_time_us = lcm_->NowUs();
  if (transport::PublishMessage(*lcm_, wire::channels::kEsgFrame, out))
    counters_.Add(Counter::kPublished);
  else
    counters_.Add(Counter::kPublishFailed);
}

int RunSceneProc(const LabConfig& config, transport::LcmInterface& lcm,
                 const std::string& stats_path, const std::string& ready_path, bool every_frame) {
  SceneProc node(config, &lcm);
  node.EnableLiveChecks(config.session.frame_rate_hz, !every_frame);
  if (every_frame) spdlog::info("every DCP frame answered however late (--every-frame)");
  if (!ready_path.empty()) transport::WriteReadyFile(ready_path);
  spdlog::info("ready: {} -> {}", lcm.FullChannel(wire::channels::kDcpFrame),
               lcm.FullChannel(wire::channels::kEsgFrame));
  transport::RunNodeLoop(
      lcm, "scene_proc", node.counters(), node.latencies(), [&] { return node.last_frame(); },
      nullptr, stats_path);
  spdlog::info("published {} ESG frames; DCP frames missing {}, late {}, dropped {}",
               node.counters().Get(Counter::kPublished), node.counters().Get(Counter::kDcpMissing),
               node.counters().Get(Counter::kFramesLate),
               node.counters().Sum(kDroppedFirst, kDroppedLast));
  return 0;
}

}  // namespace rms::scene_proc
