#include "rms/instructor_station/station_views.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "rms/esg_renderer/png_io.h"

namespace rms::instructor_station {

namespace {
using Clock = std::chrono::steady_clock;
// A view nobody asked for in this long is no longer drawn.
constexpr auto kWatchedFor = std::chrono::seconds(2);
}  // namespace

StationViews::StationViews(const LabConfig& config, int width, int height, double max_rate_hz,
                           Counters* counters)
    : config_(config),
      width_(width),
      height_(height),
      min_interval_(std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / max_rate_hz))),
      counters_(counters) {
  gl_ = esg_renderer::CreateGlContext(esg_renderer::GlBackend::kOsMesa, width, height);
  renderer_ = std::make_unique<esg_renderer::FrameRenderer>(config, gl_.get(),
                                                            esg_renderer::RenderOptions{});
  overlay_ = esg_renderer::MakeOverlayModel(config);
  for (auto& p : programs_) p = std::make_unique<scene_proc::VisualSceneProgram>(config);
}

void StationViews::Request(int view) {
  if (view < 0 || view >= kNumViews) throw std::out_of_range("view");
  std::lock_guard<std::mutex> lock(mu_);
  watched_[view] = Clock::now();
}

ViewImage StationViews::Latest(int view) const {
  std::lock_guard<std::mutex> lock(mu_);
  return images_.at(static_cast<std::size_t>(view));
}

void StationViews::Update(const wire::DcpFrameData& dcp, std::uint32_t lost_stations) {
  const auto now = Clock::now();
  std::array<bool, kNumViews> watched{}, due{};
  {
    std::lock_guard<std::mutex> lock(mu_);
    for (int v = 0; v < kNumViews; ++v) {
      watched[v] = now - watched_[v] < kWatchedFor;
      // Due: watched, not drawn for this frame yet, and not drawn too
      // recently. A frozen session's frame is drawn once when first asked.
      due[v] = watched[v] && images_[v].frame != dcp.frame && now - drawn_at_[v] >= min_interval_;
    }
  }
  const auto frame_count = static_cast<std::uint32_t>(dcp.frame & 0xFFFFFF);
  for (int v = 0; v < kNumViews; ++v) {
    // The operator's view: its camera drive follows the operator's commands
    // every frame, watched or not, as scene_proc's does.
    if (v != kOperatorView && !watched[v]) continue;
    if (stepped_frame_[v] != dcp.frame) {
      content_[v] = programs_[v]->Step(AsStation(dcp, v, lost_stations), frame_count, nullptr);
      stepped_frame_[v] = dcp.frame;
    }
    if (due[v]) Draw(v, content_[v], dcp.frame);
  }
}

// View v's DCP frame: the operator's as it is; a station at its default
// aim, widest, black when it is lost.
wire::DcpFrameData StationViews::AsStation(wire::DcpFrameData d, int v,
                                           std::uint32_t lost_stations) {
  if (v != kOperatorView) {
    d.control.camera_station = v;
    d.camera_pan_deg = d.camera_tilt_deg = d.camera_zoom = 0.0;
    d.control.no_video = (lost_stations >> (v - 1)) & 1u;
  }
  return d;
}

void StationViews::Draw(int view, const wire::EsgFrameData& e, std::int64_t frame) {
  ViewImage img = Render(e, frame);
  std::lock_guard<std::mutex> lock(mu_);
  images_[view] = std::move(img);
  drawn_at_[view] = Clock::now();
}

void StationViews::RequestPast(int view, std::int64_t frame) {
  if (view < 0 || view >= kNumViews) throw std::out_of_range("view");
  std::lock_guard<std::mutex> lock(mu_);
  for (const PastImage& p : past_)
    if (p.view == view && p.asked == frame) return;  // drawn
  const auto key = std::make_pair(view, frame);
  if (std::find(past_asked_.begin(), past_asked_.end(), key) != past_asked_.end()) return;
  past_asked_.push_back(key);
  // A viewer dragging the slider asks for many: only the newest few wait.
  while (past_asked_.size() > kNumViews * 2) past_asked_.pop_front();
}

ViewImage StationViews::Past(int view, std::int64_t frame) const {
  std::lock_guard<std::mutex> lock(mu_);
  for (const PastImage& p : past_)
    if (p.view == view && p.asked == frame) return p.image;
  return {};
}

std::optional<std::pair<int, std::int64_t>> StationViews::PendingPast() const {
  std::lock_guard<std::mutex> lock(mu_);
  if (past_asked_.empty()) return std::nullopt;
  return past_asked_.back();  // the newest first: what a viewer waits for now
}

void StationViews::DrawPast(int view, std::int64_t asked_frame,
                            const std::vector<wire::DcpFrameData>& frames,
                            std::uint32_t lost_stations) {
  PastImage p;
  p.view = view;
  p.asked = asked_frame;
  if (!frames.empty()) {
    // A program of its own, run up over the lead-in as the live one ran.
    scene_proc::VisualSceneProgram program(config_);
    wire::EsgFrameData e;
    for (const wire::DcpFrameData& d : frames)
      e = program.Step(AsStation(d, view, lost_stations),
                       static_cast<std::uint32_t>(d.frame & 0xFFFFFF), nullptr);
    p.image = Render(e, frames.back().frame);
  }
  std::lock_guard<std::mutex> lock(mu_);
  const auto key = std::make_pair(view, asked_frame);
  past_asked_.erase(std::remove(past_asked_.begin(), past_asked_.end(), key), past_asked_.end());
  if (p.image.png.empty()) return;  // nothing kept to draw it from
  past_.push_back(std::move(p));
  while (past_.size() > kPastCached) past_.pop_front();
}

ViewImage StationViews::Render(const wire::EsgFrameData& e, std::int64_t frame) {
  // Through the words, as the ESG receives them (the same rounding).
  const wire::EsgFrameData f = wire::UnpackEsgWords(wire::PackEsgWords(e, nullptr));
  renderer_->Render(f);
  const std::uint8_t* px = renderer_->pixels();
  std::vector<std::uint8_t> rgba(px, px + static_cast<std::size_t>(width_) * height_ * 4);
  esg_renderer::DrawOverlay(rgba.data(), width_, height_, f, overlay_);
  ViewImage img;
  img.frame = frame;
  img.png = esg_renderer::EncodePng(width_, height_, rgba.data());
  counters_->Add(Counter::kViewsRendered);
  return img;
}

}  // namespace rms::instructor_station
