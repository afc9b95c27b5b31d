// rms_render_bench: what each of the ESG's savings buys over a whole scripted
// mission (docs/esg.md, "Skip what the scene doesn't need"), run time against
// error. The mission is flown in process (OfflineSession: the real DCP and
// Visual Scene Program, the words packed and read back); every frame of the
// selected camera station is drawn by each renderer variant, timed from the
// first GL call to the pixels in memory, and compared pixel by pixel with the
// depth-buffer reference drawn with every cull on.
//
//   build/bench/rms_render_bench [--width 1024 --height 768] [--every 1] [--json out.json]
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "rms/base/check.h"
#include "rms/base/command_line.h"
#include "rms/base/text.h"
#include "rms/esg_renderer/gl_context.h"
#include "rms/esg_renderer/overlay.h"
#include "rms/esg_renderer/png_io.h"
#include "rms/esg_renderer/renderer.h"
#include "rms/sim/offline_session.h"

#include "bench_stats.h"

namespace {

using Clock = std::chrono::steady_clock;
using rms::bench::Mean;
using rms::bench::Percentile;
double Ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

struct Variant {
  std::string name;
  rms::esg_renderer::RenderOptions options;
  std::unique_ptr<rms::esg_renderer::GlContext> gl;
  std::unique_ptr<rms::esg_renderer::FrameRenderer> renderer;
  std::vector<double> ms;
  long clusters = 0, triangles = 0, differing = 0, frames_differing = 0, worst = 0;
};

struct Options {
  std::string config_path = rms::DefaultConfigPath();
  std::string timeline = std::string(RMSLAB_SOURCE_DIR) + "/scripts/timelines/mission.tl";
  int every = 1, width = 1024, height = 768;
  // Idle this long before each variant's frame, as the ESG is between a
  // session's frames (0: back to back, caches and cores warm).
  double pace_ms = 0.0;
  std::string json_out, gl_name = "osmesa", dump_dir, md_path;
  std::vector<std::string> sizes;
};

// What the mission measured beyond each variant's own figures.
struct Mission {
  long frames = 0, unchanged = 0;
  std::vector<double> all_stations_ms, overlay_ms;
};

// The variants, v[0] the reference the others are compared with.
std::vector<Variant> MakeVariants(const rms::LabConfig& config, const Options& o) {
  using rms::esg_renderer::Visibility;
  std::vector<Variant> v;
  auto add = [&](std::string name, Visibility vis, bool frustum, bool backface) {
    Variant x;
    x.name = std::move(name);
    x.options = {
        .visibility = vis, .id_colors = false, .frustum_cull = frustum, .backface_cull = backface};
    v.push_back(std::move(x));
  };
  add("depth buffer, all culls (reference)", Visibility::kDepth, true, true);
  add("priority, all culls (the ESG default)", Visibility::kPriority, true, true);
  add("priority, no frustum cull", Visibility::kPriority, false, true);
  add("priority, no back-face cull", Visibility::kPriority, true, false);
  add("depth buffer, no culls", Visibility::kDepth, false, false);
  for (Variant& x : v) {
    x.gl = rms::esg_renderer::CreateGlContext(rms::esg_renderer::ParseGlBackend(o.gl_name), o.width,
                                              o.height);
    x.renderer = std::make_unique<rms::esg_renderer::FrameRenderer>(config, x.gl.get(), x.options);
  }
  return v;
}

// One frame drawn by every variant, each compared with the reference (kept in `ref`).
void DrawVariants(const rms::wire::EsgFrameData& f, const Options& o, std::vector<Variant>* v,
                  std::vector<std::uint8_t>* ref) {
  const std::size_t n = static_cast<std::size_t>(o.width) * o.height;
  for (std::size_t k = 0; k < v->size(); ++k) {
    Variant& x = (*v)[k];
    if (o.pace_ms > 0)
      std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(o.pace_ms));
    const auto t0 = Clock::now();
    x.renderer->Render(f);
    const std::uint8_t* px = x.renderer->pixels();
    x.ms.push_back(Ms(Clock::now() - t0));
    x.clusters += x.renderer->stats().clusters_drawn;
    x.triangles += x.renderer->stats().triangles_submitted;
    if (k == 0) {
      std::memcpy(ref->data(), px, n * 4);
      continue;
    }
    long d = 0;
    for (std::size_t i = 0; i < n; ++i) d += std::memcmp(px + 4 * i, &(*ref)[4 * i], 3) != 0;
    if (d > x.worst && !o.dump_dir.empty()) {  // the worst frame so far
      const std::string stem = o.dump_dir + "/variant" + std::to_string(k) + "_worst_";
      rms::esg_renderer::WritePng(stem + "variant.png", o.width, o.height, px);
      rms::esg_renderer::WritePng(stem + "reference.png", o.width, o.height, ref->data());
      x.worst = d;
    }
    x.differing += d;
    x.frames_differing += d > 0;
  }
}

// The mission flown; every `every`th frame of the selected station drawn by
// each variant, every station by the default, and an unchanged frame's cost.
Mission FlyMission(const rms::LabConfig& config, const Options& o, std::vector<Variant>* v) {
  rms::sim::OfflineSession session(
      config, rms::operator_station::Timeline::Load(o.timeline, config.inputs));
  const std::size_t n = static_cast<std::size_t>(o.width) * o.height;
  std::vector<std::uint8_t> ref(n * 4), out(n * 4);
  const rms::esg_renderer::OverlayModel overlay = rms::esg_renderer::MakeOverlayModel(config);
  Mission m;
  std::vector<std::int32_t> prev_words;
  while (session.Next()) {
    // Unchanged frames: the selected station's words but for the frame
    // counter (word 0) equal the previous frame's, as esg_renderer tests.
    const std::vector<std::int32_t> words = rms::wire::PackEsgWords(session.esg(), nullptr);
    const bool same =
        !prev_words.empty() && std::equal(words.begin() + 1, words.end(), prev_words.begin() + 1);
    prev_words = words;
    ++m.frames;
    m.unchanged += same;
    if (session.frame() % o.every) continue;
    const rms::wire::EsgFrameData& f = session.esg();
    DrawVariants(f, o, v, &ref);
    // Every station drawn each frame (what the ESG does not do) against the selected one.
    Variant& x = (*v)[1];
    auto t0 = Clock::now();
    for (int s = 1; s <= rms::kNumCameraStations; ++s) {
      x.renderer->Render(session.esg(s));
      x.renderer->pixels();
    }
    m.all_stations_ms.push_back(Ms(Clock::now() - t0));
    // An unchanged frame costs the overlay drawn again over the last output,
    // what lay under its frame counter put back first (as esg_renderer does).
    std::memcpy(out.data(), ref.data(), n * 4);
    rms::esg_renderer::CounterBackdrop backdrop;
    rms::esg_renderer::DrawOverlay(out.data(), o.width, o.height, f, overlay, &backdrop);
    t0 = Clock::now();
    rms::esg_renderer::RestoreCounterBackdrop(out.data(), o.width, o.height, backdrop);
    rms::esg_renderer::DrawOverlay(out.data(), o.width, o.height, f, overlay, &backdrop);
    m.overlay_ms.push_back(Ms(Clock::now() - t0));
  }
  return m;
}

// The figures on the terminal and, with --json, as JSON.
void PrintFigures(const Options& o, const std::vector<Variant>& v, const Mission& m) {
  const long measured = static_cast<long>(v[0].ms.size());
  nlohmann::ordered_json j;
  j["timeline"] = o.timeline;
  j["size"] = {o.width, o.height};
  j["gl"] = v[0].gl->description();
  j["frames"] = m.frames;
  j["frames_measured"] = measured;
  j["pace_ms"] = o.pace_ms;
  std::printf("%s, %dx%d, %s: %ld frames, %ld measured, idle %.1f ms before each\n\n",
              o.timeline.c_str(), o.width, o.height, v[0].gl->description().c_str(), m.frames,
              measured, o.pace_ms);
  std::printf("%-40s %9s %9s %9s %9s %10s %12s %8s\n", "variant (selected station)", "mean ms",
              "p50 ms", "p99 ms", "clusters", "triangles", "px differ", "frames");
  for (const Variant& x : v) {
    const double mean = Mean(x.ms);
    std::printf("%-40s %9.3f %9.3f %9.3f %9.1f %10.1f %12ld %8ld\n", x.name.c_str(), mean,
                Percentile(x.ms, 0.5), Percentile(x.ms, 0.99),
                static_cast<double>(x.clusters) / measured,
                static_cast<double>(x.triangles) / measured, x.differing, x.frames_differing);
    j["variants"].push_back(
        {{"name", x.name},
         {"mean_ms", mean},
         {"p50_ms", Percentile(x.ms, 0.5)},
         {"p99_ms", Percentile(x.ms, 0.99)},
         {"clusters_drawn_mean", static_cast<double>(x.clusters) / measured},
         {"triangles_submitted_mean", static_cast<double>(x.triangles) / measured},
         {"pixels_differing_from_reference", x.differing},
         {"frames_differing_from_reference", x.frames_differing}});
  }
  const double sel = Mean(v[1].ms), all8 = Mean(m.all_stations_ms), ov = Mean(m.overlay_ms);
  const double frac = static_cast<double>(m.unchanged) / m.frames;
  std::printf("\nselected station only: %.3f ms a frame; all eight stations: %.3f ms (x%.1f)\n",
              sel, all8, all8 / sel);
  std::printf(
      "unchanged frames (words 1.. equal the previous frame's): %ld of %ld (%.1f%%); such a frame "
      "costs "
      "%.3f ms (the overlay again) instead of %.3f ms\n",
      m.unchanged, m.frames, 100 * frac, ov, sel);
  std::printf(
      "mission render time with skipping: %.3f ms a frame on average, without: %.3f ms (%.1f%% "
      "saved)\n",
      (1 - frac) * sel + frac * ov, sel, 100 * frac * (sel - ov) / sel);
  j["selected_station_ms"] = sel;
  j["all_stations_ms"] = all8;
  j["unchanged_frames"] = m.unchanged;
  j["unchanged_fraction"] = frac;
  j["unchanged_frame_ms"] = ov;
  j["mean_ms_with_skipping"] = (1 - frac) * sel + frac * ov;
  if (!o.json_out.empty()) std::ofstream(o.json_out) << j.dump(2) << "\n";
}

// docs/performance.md's table of the variants.
void PriorityTable(const Options& o, const std::vector<Variant>& v, const Mission& m,
                   std::ostringstream& md) {
  const long measured = static_cast<long>(v[0].ms.size());
  md << "## Priority rendering against the depth buffer\n\n"
     << rms::Sprintf(
            "`rms_render_bench`: the scripted mission (%s) in process, every %s frame of the "
            "selected "
            "station drawn by each variant at %dx%d (%s), timed from the first GL call to the "
            "pixels in "
            "memory, and compared pixel by pixel with the depth-buffer reference (%ld frames "
            "measured).\n\n",
            std::filesystem::path(o.timeline).filename().c_str(),
            o.every == 1 ? "" : (std::to_string(o.every) + "th").c_str(), o.width, o.height,
            v[0].gl->description().c_str(), measured)
     << "| variant | mean ms | p50 ms | p99 ms | clusters drawn | triangles | pixels differing | "
        "frames differing |\n"
     << "|---|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Variant& x : v) {
    md << rms::Sprintf(
        "| %s | %.3f | %.3f | %.3f | %.1f | %.1f | %ld | %ld |\n", x.name.c_str(), Mean(x.ms),
        Percentile(x.ms, 0.5), Percentile(x.ms, 0.99), static_cast<double>(x.clusters) / measured,
        static_cast<double>(x.triangles) / measured, x.differing, x.frames_differing);
  }
  const double sel = Mean(v[1].ms), all8 = Mean(m.all_stations_ms), ov = Mean(m.overlay_ms);
  const double frac = static_cast<double>(m.unchanged) / m.frames;
  md << rms::Sprintf(
      "\nEvery station drawn each frame: %.3f ms against %.3f ms for the selected one (x%.1f). "
      "Unchanged frames: %ld of %ld (%.1f%%), each costing %.3f ms (the overlay again): %.3f ms a "
      "frame "
      "on average with skipping, %.3f without.\n\n",
      all8, sel, all8 / sel, m.unchanged, m.frames, 100 * frac, ov, (1 - frac) * sel + frac * ov,
      sel);
}

// The ESG's default and the depth buffer at each --sizes size, every 10th frame.
void ResolutionTable(const rms::LabConfig& config, const Options& o, const std::vector<Variant>& v,
                     std::ostringstream& md) {
  md << "## Render resolution against frame time\n\n"
     << "The same mission, every 10th frame, the ESG's default (priority, all culls) and the depth "
        "buffer:\n\n"
     << "| size | pixels | priority mean ms | priority p99 ms | depth buffer mean ms | depth "
        "buffer p99 ms |\n"
     << "|---|---:|---:|---:|---:|---:|\n";
  for (const std::string& wh : o.sizes) {
    int w = 0, h = 0;
    if (std::sscanf(wh.c_str(), "%dx%d", &w, &h) != 2 || w <= 0 || h <= 0) {
      throw rms::InputError("--sizes: '" + wh + "' is not WIDTHxHEIGHT");
    }
    rms::sim::OfflineSession sz(config,
                                rms::operator_station::Timeline::Load(o.timeline, config.inputs));
    std::vector<double> ms[2];
    std::unique_ptr<rms::esg_renderer::GlContext> gl[2];
    std::unique_ptr<rms::esg_renderer::FrameRenderer> r[2];
    for (int k = 0; k < 2; ++k) {
      gl[k] =
          rms::esg_renderer::CreateGlContext(rms::esg_renderer::ParseGlBackend(o.gl_name), w, h);
      r[k] = std::make_unique<rms::esg_renderer::FrameRenderer>(config, gl[k].get(),
                                                                k ? v[0].options : v[1].options);
    }
    while (sz.Next()) {
      if (sz.frame() % 10) continue;
      for (int k = 0; k < 2; ++k) {
        const auto t0 = Clock::now();
        r[k]->Render(sz.esg());
        r[k]->pixels();
        ms[k].push_back(Ms(Clock::now() - t0));
      }
    }
    md << rms::Sprintf("| %dx%d | %d | %.3f | %.3f | %.3f | %.3f |\n", w, h, w * h, Mean(ms[0]),
                       Percentile(ms[0], 0.99), Mean(ms[1]), Percentile(ms[1], 0.99));
  }
  md << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab rms_render_bench: the ESG's savings (frustum cull, back-face cull, priority instead "
      "of a "
      "depth buffer, the selected station only, unchanged frames not redrawn) measured over a "
      "mission"};
  Options o;
  app.add_option("--config", o.config_path, "Configuration file")->capture_default_str();
  app.add_option("--timeline", o.timeline, "Timeline to fly")->capture_default_str();
  app.add_option("--every", o.every, "Measure every Nth frame")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--width", o.width, "Image width")->capture_default_str();
  app.add_option("--height", o.height, "Image height")->capture_default_str();
  app.add_option("--gl", o.gl_name, "GL backend: osmesa or egl")->capture_default_str();
  app.add_option("--json", o.json_out, "Also write the figures as JSON to this file");
  app.add_option("--dump", o.dump_dir,
                 "Write each variant's worst frame, and the reference's, as PNG here");
  app.add_option(
         "--pace-ms", o.pace_ms,
         "Idle this long before each variant's frame, as the ESG between a session's frames "
         "(33 at 30 Hz; 0: back to back)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  app.add_option("--md", o.md_path, "Write the tables as markdown to this file");
  app.add_option("--sizes", o.sizes,
                 "Also time the ESG's default renderer and the depth buffer at these sizes (WxH)");
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  try {
    const rms::LabConfig config = rms::LoadConfig(o.config_path);
    std::vector<Variant> v = MakeVariants(config, o);
    const Mission m = FlyMission(config, o, &v);
    PrintFigures(o, v, m);
    std::ostringstream md;
    PriorityTable(o, v, m, md);
    if (!o.sizes.empty()) ResolutionTable(config, o, v, md);
    if (!o.md_path.empty()) std::ofstream(o.md_path) << md.str();
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rms_render_bench: %s\n", e.what());
    return 2;
  }
}
