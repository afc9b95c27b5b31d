#include "rms/sim/visibility.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <vector>

#include "rms/esg_renderer/gl_context.h"
#include "rms/esg_renderer/renderer.h"
#include "rms/scene_model/scene_model.h"
#include "rms/sim/offline_session.h"

namespace rms::sim {

namespace {

// The nearest hit (distance along the unit ray) of a ray from the eye with a
// cluster's faces (Moller-Trumbore on each triangle), or +inf.
double NearestHit(const scene_model::Cluster& c, const Eigen::Affine3d& X, const Eigen::Vector3d& o,
                  const Eigen::Vector3d& d) {
  double best = std::numeric_limits<double>::infinity();
  for (const scene_model::Triangle& t : c.mesh.triangles()) {
    if (t.decal) continue;
    const Eigen::Vector3d a = X * t.a.cast<double>(), b = X * t.b.cast<double>(),
                          cc = X * t.c.cast<double>();
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

// Which of the two a differing pixel should show: the exact ray through its
// centre (and, at a silhouette, within 1/64 pixel of it) decides.
struct PixelJudge {
  const scene_model::SceneModel& model;
  const scene_model::ClusterPoses& poses;
  const wire::EsgFrameData& f;
  int width, height;

  // Does cluster cp (priority's) win the exact ray through (px + 0.5 + dx,
  // py + 0.5 + dy) against cd (the depth buffer's)?
  bool PriorityWins(int cp, int cd, int px, int py, double dx, double dy) const {
    const double inf = std::numeric_limits<double>::infinity();
    const double tan_half = std::tan(0.5 * f.fov_deg * M_PI / 180.0);
    const double xn = 2.0 * (px + 0.5 + dx) / width - 1.0,
                 yn = 1.0 - 2.0 * (py + 0.5 + dy) / height;
    const Eigen::Vector3d dir =
        (f.R_RE * Eigen::Vector3d(1.0, xn * tan_half * width / height, -yn * tan_half))
            .normalized();
    const double tp = cp < 0 ? inf : NearestHit(model[cp], poses.X_RC[cp], f.p_RoEye_R_ft, dir);
    const double td = cd < 0 ? inf : NearestHit(model[cd], poses.X_RC[cd], f.p_RoEye_R_ft, dir);
    return tp <= td && tp < inf;
  }

  void Judge(int cp, int cd, std::size_t i, StationVisibility* pc) const {
    const int px = static_cast<int>(i % width), py = static_cast<int>(i / width);
    constexpr double kEdge = 1.0 / 64;  // the rasteriser's sub-pixel precision, generously
    if (PriorityWins(cp, cd, px, py, 0, 0)) {
      ++pc->reference_errors;
    } else if (PriorityWins(cp, cd, px, py, kEdge, 0) || PriorityWins(cp, cd, px, py, -kEdge, 0) ||
               PriorityWins(cp, cd, px, py, 0, kEdge) || PriorityWins(cp, cd, px, py, 0, -kEdge)) {
      ++pc->silhouette_ties;
    } else {
      ++pc->priority_errors;
    }
  }
};

}  // namespace

VisibilityReport CompareVisibility(const LabConfig& config, const VisibilityOptions& o) {
  OfflineSession session(config, operator_station::Timeline::Load(o.timeline, config.inputs));
  auto ga = esg_renderer::CreateGlContext(esg_renderer::ParseGlBackend(o.gl), o.width, o.height);
  auto gb = esg_renderer::CreateGlContext(esg_renderer::ParseGlBackend(o.gl), o.width, o.height);
  esg_renderer::FrameRenderer prio(
      config, ga.get(), {.visibility = esg_renderer::Visibility::kPriority, .id_colors = true});
  esg_renderer::FrameRenderer depth(
      config, gb.get(), {.visibility = esg_renderer::Visibility::kDepth, .id_colors = true});
  const scene_model::SceneModel model = scene_model::BuildSceneModel(config);
  VisibilityReport report;
  const std::size_t n = static_cast<std::size_t>(o.width) * o.height;
  std::vector<std::uint8_t> a(n * 4);
  while (session.Next()) {
    if (session.frame() % o.every) continue;
    for (int s = 1; s <= kNumCameraStations; ++s) {
      const wire::EsgFrameData& f = session.esg(s);
      prio.Render(f);
      std::memcpy(a.data(), prio.pixels(), n * 4);
      depth.Render(f);
      const std::uint8_t* b = depth.pixels();
      long diff = 0;
      StationVisibility& pc = report.stations[s - 1];
      std::optional<scene_model::ClusterPoses> poses;
      for (std::size_t i = 0; i < n; ++i) {
        if (std::memcmp(&a[4 * i], b + 4 * i, 3) == 0) continue;
        ++diff;
        const int cp = esg_renderer::ClusterOfColor(&a[4 * i]),
                  cd = esg_renderer::ClusterOfColor(b + 4 * i);
        if (o.explain) ++report.pairs[{s, cp, cd}];
        if (!poses) poses = scene_model::ComputeClusterPoses(config, f.scene_pose());
        PixelJudge{model, *poses, f, o.width, o.height}.Judge(cp, cd, i, &pc);
      }
      ++pc.frames;
      pc.pixels += static_cast<long>(n);
      pc.differing += diff;
      pc.frames_differing += diff > 0;
      pc.cycles += prio.stats().cycles_broken;
    }
  }
  return report;
}

}  // namespace rms::sim
