#include "rms/scene_model/separating_plane.h"

#include <algorithm>
#include <limits>

#include "rms/scene_model/scene_model.h"

namespace rms::scene_model {

namespace {

void Range(const PosedHull& h, const Eigen::Vector3d& n, double* lo, double* hi) {
  *lo = std::numeric_limits<double>::infinity();
  *hi = -*lo;
  for (const auto& p : h.points_R) {
    const double v = n.dot(p);
    *lo = std::min(*lo, v);
    *hi = std::max(*hi, v);
  }
}

// Frame coherence: last frame's plane, if it still separates.
bool HintSeparates(const PosedHull& a, const PosedHull& b, const SeparatingPlane& hint,
                   double eps) {
  double alo, ahi, blo, bhi;
  Range(a, hint.n_R, &alo, &ahi);
  Range(b, hint.n_R, &blo, &bhi);
  return ahi <= hint.d_ft + eps && blo >= hint.d_ft - eps;
}

}  // namespace

PosedHull PoseHull(const Cluster& c, const Eigen::Affine3d& X_RC) {
  PosedHull h;
  h.points_R.reserve(c.points.size());
  for (const auto& p : c.points) {
    h.points_R.push_back(X_RC * p);
    h.centroid_R += h.points_R.back();
  }
  if (!h.points_R.empty()) h.centroid_R /= static_cast<double>(h.points_R.size());
  // Normals and edges: the linear part may scale (the post), which keeps
  // axis-aligned box normals; directions are renormalised.
  const Eigen::Matrix3d M = X_RC.linear();
  const Eigen::Matrix3d N = M.inverse().transpose();
  for (const auto& n : c.normals) h.normals_R.push_back((N * n).normalized());
  for (const auto& e : c.edges) h.edges_R.push_back((M * e).normalized());
  for (const auto& p : h.points_R) h.scale_ft = std::max(h.scale_ft, (p - h.centroid_R).norm());
  return h;
}

std::optional<SeparatingPlane> FindSeparatingPlane(const PosedHull& a, const PosedHull& b,
                                                   double eps, const SeparatingPlane* hint,
                                                   int* axes_tried) {
  int tried = 0;
  double best_gap = -std::numeric_limits<double>::infinity();
  SeparatingPlane best;
  auto consider = [&](Eigen::Vector3d n) {
    const double len = n.norm();
    if (!(len > 1e-12)) return false;
    n /= len;
    ++tried;
    double alo, ahi, blo, bhi;
    Range(a, n, &alo, &ahi);
    Range(b, n, &blo, &bhi);
    if (blo - ahi > best_gap) {
      best_gap = blo - ahi;
      best = {n, 0.5 * (ahi + blo)};
    }
    if (alo - bhi > best_gap) {
      best_gap = alo - bhi;
      best = {-n, -0.5 * (bhi + alo)};
    }
    return best_gap >= -eps;
  };
  auto done = [&]() -> std::optional<SeparatingPlane> {
    if (axes_tried) *axes_tried = tried;
    if (best_gap >= -eps) return best;
    return std::nullopt;
  };
  if (hint) {
    ++tried;
    if (HintSeparates(a, b, *hint, eps)) {
      if (axes_tried) *axes_tried = tried;
      return *hint;
    }
  }
  consider(b.centroid_R - a.centroid_R);
  for (const auto& n : a.normals_R) consider(n);
  for (const auto& n : b.normals_R) consider(n);
  if (best_gap >= -eps) return done();
  for (const auto& ea : a.edges_R) {
    for (const auto& eb : b.edges_R) {
      if (consider(ea.cross(eb))) return done();
    }
  }
  return done();
}

}  // namespace rms::scene_model
