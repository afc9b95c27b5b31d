#include "rms/reference/exact_hull.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Gmpq.h>
#include <CGAL/Interval_nt.h>
#include <atomic>
#include <utility>
#include <vector>

namespace rms::reference {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using IA = CGAL::Interval_nt<false>;
using Q = CGAL::Gmpq;

std::atomic<long> g_fallbacks{0};

struct Hull {
  std::vector<std::array<int, 3>> facets;  // supporting triples
  std::vector<std::pair<int, int>> edges;  // pairs that lie on a facet triple
};

Hull ExactHull(const std::array<Eigen::Vector3d, 8>& v) {
  std::array<K::Point_3, 8> p;
  for (int i = 0; i < 8; ++i) p[i] = K::Point_3(v[i].x(), v[i].y(), v[i].z());
  Hull h;
  bool edge_seen[8][8] = {};
  for (int i = 0; i < 8; ++i)
    for (int j = i + 1; j < 8; ++j)
      for (int k = j + 1; k < 8; ++k) {
        if (CGAL::collinear(p[i], p[j], p[k])) continue;
        int pos = 0, neg = 0;
        for (int m = 0; m < 8; ++m) {
          if (m == i || m == j || m == k) continue;
          const CGAL::Orientation o = CGAL::orientation(p[i], p[j], p[k], p[m]);
          pos += o == CGAL::POSITIVE;
          neg += o == CGAL::NEGATIVE;
        }
        if (pos > 0 && neg > 0) continue;  // not a supporting plane
        h.facets.push_back({i, j, k});
        for (auto [x, y] : {std::pair{i, j}, std::pair{i, k}, std::pair{j, k}}) {
          if (!edge_seen[x][y]) {
            edge_seen[x][y] = true;
            h.edges.emplace_back(x, y);
          }
        }
      }
  return h;
}

template <class NT>
struct P3 {
  NT x, y, z;
};

template <class NT>
P3<NT> Sub(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return {NT(a.x()) - NT(b.x()), NT(a.y()) - NT(b.y()), NT(a.z()) - NT(b.z())};
}
template <class NT>
P3<NT> Cross(const P3<NT>& a, const P3<NT>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class NT>
NT Dot(const P3<NT>& n, const Eigen::Vector3d& p) {
  return n.x * NT(p.x()) + n.y * NT(p.y()) + n.z * NT(p.z());
}

// Strict separation along n: max over a < min over b, or max over b < min over a.
// Returns 1 separated, 0 not, -1 undecided (intervals only).
template <class NT>
int SeparatedAlong(const P3<NT>& n, const std::array<Eigen::Vector3d, 8>& a,
                   const std::array<Eigen::Vector3d, 8>& b) {
  std::array<NT, 8> pa, pb;
  for (int i = 0; i < 8; ++i) {
    pa[i] = Dot(n, a[i]);
    pb[i] = Dot(n, b[i]);
  }
  if constexpr (std::is_same_v<NT, IA>) {
    // For every pair (i, j): is pa[i] < pb[j] certainly / certainly not?
    bool ab_certain = true, ab_impossible = false, ba_certain = true, ba_impossible = false;
    for (int i = 0; i < 8; ++i)
      for (int j = 0; j < 8; ++j) {
        const IA d = pb[j] - pa[i];
        if (!(d.inf() > 0)) ab_certain = false;
        if (d.sup() <= 0) ab_impossible = true;
        const IA e = pa[i] - pb[j];
        if (!(e.inf() > 0)) ba_certain = false;
        if (e.sup() <= 0) ba_impossible = true;
      }
    if (ab_certain || ba_certain) return 1;
    if (ab_impossible && ba_impossible) return 0;
    return -1;
  } else {
    NT amax = pa[0], amin = pa[0], bmax = pb[0], bmin = pb[0];
    for (int i = 1; i < 8; ++i) {
      if (pa[i] > amax) amax = pa[i];
      if (pa[i] < amin) amin = pa[i];
      if (pb[i] > bmax) bmax = pb[i];
      if (pb[i] < bmin) bmin = pb[i];
    }
    return (amax < bmin || bmax < amin) ? 1 : 0;
  }
}

bool AxisSeparates(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r,
                   const Eigen::Vector3d& s, const std::array<Eigen::Vector3d, 8>& a,
                   const std::array<Eigen::Vector3d, 8>& b) {
  // n = (q - p) x (s - r)
  {
    CGAL::Protect_FPU_rounding<true> guard;
    const P3<IA> n = Cross(Sub<IA>(q, p), Sub<IA>(s, r));
    const int res = SeparatedAlong(n, a, b);
    if (res >= 0) return res == 1;
  }
  ++g_fallbacks;
  const P3<Q> n = Cross(Sub<Q>(q, p), Sub<Q>(s, r));
  return SeparatedAlong(n, a, b) == 1;
}

}  // namespace

long ExactFallbacks() { return g_fallbacks.load(); }

bool ExactHullsIntersect(const std::array<Eigen::Vector3d, 8>& a,
                         const std::array<Eigen::Vector3d, 8>& b) {
  const Hull ha = ExactHull(a), hb = ExactHull(b);
  // Facet normals: n = (j - i) x (k - i).
  for (const auto* hv : {&ha, &hb}) {
    const auto& pts = hv == &ha ? a : b;
    for (const auto& f : hv->facets) {
      if (AxisSeparates(pts[f[0]], pts[f[1]], pts[f[0]], pts[f[2]], a, b)) return false;
    }
  }
  for (const auto& [i, j] : ha.edges)
    for (const auto& [k, l] : hb.edges)
      if (AxisSeparates(a[i], a[j], b[k], b[l], a, b)) return false;
  return true;
}

}  // namespace rms::reference
