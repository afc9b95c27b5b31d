#include "rms/esg_renderer/esg_renderer.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <spdlog/spdlog.h>

#include "rms/base/check.h"
#include "rms/esg_renderer/overlay.h"
#include "rms/esg_renderer/png_io.h"
#include "rms/window_keys_t.hpp"
#include "rms/wire/channels.h"
#include "rms/wire/frame_receiver.h"
#include "rms/wire/message_io.h"

namespace rms::esg_renderer {

namespace {

std::int64_t MonotonicUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
}  // namespace

EsgRenderer::EsgRenderer(const LabConfig& config, transport::LcmInterface* lcm,
                         FrameRenderer* renderer, EsgOptions options, VideoWriter* video,
                         LiveWindow* window)
    : config_(config),
      lcm_(lcm),
      renderer_(renderer),
      options_(std::move(options)),
      video_(video),
      window_(window) {
  overlay_ = MakeOverlayModel(config);
  lcm_->Subscribe(wire::channels::kEsgFrame,
                  [this](const void* d, int n, std::int64_t t) { OnFrame(d, n, t); });
  if (window_) {
    lcm_->Subscribe(wire::channels::kOperatorState,
                    [this](const void* d, int n, std::int64_t) { OnOperatorState(d, n); });
  }
}

void EsgRenderer::OnOperatorState(const void* data, int size) {
  operator_state_t m{};
  if (const wire::DecodeError e = wire::SafeDecode(data, size, &m); e != wire::DecodeError::kNone) {
    counters_.Add(wire::DroppedOperatorStateCounter(e));
    return;
  }
  bool finite = std::isfinite(m.distance_ft) && std::isfinite(m.angle_deg) &&
                std::isfinite(m.bay_clearance_ft) && std::isfinite(m.close_gap_ft) &&
                std::isfinite(m.dock_distance_ft) && std::isfinite(m.dock_angle_deg) &&
                std::isfinite(m.turn_clearance_ft);
  for (int i = 0; i < 3; ++i)
    finite = finite && std::isfinite(m.offset_ft[i]) && std::isfinite(m.rotation_deg[i]);
  for (int i = 0; i < 6; ++i) finite = finite && std::isfinite(m.margin_ft[i]);
  if (!finite) {
    counters_.Add(Counter::kDroppedOperatorStateNonFinite);
    return;
  }
  if (operator_state_ && m.frame < operator_state_->frame) {
    counters_.Add(Counter::kDroppedOperatorStateStale);
    return;
  }
  operator_state_ = m;
}

void EsgRenderer::PollWindow() {
  if (!window_ || !window_->open()) return;
  const WindowKeys k = window_->Poll();
  if (!window_->open()) spdlog::info("the live window was closed; rendering goes on");
  const std::int64_t now = lcm_->NowUs();
  const bool heartbeat = (keys_held_ || !k.held.empty()) && now - keys_sent_us_ >= 100000;
  if (!k.changed && !heartbeat) return;
  window_keys_t m;
  m.send_time_us = now;
  m.sequence = keys_sequence_++;
  for (int c : k.held) m.held.push_back(static_cast<std::int16_t>(c));
  for (int c : k.pressed) m.pressed.push_back(static_cast<std::int16_t>(c));
  m.num_held = static_cast<std::int16_t>(m.held.size());
  m.num_pressed = static_cast<std::int16_t>(m.pressed.size());
  m.focused = k.focused;
  if (transport::PublishMessage(*lcm_, wire::channels::kWindowKeys, m))
    counters_.Add(Counter::kWindowKeysMessages);
  else
    counters_.Add(Counter::kPublishFailed);
  counters_.Add(Counter::kWindowKeysPressed, static_cast<std::int64_t>(k.pressed.size()));
  keys_sent_us_ = now;
  keys_held_ = !k.held.empty();
}

void EsgRenderer::EnableLiveChecks(double frame_rate_hz) {
  frames_.SetClock(transport::SessionFrameClock(frame_rate_hz));
  late_ = wire::LateFrameFilter(frame_rate_hz);
}

void EsgRenderer::OnFrame(const void* data, int size, std::int64_t recv_time_us) {
  const std::int64_t now_us = late_.enabled() ? lcm_->NowUs() : recv_time_us;
  auto got = wire::ReceiveFrame<esg_frame_t>(
      data, size, &frames_, &counters_,
      [](const esg_frame_t& m) {
        if (m.num_words < 1 || m.num_words > wire::kEsgMaxWords) {
          throw wire::MalformedError(Counter::kDroppedWordCount,
                                     "ESG frame with " + std::to_string(m.num_words) + " words");
        }
        return wire::UnpackEsgWords(m.words);
      },
      now_us, &late_);
  if (!got) return;
  auto& [msg, data_words] = *got;
  counters_.Set(Counter::kEsgMissing, frames_.missing());
  latencies_["scene_to_esg"].Add(now_us - msg.send_time_us);
  if (first_frame_ < 0) first_frame_ = msg.frame;
  if (pending_) counters_.Add(Counter::kSuperseded);
  pending_.emplace(std::move(msg), std::move(data_words));
}

void EsgRenderer::FinishVideo() {
  RenderPending();
  if (video_ && last_rendered_ >= 0 && frames_.last() > last_rendered_) {
    video_->Add(image_, static_cast<int>(
                            std::clamp<std::int64_t>(frames_.last() - last_rendered_, 1, 300)));
  }
}

bool EsgRenderer::RenderPending() {
  if (!pending_) return false;
  const auto [msg, frame] = std::move(*pending_);
  pending_.reset();
  const int w = renderer_->width(), h = renderer_->height();
  const std::size_t bytes = static_cast<std::size_t>(w) * h * 4;
  // Skip what the scene doesn't need: the same words but for the frame
  // counter (word 0) draw the same scene and the same overlay but for the
  // counter, which is drawn again over what lay under it.
  const bool unchanged =
      options_.skip_unchanged && image_ && msg.words.size() == last_words_.size() &&
      std::equal(msg.words.begin() + 1, msg.words.end(), last_words_.begin() + 1);
  const std::int64_t t0 = MonotonicUs();
  if (unchanged) {
    counters_.Add(Counter::kSkippedUnchanged);
    RestoreCounterBackdrop(image_, w, h, backdrop_);
  } else {
    renderer_->Render(frame);
    image_ = renderer_->pixels();
    last_words_ = msg.words;
    const RenderStats& s = renderer_->stats();
    counters_.Add(Counter::kRenderedScenes);
    counters_.Add(Counter::kClustersDrawn, s.clusters_drawn);
    counters_.Add(Counter::kClustersCulled, s.clusters_culled);
    counters_.Add(Counter::kTrianglesSubmitted, s.triangles_submitted);
    if (s.cycles_broken) counters_.Add(Counter::kPriorityCyclesBroken, s.cycles_broken);
    latencies_["render"].Add(MonotonicUs() - t0);
  }
  // The overlay over the renderer's own buffer: no copy of the image in the
  // frame's path (3 MB at 1024x768).
  if (!options_.id_colors) DrawOverlay(image_, w, h, frame, overlay_, &backdrop_);
  const std::int64_t done = lcm_->NowUs();
  counters_.Add(Counter::kRendered);
  latencies_["esg_to_render"].Add(done - msg.send_time_us);
  RecordEndToEnd(done - msg.input_send_time_us, config_.session.frame_rate_hz,
                 &latencies_["input_to_render"], &counters_);
  if (video_) {
    // One video frame per frame number: frames skipped, superseded or lost
    // repeat the last image (before the first drawn, the first drawn), so the
    // video keeps the session's time.
    const std::int64_t since = last_rendered_ < 0 ? first_frame_ - 1 : last_rendered_;
    const std::int64_t gap = std::clamp<std::int64_t>(msg.frame - since, 1, 300);
    video_->Add(image_, static_cast<int>(gap));
  }
  if (window_ && window_->open()) {
    // The window alone shows the operator's guidance over the ESG's image.
    shown_.assign(image_, image_ + bytes);
    if (operator_state_) DrawGuidance(shown_.data(), w, h, *operator_state_);
    if (window_->Show(shown_.data())) counters_.Add(Counter::kWindowFrames);
  }
  last_rendered_ = msg.frame;
  if (options_.png_every > 0 && !options_.png_dir.empty() && msg.frame % options_.png_every == 0) {
    char name[64];
    std::snprintf(name, sizeof name, "frame_%06lld.png", static_cast<long long>(msg.frame));
    try {
      WritePng((std::filesystem::path(options_.png_dir) / name).string(), w, h, image_);
      counters_.Add(Counter::kPngWritten);
    } catch (const std::exception& e) {
      counters_.Add(Counter::kPngFailed);
      spdlog::warn("{}", e.what());
    }
  }
  return true;
}

int RunEsgRenderer(const LabConfig& config, transport::LcmInterface& lcm, const EsgOptions& options,
                   const std::string& stats_path, const std::string& ready_path) {
  if (!options.png_dir.empty()) std::filesystem::create_directories(options.png_dir);
  RenderOptions ro;
  ro.id_colors = options.id_colors;
  if (options.visibility == "depth")
    ro.visibility = Visibility::kDepth;
  else if (options.visibility != "priority")
    throw InputError("--visibility must be priority or depth");
  ro.frustum_cull = options.frustum_cull;
  ro.backface_cull = options.backface_cull;
  std::unique_ptr<GlContext> gl =
      CreateGlContext(ParseGlBackend(options.gl), options.width, options.height);
  FrameRenderer renderer(config, gl.get(), ro);
  spdlog::info(
      "{}; {}x{}; {} triangles in {} clusters; visibility by {}", gl->description(), options.width,
      options.height, renderer.triangle_count(), scene_model::kNumClusters,
      ro.visibility == Visibility::kDepth ? "depth buffer" : "priority (separating planes)");
  std::unique_ptr<VideoWriter> video;
  if (!options.video_path.empty()) {
    video = std::make_unique<VideoWriter>(options.video_path, options.width, options.height,
                                          config.session.frame_rate_hz);
    spdlog::info("video: {}", options.video_path);
  }
  std::unique_ptr<LiveWindow> window;
  if (options.window) {
    try {
      window = std::make_unique<LiveWindow>(options.width, options.height, "rmslab ESG");
      spdlog::info("live window open");
    } catch (const std::exception& e) {
      spdlog::warn("no live window: {}; rendering headless", e.what());
    }
  }
  EsgRenderer node(config, &lcm, &renderer, options, video.get(), window.get());
  node.EnableLiveChecks(config.session.frame_rate_hz);
  if (!ready_path.empty()) transport::WriteReadyFile(ready_path);
  spdlog::info("ready: {}", lcm.FullChannel(wire::channels::kEsgFrame));
  // With a window, wake often enough that a released key is sent at once.
  transport::RunNodeLoop(
      lcm, "esg_renderer", node.counters(), node.latencies(), [&] { return node.last_rendered(); },
      [&] {
        node.RenderPending();
        node.PollWindow();
      },
      stats_path, window ? 5 : 100);
  if (video) {
    // Frames already in the socket at the stop still belong in the video.
    lcm.HandleSubscriptions(0);
    node.FinishVideo();
    video->Close();
    node.counters().Set(Counter::kVideoFrames, video->frames_written());
    node.counters().Set(Counter::kVideoDropped, video->frames_dropped());
    if (!stats_path.empty())
      transport::WriteStatsJson(stats_path, "esg_renderer", node.counters(), node.latencies());
  }
  spdlog::info(
      "rendered {} frames ({} scenes drawn, {} unchanged, {} superseded, {} missing, {} late, {} "
      "dropped, "
      "{} PNG{})",
      node.counters().Get(Counter::kRendered), node.counters().Get(Counter::kRenderedScenes),
      node.counters().Get(Counter::kSkippedUnchanged), node.counters().Get(Counter::kSuperseded),
      node.counters().Get(Counter::kEsgMissing), node.counters().Get(Counter::kFramesLate),
      node.counters().Sum(kDroppedFirst, kDroppedLast), node.counters().Get(Counter::kPngWritten),
      video ? ", " + std::to_string(video->frames_written()) + " video frames" : std::string());
  return 0;
}

}  // namespace rms::esg_renderer
