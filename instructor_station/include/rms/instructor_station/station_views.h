#pragma once
// The live views a viewer of the web page asks for (docs/instructor.md
// "Live views"): the operator's own view or any of the eight camera
// stations, drawn by this process from the DCP frame with the scene's and
// the ESG's own code (the Visual Scene Program, then FrameRenderer on the
// frame's words, then the overlay), so the 64-word ESG frame stays the
// operator's alone. Only the views someone watched in the last two seconds
// are drawn, each at most `max_rate_hz`, each once per DCP frame (and once
// when first asked for while the session is frozen).
#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "rms/base/config.h"
#include "rms/base/counters.h"
#include "rms/esg_renderer/gl_context.h"
#include "rms/esg_renderer/overlay.h"
#include "rms/esg_renderer/renderer.h"
#include "rms/scene_proc/camera_stations.h"
#include "rms/scene_proc/visual_scene_program.h"
#include "rms/wire/word_blocks.h"

namespace rms::instructor_station {

// 0: the operator's view (the station and camera drive the operator chose);
// 1..8: that camera station at its default aim.
inline constexpr int kOperatorView = 0;
inline constexpr int kNumViews = rms::kNumCameraStations + 1;

struct ViewImage {
  std::int64_t frame = -1;        // the DCP frame it shows
  std::vector<std::uint8_t> png;  // empty until first drawn
};

class StationViews {
 public:
  StationViews(const LabConfig& config, int width, int height, double max_rate_hz,
               Counters* counters);
  // From any thread: someone is watching `view` (0..8).
  void Request(int view);
  // The latest image of `view` (from any thread).
  ViewImage Latest(int view) const;
  // On the LCM thread, after each wait: steps every camera drive on a new DCP
  // frame, draws the views watched that are due.
  // lost_stations: bit k-1, station k is lost (SessionWatch::LostStations):
  // its view shows no picture, as the ESG would.
  void Update(const wire::DcpFrameData& dcp, std::uint32_t lost_stations = 0);

  // A past frame's view (docs/instructor.md "Debrief"): from any thread,
  // `view` at DCP frame `frame` is asked for; Past gives it once drawn (its
  // `frame` the one drawn: the nearest kept at or before the one asked),
  // else an empty image (the page keeps its last one and asks again). The
  // last kPastCached drawn are kept, so viewers at different instants do
  // not draw each other's away.
  static constexpr std::size_t kPastCached = 32;
  void RequestPast(int view, std::int64_t frame);
  ViewImage Past(int view, std::int64_t frame) const;
  // On the LCM thread: a past view asked for and not drawn, if any.
  std::optional<std::pair<int, std::int64_t>> PendingPast() const;
  // Draws it from `frames` (the lead-in, the frame itself last: the camera
  // drive's run-up, as it ran live) with the stations lost then.
  void DrawPast(int view, std::int64_t asked_frame, const std::vector<wire::DcpFrameData>& frames,
                std::uint32_t lost_stations);

 private:
  static std::array<std::int64_t, kNumViews> MinusOnes() {
    std::array<std::int64_t, kNumViews> a{};
    a.fill(-1);
    return a;
  }
  void Draw(int view, const wire::EsgFrameData& e, std::int64_t frame);
  ViewImage Render(const wire::EsgFrameData& e, std::int64_t frame);
  static wire::DcpFrameData AsStation(wire::DcpFrameData d, int view, std::uint32_t lost_stations);

  const LabConfig& config_;
  int width_, height_;
  std::chrono::nanoseconds min_interval_;
  Counters* counters_;
  std::unique_ptr<esg_renderer::GlContext> gl_;
  std::unique_ptr<esg_renderer::FrameRenderer> renderer_;
  esg_renderer::OverlayModel overlay_;
  std::array<std::unique_ptr<scene_proc::VisualSceneProgram>, kNumViews> programs_;
  // Each view's content for the DCP frame it last stepped on (LCM thread).
  std::array<wire::EsgFrameData, kNumViews> content_{};
  std::array<std::int64_t, kNumViews> stepped_frame_ = MinusOnes();
  mutable std::mutex mu_;  // guards the two arrays below
  std::array<std::chrono::steady_clock::time_point, kNumViews> watched_{};
  std::array<ViewImage, kNumViews> images_;
  std::array<std::chrono::steady_clock::time_point, kNumViews> drawn_at_{};
  // Past views: those asked for and not drawn (oldest first), and the last
  // kPastCached drawn, each by the view and the frame asked for.
  struct PastImage {
    int view = 0;
    std::int64_t asked = 0;
    ViewImage image;
  };
  std::deque<std::pair<int, std::int64_t>> past_asked_;
  std::deque<PastImage> past_;
};

}  // namespace rms::instructor_station
