#include "esg_node.h"

#include <cstdio>
#include <filesystem>
#include <spdlog/spdlog.h>

#include "rms/channels.h"
#include "rms/check.h"
#include "rms/message_io.h"
#include "png_io.h"

namespace rms::esg {

namespace {
// esg_frame_t: 8 (fingerprint) + 5 x 8 + 2 + 64 x 4 at most.
constexpr int kMaxEsgSize = 8 + 40 + 2 + 4 * kEsgMaxWords;
}  // namespace

EsgNode::EsgNode(const LabConfig& /*config*/, LcmInterface* lcm, EsgRenderer* renderer,
                 EsgOptions options)
    : lcm_(lcm), renderer_(renderer), options_(std::move(options)) {
  lcm_->Subscribe(channels::kEsgFrame,
                  [this](const void* d, int n, std::int64_t t) { OnFrame(d, n, t); });
}

void EsgNode::OnFrame(const void* data, int size, std::int64_t recv_time_us) {
  counters_.Add("received");
  esg_frame_t msg;
  const DecodeError err = SafeDecode(data, size, kMaxEsgSize, &msg);
  if (err != DecodeError::kNone) {
    counters_.Add(std::string("dropped.") + DecodeErrorName(err));
    return;
  }
  if (msg.num_words < 1 || msg.num_words > kEsgMaxWords) {
    counters_.Add("dropped.word_count");
    return;
  }
  EsgFrameData data_words;
  try {
    data_words = UnpackEsgWords(msg.words);
  } catch (const InputError& e) {
    counters_.Add("dropped.bad_word");
    spdlog::debug("ESG frame {} dropped: {}", msg.frame, e.what());
    return;
  }
  switch (frames_.Accept(msg.frame)) {
    case SequenceTracker::Verdict::kDuplicate: counters_.Add("dropped.duplicate"); return;
    case SequenceTracker::Verdict::kStale: counters_.Add("dropped.stale"); return;
    default: break;
  }
  counters_.Set("esg.missing", frames_.missing());
  latencies_["scene_to_esg"].Add(recv_time_us - msg.send_time_us);
  if (pending_) counters_.Add("superseded");
  pending_.emplace(std::move(msg), data_words);
}

bool EsgNode::RenderPending() {
  if (!pending_) return false;
  const auto [msg, frame] = std::move(*pending_);
  pending_.reset();
  renderer_->Render(frame);
  const std::uint8_t* px = renderer_->pixels();
  const std::int64_t done = lcm_->NowUs();
  counters_.Add("rendered");
  latencies_["esg_to_render"].Add(done - msg.send_time_us);
  latencies_["input_to_render"].Add(done - msg.input_send_time_us);
  last_rendered_ = msg.frame;
  if (options_.png_every > 0 && !options_.png_dir.empty() && msg.frame % options_.png_every == 0) {
    char name[64];
    std::snprintf(name, sizeof name, "frame_%06lld.png", static_cast<long long>(msg.frame));
    try {
      WritePng((std::filesystem::path(options_.png_dir) / name).string(), renderer_->width(),
               renderer_->height(), px);
      counters_.Add("png_written");
    } catch (const std::exception& e) {
      counters_.Add("png_failed");
      spdlog::warn("{}", e.what());
    }
  }
  return true;
}

int RunEsgRenderer(const LabConfig& config, LcmInterface& lcm, const EsgOptions& options,
                   const std::string& stats_path, const std::string& ready_path) {
  if (!options.png_dir.empty()) std::filesystem::create_directories(options.png_dir);
  std::unique_ptr<GlContext> gl = CreateOsMesaContext(options.width, options.height);
  EsgRenderer renderer(config, gl.get(), RenderOptions{options.id_colors});
  spdlog::info("{}; {}x{}; {} triangles in the static models", gl->description(), options.width,
               options.height, renderer.triangle_count());
  EsgNode node(config, &lcm, &renderer, options);
  StatusReporter status(&lcm, "esg_renderer");
  if (!ready_path.empty()) TouchFile(ready_path);
  spdlog::info("ready: {}", lcm.FullChannel(channels::kEsgFrame));
  while (!StopRequested()) {
    if (lcm.HandleSubscriptions(100) < 0) node.counters().Add("transport_errors");
    node.RenderPending();
    Counters report = node.counters();
    AddLatencyCounters(node.latencies(), &report);
    status.Tick(node.last_rendered(), report);
  }
  Counters report = node.counters();
  AddLatencyCounters(node.latencies(), &report);
  status.Final(node.last_rendered(), report);
  if (!stats_path.empty()) WriteStatsJson(stats_path, "esg_renderer", node.counters(), node.latencies());
  spdlog::info("rendered {} frames ({} superseded, {} dropped, {} PNG)", node.counters().Get("rendered"),
               node.counters().Get("superseded"), node.counters().SumPrefix("dropped."),
               node.counters().Get("png_written"));
  return 0;
}

}  // namespace rms::esg
