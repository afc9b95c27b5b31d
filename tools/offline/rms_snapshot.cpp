// rms_snapshot: pictures of a mission from every camera station, rendered
// exactly as esg_renderer renders them (the same words, renderer and
// overlay). By default each station is shown in the middle of the mission's
// first visit to it (or, with --time, all at one moment); one PNG a station
// and a contact sheet of all eight. The README's pictures come from
//   build/tools/rms_snapshot --out-dir docs/images
#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <optional>

#include "gl_context.h"
#include "offline_session.h"
#include "overlay.h"
#include "png_io.h"
#include "renderer.h"

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
  CLI11_PARSE(app, argc, argv);
  try {
    const rms::LabConfig config = rms::LoadConfig(config_path);
    const rms::op::Timeline tl = rms::op::Timeline::Load(timeline, config.inputs);
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
      rms::offline::OfflineSession scan(config, tl);
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
    auto gl = rms::esg::CreateGlContext(rms::esg::ParseGlBackend(gl_name), width, height);
    rms::esg::EsgRenderer renderer(config, gl.get(), {});
    std::vector<std::string> names;
    for (const auto& c : config.cameras) names.push_back(c.name);
    const int rows = (kN + columns - 1) / columns;
    const int sheet_w = columns * width, sheet_h = rows * height;
    std::vector<std::uint8_t> sheet(static_cast<std::size_t>(sheet_w) * sheet_h * 4, 0);
    std::vector<std::uint8_t> img(static_cast<std::size_t>(width) * height * 4);
    std::array<bool, kN> done{};
    rms::offline::OfflineSession session(config, tl);
    while (session.Next() && !std::all_of(done.begin(), done.end(), [](bool d) { return d; })) {
      for (int s = 1; s <= kN; ++s) {
        if (done[s - 1] || session.t_s() + 1e-9 < when[s - 1]) continue;
        rms::EsgFrameData f = session.esg(s);
        f.control.overlay = true;
        renderer.Render(f);
        std::memcpy(img.data(), renderer.pixels(), img.size());
        rms::esg::DrawOverlay(img.data(), width, height, f, names);
        const std::string path = out_dir + "/station_" + std::to_string(s) + ".png";
        rms::esg::WritePng(path, width, height, img.data());
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
    rms::esg::WritePng(out_dir + "/stations.png", sheet_w, sheet_h, sheet.data());
    std::printf("%s/stations.png: the contact sheet, %dx%d\n", out_dir.c_str(), sheet_w, sheet_h);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rms_snapshot: %s\n", e.what());
    return 2;
  }
}
