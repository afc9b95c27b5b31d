// rms_visibility: visual priority (separating planes, no depth buffer)
// against the depth-buffer reference over a whole scripted mission, from
// every camera station: the pixels on which the two disagree, per camera.
#include <CLI/CLI.hpp>
#include "rms/base/command_line.h"
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <map>
#include <tuple>
#include <nlohmann/json.hpp>

#include "rms/esg_renderer/gl_context.h"
#include "rms/sim/offline_session.h"
#include "rms/esg_renderer/renderer.h"
#include "rms/base/check.h"

namespace {

// The nearest hit (distance along the unit ray) of a ray from the eye with a
// cluster's faces (Moller-Trumbore on each triangle), or +inf.
double NearestHit(const rms::scene_model::Cluster& c, const Eigen::Affine3d& X, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  double best = std::numeric_limits<double>::infinity();
  for (const rms::scene_model::Triangle& t : c.mesh.triangles()) {
    if (t.decal) continue;
    const Eigen::Vector3d a = X * t.a.cast<double>(), b = X * t.b.cast<double>(), cc = X * t.c.cast<double>();
    const Eigen::Vector3d e1 = b - a, e2 = cc - a, p = d.cross(e2);
    const double det = e1.dot(p);
    if (std::abs(det) < 1e-14) continue;
    const Eigen::Vector3d s = o - a;
    const double u = s.dot(p) / det;
    if (u < 0 || u > 1) continue;
    const Eigen::Vector3d q = s.cross(e1);
    const double v = d.dot(q) / det;
    if (v < 0 || u + v > 1) continue;
    const double tt = e2.dot(q) / det;
    if (tt > 0.5 && tt < best) best = tt;  // beyond the near plane
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rmslab rms_visibility: priority rendering (separating planes, no depth buffer) against the "
               "depth buffer over a mission from every camera station. Each differing pixel is judged by an exact "
               "ray cast through its centre. Exits 1 if any pixel is a priority error."};
  std::string config_path = rms::DefaultConfigPath();
  std::string timeline = std::string(RMSLAB_SOURCE_DIR) + "/scripts/timelines/mission.tl";
  int every = 1, width = 1024, height = 768;
  std::string json_out;
  bool explain = false;
  std::string gl_name = "osmesa";
  app.add_option("--config", config_path, "Configuration file")->capture_default_str();
  app.add_option("--timeline", timeline, "Timeline to fly")->capture_default_str();
  app.add_option("--every", every, "Check every Nth frame")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--width", width, "Image width")->capture_default_str();
  app.add_option("--height", height, "Image height")->capture_default_str();
  app.add_option("--json", json_out, "Also write the figures as JSON to this file");
  app.add_option("--gl", gl_name, "GL backend: osmesa or egl")->capture_default_str();
  app.add_flag("--explain", explain, "List the cluster pairs (priority / depth) on the differing pixels");
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  try {
    const rms::LabConfig config = rms::LoadConfig(config_path);
    rms::sim::OfflineSession session(config, rms::operator_station::Timeline::Load(timeline, config.inputs));
    auto ga = rms::esg_renderer::CreateGlContext(rms::esg_renderer::ParseGlBackend(gl_name), width, height);
    auto gb = rms::esg_renderer::CreateGlContext(rms::esg_renderer::ParseGlBackend(gl_name), width, height);
    rms::esg_renderer::FrameRenderer prio(config, ga.get(), {.visibility = rms::esg_renderer::Visibility::kPriority, .id_colors = true});
    rms::esg_renderer::FrameRenderer depth(config, gb.get(), {.visibility = rms::esg_renderer::Visibility::kDepth, .id_colors = true});
    struct PerCamera {
      long frames = 0, pixels = 0, differing = 0, frames_differing = 0, cycles = 0;
      long priority_errors = 0;   // the exact ray cast sides with the depth buffer
      long reference_errors = 0;  // the exact ray cast sides with priority
      long silhouette_ties = 0;   // within 1/64 pixel of a silhouette: the rasteriser's precision
    };
    const rms::scene_model::SceneModel model = rms::scene_model::BuildSceneModel(config);
    std::array<PerCamera, rms::kNumCameraStations> per{};
    const std::size_t n = static_cast<std::size_t>(width) * height;
    std::vector<std::uint8_t> a(n * 4);
    std::map<std::tuple<int, int, int>, long> pairs;  // station, priority cluster, depth cluster
    while (session.Next()) {
      if (session.frame() % every) continue;
      for (int s = 1; s <= rms::kNumCameraStations; ++s) {
        const rms::wire::EsgFrameData& f = session.esg(s);
        prio.Render(f);
        std::memcpy(a.data(), prio.pixels(), n * 4);
        depth.Render(f);
        const std::uint8_t* b = depth.pixels();
        long diff = 0;
        PerCamera& pc = per[s - 1];
        std::optional<rms::scene_model::ClusterPoses> poses;
        for (std::size_t i = 0; i < n; ++i) {
          if (std::memcmp(&a[4 * i], b + 4 * i, 3) == 0) continue;
          ++diff;
          const int cp = rms::esg_renderer::ClusterOfColor(&a[4 * i]), cd = rms::esg_renderer::ClusterOfColor(b + 4 * i);
          if (explain) ++pairs[{s, cp, cd}];
          // The arbiter: which of the two does the exact ray through the
          // pixel's centre meet first?
          if (!poses) poses = rms::scene_model::ComputeClusterPoses(config, f.scene_pose());
          const double tan_half = std::tan(0.5 * f.fov_deg * M_PI / 180.0);
          const int px = static_cast<int>(i % width), py = static_cast<int>(i / width);
          const double inf = std::numeric_limits<double>::infinity();
          // Does the priority cluster win the exact ray through (px + 0.5 + dx, py + 0.5 + dy)?
          auto priority_wins = [&](double dx, double dy) {
            const double xn = 2.0 * (px + 0.5 + dx) / width - 1.0, yn = 1.0 - 2.0 * (py + 0.5 + dy) / height;
            const Eigen::Vector3d dir =
                (f.R_RE * Eigen::Vector3d(1.0, xn * tan_half * width / height, -yn * tan_half)).normalized();
            const double tp = cp < 0 ? inf : NearestHit(model[cp], poses->X_RC[cp], f.p_RoEye_R_ft, dir);
            const double td = cd < 0 ? inf : NearestHit(model[cd], poses->X_RC[cd], f.p_RoEye_R_ft, dir);
            return tp <= td && tp < inf;
          };
          constexpr double kEdge = 1.0 / 64;  // the rasteriser's sub-pixel precision, generously
          if (priority_wins(0, 0)) {
            ++pc.reference_errors;
          } else if (priority_wins(kEdge, 0) || priority_wins(-kEdge, 0) || priority_wins(0, kEdge) ||
                     priority_wins(0, -kEdge)) {
            ++pc.silhouette_ties;
          } else {
            ++pc.priority_errors;
          }
        }
        ++pc.frames;
        pc.pixels += static_cast<long>(n);
        pc.differing += diff;
        pc.frames_differing += diff > 0;
        pc.cycles += prio.stats().cycles_broken;
      }
    }
    nlohmann::ordered_json j;
    j["timeline"] = timeline;
    j["every"] = every;
    j["size"] = {width, height};
    long total = 0, total_priority_errors = 0;
    std::printf("%-36s %8s %14s %10s %8s %8s %9s %9s %9s\n", "camera station", "frames", "pixels", "differing",
                "frames", "cycles", "prio err", "depth err", "edge tie");
    for (int s = 0; s < rms::kNumCameraStations; ++s) {
      const PerCamera& pc = per[s];
      std::printf("%d %-34s %8ld %14ld %10ld %8ld %8ld %9ld %9ld %9ld\n", s + 1, config.cameras[s].name.c_str(), pc.frames,
                  pc.pixels, pc.differing, pc.frames_differing, pc.cycles, pc.priority_errors, pc.reference_errors,
                  pc.silhouette_ties);
      j["cameras"].push_back({{"station", s + 1}, {"name", config.cameras[s].name}, {"frames", pc.frames},
                              {"pixels", pc.pixels}, {"differing_pixels", pc.differing},
                              {"frames_with_differences", pc.frames_differing}, {"cycles_broken", pc.cycles},
                              {"priority_errors", pc.priority_errors}, {"depth_reference_errors", pc.reference_errors},
                              {"silhouette_ties", pc.silhouette_ties}});
      total += pc.differing;
      total_priority_errors += pc.priority_errors;
    }
    j["differing_pixels"] = total;
    j["priority_errors"] = total_priority_errors;
    std::printf("total differing pixels: %ld; priority errors (the exact ray sides with the depth buffer): %ld\n", total,
                total_priority_errors);
    if (explain) {
      for (const auto& [k, count] : pairs) {
        const auto& [st, pc, dc] = k;
        std::printf("  station %d: %s drawn where the depth buffer shows %s: %ld px\n", st,
                    pc < 0 ? "sky" : std::string(rms::scene_model::ClusterName(pc)).c_str(),
                    dc < 0 ? "sky" : std::string(rms::scene_model::ClusterName(dc)).c_str(), count);
      }
    }
    if (!json_out.empty()) std::ofstream(json_out) << j.dump(2) << "\n";
    return total_priority_errors == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rms_visibility: %s\n", e.what());
    return 2;
  }
}
