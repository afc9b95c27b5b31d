// rms_snapshot: pictures of a mission from every camera station, rendered
// exactly as esg_renderer renders them (the same words, renderer and
// overlay). By default each station is shown in the middle of the mission's
// first visit to it (or, with --time, all at one moment); one PNG a station
// and a contact sheet of all eight. The README's pictures come from
//   build/tools/rms_snapshot --out-dir docs/images
// With --shot T:STATION:NAME (repeated) it takes just those pictures, with
// the crosshairs on and the live window's guidance panel drawn as the
// operator station would fill it (docs/operator.md's pictures).
#include <CLI/CLI.hpp>
#include "rms/base/command_line.h"
#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <optional>

#include "rms/dynamics_proc/dynamics_proc.h"
#include "rms/esg_renderer/gl_context.h"
#include "rms/operator_station/guidance.h"
#include "rms/sim/offline_session.h"
#include "rms/esg_renderer/overlay.h"
#include "rms/esg_renderer/png_io.h"
#include "rms/esg_renderer/renderer.h"
#include "rms/base/check.h"

namespace {

// The live window's guidance panel as the operator station would fill it
// from this frame's telemetry (a by-hand session in manual augmented control).
rms::operator_state_t StateOf(const rms::LabConfig& config, const rms::sim::OfflineSession& s,
                              rms::operator_station::CommandFrame frame) {
  const rms::dcp_telemetry_t t = rms::dynamics_proc::MakeTelemetry(s.status(), s.dcp());
  const rms::operator_station::ArmState arm = rms::operator_station::ArmStateFrom(t);
  if (frame == rms::operator_station::CommandFrame::kPayload && arm.mode == 1) frame = rms::operator_station::CommandFrame::kEndEffector;
  const rms::operator_station::Guidance g = rms::operator_station::ComputeGuidance(rms::operator_station::MakeGuidanceGeometry(config), arm, frame);
  rms::operator_state_t m{};
  m.source = rms::operator_state_t::SOURCE_BY_HAND;
  m.control_mode = 2;
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

int TakeShots(const rms::LabConfig& config, const rms::operator_station::Timeline& tl, const std::vector<std::string>& shots,
              rms::operator_station::CommandFrame frame, const std::string& out_dir, int width, int height,
              const std::string& gl_name) {
  struct Shot {
    double t;
    int station;
    std::string name;
    bool done = false;
  };
  std::vector<Shot> list;
  for (const std::string& spec : shots) {
    Shot sh;
    char name[256] = {};
    if (std::sscanf(spec.c_str(), "%lf:%d:%255s", &sh.t, &sh.station, name) != 3 || sh.station < 1 ||
        sh.station > rms::kNumCameraStations) {
      throw rms::InputError("--shot '" + spec + "': must be TIME:STATION:NAME, station 1..8");
    }
    sh.name = name;
    list.push_back(sh);
  }
  auto gl = rms::esg_renderer::CreateGlContext(rms::esg_renderer::ParseGlBackend(gl_name), width, height);
  rms::esg_renderer::FrameRenderer renderer(config, gl.get(), {});
  const rms::esg_renderer::OverlayModel overlay = rms::esg_renderer::MakeOverlayModel(config);
  std::vector<std::uint8_t> img(static_cast<std::size_t>(width) * height * 4);
  rms::sim::OfflineSession session(config, tl);
  while (session.Next()) {
    for (Shot& sh : list) {
      if (sh.done || session.t_s() + 1e-9 < sh.t) continue;
      rms::wire::EsgFrameData f = session.esg(sh.station);
      f.control.overlay = true;
      f.control.crosshairs = true;
      renderer.Render(f);
      std::memcpy(img.data(), renderer.pixels(), img.size());
      rms::esg_renderer::DrawOverlay(img.data(), width, height, f, overlay);
      rms::esg_renderer::DrawGuidance(img.data(), width, height, StateOf(config, session, frame));
      const std::string path = out_dir + "/" + sh.name + ".png";
      rms::esg_renderer::WritePng(path, width, height, img.data());
      std::printf("%s: station %d at t = %.2f s\n", path.c_str(), sh.station, session.t_s());
      sh.done = true;
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rmslab rms_snapshot: one picture from each camera station over a mission, and a contact sheet"};
  std::string config_path = rms::DefaultConfigPath();
  std::string timeline = std::string(RMSLAB_SOURCE_DIR) + "/scripts/timelines/mission.tl";
  std::string out_dir = ".", gl_name = "osmesa";
  int width = 480, height = 360, columns = 4;
  std::optional<double> at_time;
  app.add_option("--config", config_path, "Configuration file")->capture_default_str();
  app.add_option("--timeline", timeline, "Timeline to fly")->capture_default_str();
  app.add_option("--out-dir", out_dir, "Directory for station_N.png and stations.png")->capture_default_str();
  app.add_option("--time", at_time, "All stations at this time (s) instead of each at its first visit");
  app.add_option("--width", width, "Width of each picture")->capture_default_str()->check(CLI::Range(64, 4096));
  app.add_option("--height", height, "Height of each picture")->capture_default_str()->check(CLI::Range(48, 4096));
  app.add_option("--columns", columns, "Pictures a row in the contact sheet")->capture_default_str()->check(CLI::Range(1, 8));
  app.add_option("--gl", gl_name, "GL backend: osmesa or egl")->capture_default_str();
  std::vector<std::string> shots;
  app.add_option("--shot", shots,
                 "T:STATION:NAME: one picture at time T (s) from STATION into NAME.png, crosshairs on, with the "
                 "window's guidance panel (repeat for more)");
  std::string guidance_frame = "end_effector";
  app.add_option("--guidance-frame", guidance_frame, "The guidance panel's command frame: end_effector, orbiter, payload")
      ->capture_default_str()
      ->check(CLI::IsMember({"end_effector", "orbiter", "payload"}));
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  try {
    const rms::LabConfig config = rms::LoadConfig(config_path);
    const rms::operator_station::Timeline tl = rms::operator_station::Timeline::Load(timeline, config.inputs);
    constexpr int kN = rms::kNumCameraStations;
    // When to take each station: the middle of its first visit.
    std::array<double, kN> when{};
    if (at_time) {
      when.fill(*at_time);
    } else {
      std::array<double, kN> first, last;
      first.fill(-1);
      last.fill(-1);
      std::array<bool, kN> in_first_visit{};
      rms::sim::OfflineSession scan(config, tl);
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
        if (first[s] < 0) std::fprintf(stderr, "station %d is never selected: shown at the end\n", s + 1);
      }
    }
    if (!shots.empty()) {
      return TakeShots(config, tl, shots, *rms::operator_station::ParseCommandFrame(guidance_frame), out_dir, width, height, gl_name);
    }
    auto gl = rms::esg_renderer::CreateGlContext(rms::esg_renderer::ParseGlBackend(gl_name), width, height);
    rms::esg_renderer::FrameRenderer renderer(config, gl.get(), {});
    std::vector<std::string> names;
    for (const auto& c : config.cameras) names.push_back(c.name);
    const rms::esg_renderer::OverlayModel overlay = rms::esg_renderer::MakeOverlayModel(config);
    const int rows = (kN + columns - 1) / columns;
    const int sheet_w = columns * width, sheet_h = rows * height;
    std::vector<std::uint8_t> sheet(static_cast<std::size_t>(sheet_w) * sheet_h * 4, 0);
    std::vector<std::uint8_t> img(static_cast<std::size_t>(width) * height * 4);
    std::array<bool, kN> done{};
    rms::sim::OfflineSession session(config, tl);
    while (session.Next() && !std::all_of(done.begin(), done.end(), [](bool d) { return d; })) {
      for (int s = 1; s <= kN; ++s) {
        if (done[s - 1] || session.t_s() + 1e-9 < when[s - 1]) continue;
        rms::wire::EsgFrameData f = session.esg(s);
        f.control.overlay = true;
        renderer.Render(f);
        std::memcpy(img.data(), renderer.pixels(), img.size());
        rms::esg_renderer::DrawOverlay(img.data(), width, height, f, overlay);
        const std::string path = out_dir + "/station_" + std::to_string(s) + ".png";
        rms::esg_renderer::WritePng(path, width, height, img.data());
        const int x0 = ((s - 1) % columns) * width, y0 = ((s - 1) / columns) * height;
        for (int y = 0; y < height; ++y) {
          std::memcpy(&sheet[(static_cast<std::size_t>(y0 + y) * sheet_w + x0) * 4],
                      &img[static_cast<std::size_t>(y) * width * 4], static_cast<std::size_t>(width) * 4);
        }
        std::printf("%s: station %d (%s) at t = %.2f s, frame %lld\n", path.c_str(), s, names[s - 1].c_str(),
                    session.t_s(), static_cast<long long>(session.frame()));
        done[s - 1] = true;
      }
    }
    rms::esg_renderer::WritePng(out_dir + "/stations.png", sheet_w, sheet_h, sheet.data());
    std::printf("%s/stations.png: the contact sheet, %dx%d\n", out_dir.c_str(), sheet_w, sheet_h);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rms_snapshot: %s\n", e.what());
    return 2;
  }
}
