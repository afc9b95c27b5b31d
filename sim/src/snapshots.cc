#include "rms/sim/snapshots.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/dcp_model/dcp_telemetry.h"
#include "rms/esg_renderer/gl_context.h"
#include "rms/esg_renderer/overlay.h"
#include "rms/esg_renderer/png_io.h"
#include "rms/esg_renderer/renderer.h"
#include "rms/sim/offline_session.h"
#include "rms/wire/dcp_mode.h"

namespace rms::sim {

namespace {

// The live window's guidance panel as the operator station would fill it
// from this frame's telemetry (a by-hand session in manual augmented control).
operator_state_t StateOf(const LabConfig& config, const OfflineSession& s,
                         operator_station::CommandFrame frame) {
  const dcp_telemetry_t t = dcp_model::MakeTelemetry(s.status(), s.dcp());
  const operator_station::ArmState arm = operator_station::ArmStateFrom(t);
  if (frame == operator_station::CommandFrame::kPayload && arm.mode == wire::DcpMode::kAcquisition)
    frame = operator_station::CommandFrame::kEndEffector;
  const operator_station::Guidance g =
      operator_station::ComputeGuidance(operator_station::MakeGuidanceGeometry(config), arm, frame);
  operator_state_t m{};
  m.source = operator_state_t::SOURCE_BY_HAND;
  m.control_mode = operator_state_t::CONTROL_MANUAL_AUGMENTED;
  m.command_frame = static_cast<std::int8_t>(frame);
  m.guidance_valid = true;
  m.show_guidance = true;
  m.mode = t.mode;
  m.target = static_cast<std::int8_t>(g.target);
  for (int i = 0; i < 3; ++i) {
    m.offset_ft[i] = g.offset_ft[i];
    m.rotation_deg[i] = g.rotation_deg[i];
  }
  for (int i = 0; i < 6; ++i) m.margin_ft[i] = t.acquisition_margin_ft[i];
  m.bay_clearance_ft = t.bay_clearance_ft;
  m.dock_distance_ft = t.dock_distance_ft;
  m.dock_angle_deg = t.dock_angle_deg;
  return m;
}

struct Shot {
  double t;
  int station;
  std::string name;
  bool done = false;
};

std::vector<Shot> ParseShots(const std::vector<std::string>& specs) {
  std::vector<Shot> list;
  for (const std::string& spec : specs) {
    Shot sh;
    char name[256] = {};
    if (std::sscanf(spec.c_str(), "%lf:%d:%255s", &sh.t, &sh.station, name) != 3 ||
        sh.station < 1 || sh.station > kNumCameraStations) {
      throw InputError("--shot '" + spec + "': must be TIME:STATION:NAME, station 1.." +
                       std::to_string(kNumCameraStations));
    }
    sh.name = name;
    list.push_back(sh);
  }
  return list;
}

// A station's picture as the ESG shows it: the frame's words, rendered, the overlay.
struct Camera {
  std::unique_ptr<esg_renderer::GlContext> gl;
  esg_renderer::FrameRenderer renderer;
  esg_renderer::OverlayModel overlay;
  std::vector<std::uint8_t> img;
  Camera(const LabConfig& config, const PictureOptions& o)
      : gl(esg_renderer::CreateGlContext(esg_renderer::ParseGlBackend(o.gl), o.width, o.height)),
        renderer(config, gl.get(), {}),
        overlay(esg_renderer::MakeOverlayModel(config)),
        img(static_cast<std::size_t>(o.width) * o.height * 4) {}
  const std::vector<std::uint8_t>& Picture(const wire::EsgFrameData& f, const PictureOptions& o) {
    renderer.Render(f);
    std::memcpy(img.data(), renderer.pixels(), img.size());
    esg_renderer::DrawOverlay(img.data(), o.width, o.height, f, overlay);
    return img;
  }
};

}  // namespace

std::array<double, kNumCameraStations> StationTimes(const LabConfig& config,
                                                    const operator_station::Timeline& tl,
                                                    std::optional<double> at_time_s) {
  constexpr int kN = kNumCameraStations;
  std::array<double, kN> when{};
  if (at_time_s) {
    when.fill(*at_time_s);
    return when;
  }
  std::array<double, kN> first, last;
  first.fill(-1);
  last.fill(-1);
  std::array<bool, kN> in_first_visit{};
  OfflineSession scan(config, tl);
  while (scan.Next()) {
    const int s = scan.inputs().camera_station - 1;
    for (int k = 0; k < kN; ++k) in_first_visit[k] = in_first_visit[k] && k == s;  // a visit ends
    if (first[s] < 0) {
      first[s] = scan.t_s();
      in_first_visit[s] = true;
    }
    if (in_first_visit[s]) last[s] = scan.t_s();
  }
  for (int s = 0; s < kN; ++s) {
    when[s] = first[s] < 0 ? tl.end_time() : 0.5 * (first[s] + last[s]);
    if (first[s] < 0)
      std::fprintf(stderr, "station %d is never selected: shown at the end\n", s + 1);
  }
  return when;
}

void ContactSheet(const LabConfig& config, const operator_station::Timeline& tl,
                  const std::array<double, kNumCameraStations>& when, int columns,
                  const PictureOptions& o) {
  constexpr int kN = kNumCameraStations;
  Camera camera(config, o);
  const int rows = (kN + columns - 1) / columns;
  const int sheet_w = columns * o.width, sheet_h = rows * o.height;
  std::vector<std::uint8_t> sheet(static_cast<std::size_t>(sheet_w) * sheet_h * 4, 0);
  std::array<bool, kN> done{};
  OfflineSession session(config, tl);
  while (session.Next() && !std::all_of(done.begin(), done.end(), [](bool d) { return d; })) {
    for (int s = 1; s <= kN; ++s) {
      if (done[s - 1] || session.t_s() + 1e-9 < when[s - 1]) continue;
      wire::EsgFrameData f = session.esg(s);
      f.control.overlay = true;
      const std::vector<std::uint8_t>& img = camera.Picture(f, o);
      const std::string path = o.out_dir + "/station_" + std::to_string(s) + ".png";
      esg_renderer::WritePng(path, o.width, o.height, img.data());
      const int x0 = ((s - 1) % columns) * o.width, y0 = ((s - 1) / columns) * o.height;
      for (int y = 0; y < o.height; ++y) {
        std::memcpy(&sheet[(static_cast<std::size_t>(y0 + y) * sheet_w + x0) * 4],
                    &img[static_cast<std::size_t>(y) * o.width * 4],
                    static_cast<std::size_t>(o.width) * 4);
      }
      std::printf("%s: station %d (%s) at t = %.2f s, frame %lld\n", path.c_str(), s,
                  config.cameras[s - 1].name.c_str(), session.t_s(),
                  static_cast<long long>(session.frame()));
      done[s - 1] = true;
    }
  }
  esg_renderer::WritePng(o.out_dir + "/stations.png", sheet_w, sheet_h, sheet.data());
  std::printf("%s/stations.png: the contact sheet, %dx%d\n", o.out_dir.c_str(), sheet_w, sheet_h);
}

void TakeShots(const LabConfig& config, const operator_station::Timeline& tl,
               const std::vector<std::string>& shots, operator_station::CommandFrame frame,
               const PictureOptions& o) {
  std::vector<Shot> list = ParseShots(shots);
  Camera camera(config, o);
  OfflineSession session(config, tl);
  while (session.Next()) {
    for (Shot& sh : list) {
      if (sh.done || session.t_s() + 1e-9 < sh.t) continue;
      wire::EsgFrameData f = session.esg(sh.station);
      f.control.overlay = true;
      f.control.crosshairs = true;
      std::vector<std::uint8_t> img = camera.Picture(f, o);
      esg_renderer::DrawGuidance(img.data(), o.width, o.height, StateOf(config, session, frame));
      const std::string path = o.out_dir + "/" + sh.name + ".png";
      esg_renderer::WritePng(path, o.width, o.height, img.data());
      std::printf("%s: station %d at t = %.2f s\n", path.c_str(), sh.station, session.t_s());
      sh.done = true;
    }
  }
}

}  // namespace rms::sim
