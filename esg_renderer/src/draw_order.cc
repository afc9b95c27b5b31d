#include "rms/esg_renderer/draw_order.h"

#include <algorithm>
#include <bit>
#include <cstdint>

namespace rms::esg_renderer {

std::vector<Eigen::Vector2f> ConvexHull2d(std::vector<Eigen::Vector2f> p) {
  std::sort(p.begin(), p.end(), [](const auto& a, const auto& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
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
bool SeparatedByEdgesOf(const std::vector<Eigen::Vector2f>& a,
                        const std::vector<Eigen::Vector2f>& b, float tol) {
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
  if (a.x1 < b.x0 + tol || b.x1 < a.x0 + tol || a.y1 < b.y0 + tol || b.y1 < a.y0 + tol)
    return false;
  return !SeparatedByEdgesOf(a.outline, b.outline, tol) &&
         !SeparatedByEdgesOf(b.outline, a.outline, tol);
}

std::vector<int> DrawOrder(const scene_model::PriorityBits& bits,
                           const std::array<ScreenBox, scene_model::kNumClusters>& boxes,
                           int* cycles_broken, float overlap_tol) {
  // Edges "drawn before": u -> v. A pair's bit set: the first cluster may
  // hide the second, so the second goes first.
  std::array<std::uint64_t, scene_model::kNumClusters>
      before{};  // (kNumClusters <= 64)  // bit u of before[v]: u must precede v
  std::vector<int> nodes;
  for (int c = 0; c < scene_model::kNumClusters; ++c) {
    if (boxes[c].visible) nodes.push_back(c);
  }
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    for (std::size_t j = i + 1; j < nodes.size(); ++j) {
      const int a = nodes[i], b = nodes[j];
      if (!OutlinesOverlap(boxes[a], boxes[b], overlap_tol)) continue;
      const bool a_front = bits[scene_model::PairIndex(a, b)];
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
    for (int c = 0; c < scene_model::kNumClusters; ++c) {  // lowest id among the ready ones
      if ((remaining >> c) & 1u) {
        if ((before[c] & remaining) == 0) {
          pick = c;
          break;
        }
      }
    }
    if (pick < 0) {  // a cycle: the cluster with the fewest predecessors left
      int fewest = scene_model::kNumClusters + 1;
      for (int c = 0; c < scene_model::kNumClusters; ++c) {
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

}  // namespace rms::esg_renderer
