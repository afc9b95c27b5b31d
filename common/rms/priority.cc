#include "rms/priority.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <spdlog/spdlog.h>

#include "rms/check.h"

namespace rms {

std::pair<int, int> PairOf(int index) {
  for (int a = 0; a < kNumClusters; ++a) {
    const int first = PairIndex(a, a + 1);
    const int count = kNumClusters - a - 1;
    if (index < first + count) return {a, a + 1 + (index - first)};
  }
  RMS_CHECK(false);
  return {0, 0};
}

const char* PlaneSourceName(PlaneSource s) {
  switch (s) {
    case PlaneSource::kFixed: return "fixed";
    case PlaneSource::kRigid: return "rigid";
    case PlaneSource::kDcp: return "DCP";
    case PlaneSource::kDynamic: return "dynamic";
  }
  return "?";
}

namespace {

int DcpPairSlot(int pair) {
  for (int k = 0; k < 3; ++k) {
    if (PairIndex(kDcpPairs[k].first, kDcpPairs[k].second) == pair) return k;
  }
  return -1;
}

// The wire position of every non-DCP pair, in pair order.
struct WireLayout {
  std::array<int, kNumPairs> slot{};  // -1 for DCP pairs
  WireLayout() {
    int k = 0;
    for (int p = 0; p < kNumPairs; ++p) slot[p] = DcpPairSlot(p) >= 0 ? -1 : k++;
  }
};
const WireLayout& Layout() {
  static const WireLayout layout;
  return layout;
}

// Frames that move together: fixed clusters; the payload; the wrist, palm
// and fixed finger; the elbow and the lower boom.
int RigidGroup(ClusterFrame f) {
  switch (f) {
    case ClusterFrame::kReference:
    case ClusterFrame::kCae: return 0;
    case ClusterFrame::kPayload: return 1;
    case ClusterFrame::kF6:
    case ClusterFrame::kSystemTwo: return 2;
    case ClusterFrame::kF3: return 3;
    default: return -1;  // scaled (the post) or alone
  }
}

// How far two clusters may overlap and still be "touching": the ESG words
// carry positions to 2.4e-4 ft (FT12), so touching parts can come out that
// far into each other.
double PlaneTolerance(const PosedHull& a, const PosedHull& b) {
  return std::max(1e-6 * std::max(a.scale, b.scale), 5e-4);
}

void Range(const PosedHull& h, const Eigen::Vector3d& n, double* lo, double* hi) {
  *lo = std::numeric_limits<double>::infinity();
  *hi = -*lo;
  for (const auto& p : h.points) {
    const double v = n.dot(p);
    *lo = std::min(*lo, v);
    *hi = std::max(*hi, v);
  }
}

}  // namespace

void PackPriority(const PriorityBits& bits, ControlWord* cw,
                  std::array<std::int32_t, esg_words::kPriorityCount>* words) {
  cw->priority_dynamic = 0;
  cw->priority_fixed = 0;
  words->fill(0);
  for (int k = 0; k < 3; ++k) {
    if (bits[PairIndex(kDcpPairs[k].first, kDcpPairs[k].second)]) cw->priority_dynamic |= 1u << k;
  }
  const WireLayout& L = Layout();
  for (int p = 0; p < kNumPairs; ++p) {
    const int s = L.slot[p];
    if (s < 0 || !bits[p]) continue;
    if (s < 7) cw->priority_fixed |= 1u << s;
    else (*words)[(s - 7) / 24] |= static_cast<std::int32_t>(1u << ((s - 7) % 24));
  }
}

std::string PriorityBitPlace(int pair) {
  const int k = DcpPairSlot(pair);
  if (k >= 0) return "control word bit " + std::to_string(control_bits::kPriorityDynamicShift + k);
  const int s = Layout().slot[pair];
  if (s < 7) return "control word bit " + std::to_string(control_bits::kPriorityFixedShift + s);
  return "ESG word " + std::to_string(esg_words::kPriority + (s - 7) / 24) + " bit " + std::to_string((s - 7) % 24);
}

PriorityBits UnpackPriority(const ControlWord& cw, std::span<const std::int32_t> words) {
  PriorityBits bits;
  for (int k = 0; k < 3; ++k) {
    if (cw.priority_dynamic & (1u << k)) bits.set(PairIndex(kDcpPairs[k].first, kDcpPairs[k].second));
  }
  const WireLayout& L = Layout();
  for (int p = 0; p < kNumPairs; ++p) {
    const int s = L.slot[p];
    if (s < 0) continue;
    const bool on = s < 7 ? (cw.priority_fixed >> s) & 1u
                          : (static_cast<std::uint32_t>(words[(s - 7) / 24]) >> ((s - 7) % 24)) & 1u;
    if (on) bits.set(p);
  }
  return bits;
}

PosedHull PoseHull(const Cluster& c, const Eigen::Affine3d& X) {
  PosedHull h;
  h.points.reserve(c.points.size());
  for (const auto& p : c.points) {
    h.points.push_back(X * p);
    h.centroid += h.points.back();
  }
  if (!h.points.empty()) h.centroid /= static_cast<double>(h.points.size());
  // Normals and edges: the linear part may scale (the post), which keeps
  // axis-aligned box normals; directions are renormalised.
  const Eigen::Matrix3d M = X.linear();
  const Eigen::Matrix3d N = M.inverse().transpose();
  for (const auto& n : c.normals) h.normals.push_back((N * n).normalized());
  for (const auto& e : c.edges) h.edges.push_back((M * e).normalized());
  for (const auto& p : h.points) h.scale = std::max(h.scale, (p - h.centroid).norm());
  return h;
}

std::optional<Plane> FindSeparatingPlane(const PosedHull& a, const PosedHull& b, double eps,
                                         const Plane* hint, int* axes_tried) {
  int tried = 0;
  double best_gap = -std::numeric_limits<double>::infinity();
  Plane best;
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
  auto done = [&]() -> std::optional<Plane> {
    if (axes_tried) *axes_tried = tried;
    if (best_gap >= -eps) return best;
    return std::nullopt;
  };
  if (hint) {
    // Frame coherence: last frame's plane, if it still separates.
    double alo, ahi, blo, bhi;
    Range(a, hint->n, &alo, &ahi);
    Range(b, hint->n, &blo, &bhi);
    ++tried;
    if (ahi <= hint->d + eps && blo >= hint->d - eps) {
      if (axes_tried) *axes_tried = tried;
      return *hint;
    }
  }
  consider(b.centroid - a.centroid);
  for (const auto& n : a.normals) consider(n);
  for (const auto& n : b.normals) consider(n);
  if (best_gap >= -eps) return done();
  for (const auto& ea : a.edges) {
    for (const auto& eb : b.edges) {
      if (consider(ea.cross(eb))) return done();
    }
  }
  return done();
}

PriorityPlanner::PriorityPlanner(const SceneModel& model) : model_(model) {
  for (int p = 0; p < kNumPairs; ++p) {
    const auto [a, b] = PairOf(p);
    const int ga = RigidGroup(model[a].frame), gb = RigidGroup(model[b].frame);
    if (DcpPairSlot(p) >= 0) source_[p] = PlaneSource::kDcp;
    else if (ga == 0 && gb == 0) source_[p] = PlaneSource::kFixed;
    else if (ga >= 0 && ga == gb) source_[p] = PlaneSource::kRigid;
    else source_[p] = PlaneSource::kDynamic;
  }
}

PriorityBits PriorityPlanner::Compute(const ClusterPoses& poses, const Eigen::Vector3d& eye,
                                      const std::array<SeparatingPlane, 3>& dcp_planes,
                                      std::uint32_t dcp_valid, Counters* counters) {
  // Fixed and rigid planes are found the first time they are needed, from
  // that frame's poses, and kept in the first cluster's frame.
  std::array<std::optional<PosedHull>, kNumClusters> hulls;
  auto hull = [&](int c) -> const PosedHull& {
    if (!hulls[c]) hulls[c] = PoseHull(model_[c], poses.X_RC[c]);
    return *hulls[c];
  };
  PriorityBits bits;
  for (int p = 0; p < kNumPairs; ++p) {
    const auto [a, b] = PairOf(p);
    if (!poses.present[a] || !poses.present[b]) continue;
    PlaneSource src = source_[p];
    if (src == PlaneSource::kDcp) {
      const int k = DcpPairSlot(p);
      if (dcp_valid & (1u << k)) {
        bits[p] = dcp_planes[k].n_R.dot(eye) - dcp_planes[k].d_ft < 0;
        continue;
      }
      src = PlaneSource::kDynamic;
    }
    if (src == PlaneSource::kFixed || src == PlaneSource::kRigid) {
      if (!have_last_[p]) {
        const double eps = PlaneTolerance(hull(a), hull(b));
        const std::optional<Plane> plane = FindSeparatingPlane(hull(a), hull(b), eps, nullptr);
        if (!plane) {
          spdlog::warn("no plane separates {} and {}: the scene model overlaps", ClusterName(a), ClusterName(b));
          source_[p] = PlaneSource::kDynamic;
          src = PlaneSource::kDynamic;
        } else {
          // Into the first cluster's frame (rigid for these groups).
          const Eigen::Affine3d& X = poses.X_RC[a];
          local_[p].n = X.linear().transpose() * plane->n;
          local_[p].d = plane->d - plane->n.dot(X.translation());
          have_last_[p] = true;
        }
      }
      if (src != PlaneSource::kDynamic) {
        const Eigen::Affine3d& X = poses.X_RC[a];
        const Eigen::Vector3d eye_a = X.linear().transpose() * (eye - X.translation());
        bits[p] = local_[p].n.dot(eye_a) - local_[p].d < 0;
        continue;
      }
    }
    // Dynamic: last frame's plane if it still separates, else a fresh search.
    const PosedHull& ha = hull(a);
    const PosedHull& hb = hull(b);
    const double eps = PlaneTolerance(ha, hb);
    int tried = 0;
    const std::optional<Plane> plane = FindSeparatingPlane(ha, hb, eps, have_last_[p] ? &last_[p] : nullptr, &tried);
    if (tried > 1 && counters) counters->Add("priority.dynamic_searches");
    if (plane) {
      last_[p] = *plane;
      have_last_[p] = true;
      bits[p] = plane->n.dot(eye) - plane->d < 0;
    } else {
      have_last_[p] = false;
      if (counters) counters->Add("priority.unresolved");
      bits[p] = (eye - ha.centroid).norm() < (eye - hb.centroid).norm();
    }
  }
  return bits;
}

std::vector<Eigen::Vector2f> ConvexHull2d(std::vector<Eigen::Vector2f> p) {
  std::sort(p.begin(), p.end(), [](const auto& a, const auto& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  if (p.size() < 3) return p;
  auto cross = [](const Eigen::Vector2f& o, const Eigen::Vector2f& a, const Eigen::Vector2f& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2f> h(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(h[k - 2], h[k - 1], p[i - 1]) <= 0) --k;
    h[k++] = p[i - 1];
  }
  h.resize(k - 1);
  return h;
}

namespace {
// Is there an edge normal of `a`'s outline along which `b` lies beyond a
// (by more than -tol)? Then they do not overlap by more than tol.
bool SeparatedByEdgesOf(const std::vector<Eigen::Vector2f>& a, const std::vector<Eigen::Vector2f>& b, float tol) {
  const std::size_t n = a.size();
  if (n < 2) return false;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2f e = a[(i + 1) % n] - a[i];
    const Eigen::Vector2f out(e.y(), -e.x());  // outward for a counter-clockwise outline
    const float len = out.norm();
    if (!(len > 0)) continue;
    float amax = -1e30f, bmin = 1e30f;
    for (const auto& p : a) amax = std::max(amax, out.dot(p) / len);
    for (const auto& p : b) bmin = std::min(bmin, out.dot(p) / len);
    if (bmin >= amax - tol) return true;
  }
  return false;
}
}  // namespace

bool OutlinesOverlap(const ScreenBox& a, const ScreenBox& b, float tol) {
  if (a.everywhere || b.everywhere) return true;
  if (a.x1 < b.x0 + tol || b.x1 < a.x0 + tol || a.y1 < b.y0 + tol || b.y1 < a.y0 + tol) return false;
  return !SeparatedByEdgesOf(a.outline, b.outline, tol) && !SeparatedByEdgesOf(b.outline, a.outline, tol);
}

std::vector<int> DrawOrder(const PriorityBits& bits, const std::array<ScreenBox, kNumClusters>& boxes,
                           int* cycles_broken, float overlap_tol) {
  // Edges "drawn before": u -> v. A pair's bit set: the first cluster may
  // hide the second, so the second goes first.
  std::array<std::uint64_t, kNumClusters> before{};  // (kNumClusters <= 64)  // bit u of before[v]: u must precede v
  std::vector<int> nodes;
  for (int c = 0; c < kNumClusters; ++c) {
    if (boxes[c].visible) nodes.push_back(c);
  }
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    for (std::size_t j = i + 1; j < nodes.size(); ++j) {
      const int a = nodes[i], b = nodes[j];
      if (!OutlinesOverlap(boxes[a], boxes[b], overlap_tol)) continue;
      const bool a_front = bits[PairIndex(a, b)];
      const int first = a_front ? b : a, second = a_front ? a : b;
      before[second] |= std::uint64_t{1} << first;
    }
  }
  std::vector<int> order;
  order.reserve(nodes.size());
  std::uint64_t remaining = 0;
  for (int c : nodes) remaining |= std::uint64_t{1} << c;
  if (cycles_broken) *cycles_broken = 0;
  while (remaining) {
    int pick = -1;
    for (int c = 0; c < kNumClusters; ++c) {  // lowest id among the ready ones
      if ((remaining >> c) & 1u) {
        if ((before[c] & remaining) == 0) {
          pick = c;
          break;
        }
      }
    }
    if (pick < 0) {  // a cycle: the cluster with the fewest predecessors left
      int fewest = kNumClusters + 1;
      for (int c = 0; c < kNumClusters; ++c) {
        if (!((remaining >> c) & 1u)) continue;
        const int n = std::popcount(before[c] & remaining);
        if (n < fewest) {
          fewest = n;
          pick = c;
        }
      }
      if (cycles_broken) ++*cycles_broken;
    }
    order.push_back(pick);
    remaining &= ~(std::uint64_t{1} << pick);
  }
  return order;
}

}  // namespace rms
