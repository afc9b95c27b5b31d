// rms_visibility: visual priority (separating planes, no depth buffer)
// against the depth-buffer reference over a whole scripted mission, from
// every camera station: the pixels on which the two disagree, per camera
// (rms/sim/visibility.h; docs/scene.md).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "rms/base/check.h"
#include "rms/base/command_line.h"
#include "rms/scene_model/scene_model.h"
#include "rms/sim/visibility.h"

namespace {

// The table on the terminal, and its figures as JSON; the priority errors.
long Print(const rms::LabConfig& config, const rms::sim::VisibilityOptions& o,
           const rms::sim::VisibilityReport& r, nlohmann::ordered_json* j) {
  (*j)["timeline"] = o.timeline;
  (*j)["every"] = o.every;
  (*j)["size"] = {o.width, o.height};
  long total = 0, total_priority_errors = 0;
  std::printf("%-36s %8s %14s %10s %8s %8s %9s %9s %9s\n", "camera station", "frames", "pixels",
              "differing", "frames", "cycles", "prio err", "depth err", "edge tie");
  for (int s = 0; s < rms::kNumCameraStations; ++s) {
    const rms::sim::StationVisibility& pc = r.stations[s];
    std::printf("%d %-34s %8ld %14ld %10ld %8ld %8ld %9ld %9ld %9ld\n", s + 1,
                config.cameras[s].name.c_str(), pc.frames, pc.pixels, pc.differing,
                pc.frames_differing, pc.cycles, pc.priority_errors, pc.reference_errors,
                pc.silhouette_ties);
    (*j)["cameras"].push_back({{"station", s + 1},
                               {"name", config.cameras[s].name},
                               {"frames", pc.frames},
                               {"pixels", pc.pixels},
                               {"differing_pixels", pc.differing},
                               {"frames_with_differences", pc.frames_differing},
                               {"cycles_broken", pc.cycles},
                               {"priority_errors", pc.priority_errors},
                               {"depth_reference_errors", pc.reference_errors},
                               {"silhouette_ties", pc.silhouette_ties}});
    total += pc.differing;
    total_priority_errors += pc.priority_errors;
  }
  (*j)["differing_pixels"] = total;
  (*j)["priority_errors"] = total_priority_errors;
  std::printf(
      "total differing pixels: %ld; priority errors (the exact ray sides with the depth buffer): "
      "%ld\n",
      total, total_priority_errors);
  for (const auto& [k, count] : r.pairs) {
    const auto& [st, pc, dc] = k;
    std::printf("  station %d: %s drawn where the depth buffer shows %s: %ld px\n", st,
                pc < 0 ? "sky" : std::string(rms::scene_model::ClusterName(pc)).c_str(),
                dc < 0 ? "sky" : std::string(rms::scene_model::ClusterName(dc)).c_str(), count);
  }
  return total_priority_errors;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab rms_visibility: priority rendering (separating planes, no depth buffer) against the "
      "depth buffer over a mission from every camera station. Each differing pixel is judged by an "
      "exact "
      "ray cast through its centre. Exits 1 if any pixel is a priority error."};
  std::string config_path = rms::DefaultConfigPath();
  rms::sim::VisibilityOptions o;
  o.timeline = std::string(RMSLAB_SOURCE_DIR) + "/scripts/timelines/mission.tl";
  std::string json_out;
  app.add_option("--config", config_path, "Configuration file")->capture_default_str();
  app.add_option("--timeline", o.timeline, "Timeline to fly")->capture_default_str();
  app.add_option("--every", o.every, "Check every Nth frame")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--width", o.width, "Image width")->capture_default_str();
  app.add_option("--height", o.height, "Image height")->capture_default_str();
  app.add_option("--json", json_out, "Also write the figures as JSON to this file");
  app.add_option("--gl", o.gl, "GL backend: osmesa or egl")->capture_default_str();
  app.add_flag("--explain", o.explain,
               "List the cluster pairs (priority / depth) on the differing pixels");
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  try {
    const rms::LabConfig config = rms::LoadConfig(config_path);
    nlohmann::ordered_json j;
    const long errors = Print(config, o, rms::sim::CompareVisibility(config, o), &j);
    if (!json_out.empty()) std::ofstream(json_out) << j.dump(2) << "\n";
    return errors == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rms_visibility: %s\n", e.what());
    return 2;
  }
}
