#include "esg_node.h"

#include <cstdio>
#include <filesystem>
#include <spdlog/spdlog.h>

#include "rms/channels.h"
#include "rms/check.h"
#include "rms/frame_receiver.h"
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
  auto got = ReceiveFrame<esg_frame_t>(data, size, kMaxEsgSize, &frames_, &counters_,
                                       [](const esg_frame_t& m) {
                                         if (m.num_words < 1 || m.num_words > kEsgMaxWords) {
                                           throw MalformedError("word_count",
                                                                "ESG frame with " + std::to_string(m.num_words) + " words");
                                         }
                                         return UnpackEsgWords(m.words);
                                       });
  if (!got) return;
  auto& [msg, data_words] = *got;
  counters_.Set("esg.missing", frames_.missing());
  latencies_["scene_to_esg"].Add(recv_time_us - msg.send_time_us);
  if (pending_) counters_.Add("superseded");
  pending_.emplace(std::move(msg), std::move(data_words));
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
  if (!ready_path.empty()) TouchFile(ready_path);
  spdlog::info("ready: {}", lcm.FullChannel(channels::kEsgFrame));
  RunNodeLoop(lcm, "esg_renderer", node.counters(), node.latencies(),
              [&] { return node.last_rendered(); }, [&] { node.RenderPending(); }, stats_path);
  spdlog::info("rendered {} frames ({} superseded, {} dropped, {} PNG)", node.counters().Get("rendered"),
               node.counters().Get("superseded"), node.counters().SumPrefix("dropped."),
               node.counters().Get("png_written"));
  return 0;
}

}  // namespace rms::esg
