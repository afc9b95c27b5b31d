// Step 4's last resort for a separating plane: the widest gap along the
// cross products of A's and B's edge directions, found without computing
// most of the 144 axes and giving the exhaustive search's answer bit for bit
// (docs/collision.md "The widest edge axis").
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "rms/dcp_model/collision.h"

#include "projection.h"
#include "simd.h"

namespace rms::dcp_model::internal {

namespace {

constexpr int kNumAxes = kNumEdges * kNumEdges;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kEps = std::numeric_limits<double>::epsilon();  // 2^-52: twice the unit roundoff
// The range of |da x db| (ft^2) and of the reach (ft) in which a pair of
// directions may be skipped: its squares normal numbers, far from overflow.
constexpr double kLeastCross = 0x1p-500, kGreatestCross = 0x1p500;

// The edges along each of the solid's three directions, U (a to d), V (b to
// e) and W (c to f): edge "x-y" joins faces x and y and runs along the third
// pair's axis (hexahedron.h kEdges), each from its c/b/a vertex to its
// f/e/d one. The first of each is the class's representative; its axes come
// first in the exhaustive search's order among the class's.
constexpr std::array<std::array<int, 4>, 3> kEdgesAlong = {{
    {8, 9, 10, 11},  // along U: b-c, b-f, e-c, e-f
    {2, 3, 6, 7},    // along V: a-c, a-f, d-c, d-f
    {0, 1, 4, 5},    // along W: a-b, a-e, d-b, d-e
}};

struct EdgeDirections {
  // Edge e's vector, from its vertex kEdges[e][0] to kEdges[e][1], and its
  // length, ft (the operations of Eigen's difference and norm: the same bits).
  std::array<double, kNumEdges> x, y, z, len;
  // Per direction: how far an edge's vector lies from the representative's,
  // and the longest edge, ft.
  std::array<double, 3> spread, longest;

  explicit EdgeDirections(const Hexahedron& h) {
    for (int e = 0; e < kNumEdges; ++e) {
      const int i = kEdges[e][0], k = kEdges[e][1];
      x[e] = h.x[k] - h.x[i];
      y[e] = h.y[k] - h.y[i];
      z[e] = h.z[k] - h.z[i];
      len[e] = std::sqrt(x[e] * x[e] + y[e] * y[e] + z[e] * z[e]);
    }
    for (int c = 0; c < 3; ++c) {
      const int r = kEdgesAlong[c][0];
      double spread_sq = 0.0;
      longest[c] = 0.0;
      for (int e : kEdgesAlong[c]) {
        const double dx = x[e] - x[r], dy = y[e] - y[r], dz = z[e] - z[r];
        spread_sq = std::max(spread_sq, dx * dx + dy * dy + dz * dz);
        longest[c] = std::max(longest[c], len[e]);
      }
      spread[c] = std::sqrt(spread_sq);
    }
  }
  Eigen::Vector3d dir(int e) const { return {x[e], y[e], z[e]}; }
};

// One axis, computed as the exhaustive search computes it.
struct AxisExtents {
  bool usable;        // the edges not near parallel: the axis is tried
  double cross_len;   // |da x db|, ft^2
  Eigen::Vector3d n;  // the unit axis
  double alo, ahi;    // A's extent along n, ft
  double blo, bhi;    // B's
  // The greater of the gaps B above A and A above B, ft.
  double Widest() const { return std::max(blo - ahi, alo - bhi); }
};

AxisExtents Extents(const Hexahedron& a, const EdgeDirections& da, int ea, const Hexahedron& b,
                    const EdgeDirections& db, int eb) {
  AxisExtents x;
  x.n = da.dir(ea).cross(db.dir(eb));
  x.cross_len = x.n.norm();
  x.usable = x.cross_len > 1e-12 * da.len[ea] * db.len[eb];
  if (!x.usable) return x;
  x.n /= x.cross_len;
  ProjectionRange(a, x.n, &x.alo, &x.ahi);
  ProjectionRange(b, x.n, &x.blo, &x.bhi);
  return x;
}

#if defined(RMS_DCP_X86)
// Four axes at once, each lane computed with Extents' operations in its
// order (Eigen's cross product, (x x + y y) + z z, a quotient each
// coordinate; the extremes vertex by vertex, minpd/maxpd keeping the
// earlier of equal values as std::min/max do): the same bits.
__attribute__((target("avx"))) inline __m256d Lanes(const std::array<double, kNumEdges>& v,
                                                    const int e[4]) {
  return _mm256_setr_pd(v[e[0]], v[e[1]], v[e[2]], v[e[3]]);
}

__attribute__((target("avx"))) void RangeFour(const Hexahedron& h, __m256d nx, __m256d ny,
                                              __m256d nz, double lo[4], double hi[4]) {
  __m256d l = _mm256_set1_pd(kInf), u = _mm256_set1_pd(-kInf);
  for (int i = 0; i < kNumVertices; ++i) {
    const __m256d p = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(nx, _mm256_set1_pd(h.x[i])),
                                                  _mm256_mul_pd(ny, _mm256_set1_pd(h.y[i]))),
                                    _mm256_mul_pd(nz, _mm256_set1_pd(h.z[i])));
    l = _mm256_min_pd(p, l);  // p < l ? p : l, as std::min(l, p)
    u = _mm256_max_pd(p, u);  // p > u ? p : u, as std::max(u, p)
  }
  _mm256_storeu_pd(lo, l);
  _mm256_storeu_pd(hi, u);
}

__attribute__((target("avx"))) void ExtentsFour(const Hexahedron& a, const EdgeDirections& da,
                                                const int ea[4], const Hexahedron& b,
                                                const EdgeDirections& db, const int eb[4],
                                                AxisExtents out[4]) {
  const __m256d ax = Lanes(da.x, ea), ay = Lanes(da.y, ea), az = Lanes(da.z, ea);
  const __m256d bx = Lanes(db.x, eb), by = Lanes(db.y, eb), bz = Lanes(db.z, eb);
  const __m256d cx = _mm256_sub_pd(_mm256_mul_pd(ay, bz), _mm256_mul_pd(az, by));
  const __m256d cy = _mm256_sub_pd(_mm256_mul_pd(az, bx), _mm256_mul_pd(ax, bz));
  const __m256d cz = _mm256_sub_pd(_mm256_mul_pd(ax, by), _mm256_mul_pd(ay, bx));
  const __m256d len = _mm256_sqrt_pd(_mm256_add_pd(
      _mm256_add_pd(_mm256_mul_pd(cx, cx), _mm256_mul_pd(cy, cy)), _mm256_mul_pd(cz, cz)));
  const __m256d nx = _mm256_div_pd(cx, len), ny = _mm256_div_pd(cy, len),
                nz = _mm256_div_pd(cz, len);
  double l[4], n[3][4], alo[4], ahi[4], blo[4], bhi[4];
  _mm256_storeu_pd(l, len);
  _mm256_storeu_pd(n[0], nx);
  _mm256_storeu_pd(n[1], ny);
  _mm256_storeu_pd(n[2], nz);
  RangeFour(a, nx, ny, nz, alo, ahi);
  RangeFour(b, nx, ny, nz, blo, bhi);
  for (int k = 0; k < 4; ++k) {
    out[k] = {l[k] > 1e-12 * da.len[ea[k]] * db.len[eb[k]],
              l[k],
              {n[0][k], n[1][k], n[2][k]},
              alo[k],
              ahi[k],
              blo[k],
              bhi[k]};
  }
}
#endif

// The axes computed so far, axis k = A's edge x 12 + B's edge.
struct AxisTable {
  std::array<AxisExtents, kNumAxes> axes;
  std::array<std::uint64_t, (kNumAxes + 63) / 64> computed{};  // bit k % 64 of word k / 64

  bool Has(int k) const { return (computed[k / 64] >> (k % 64) & 1u) != 0; }
  // Computes those of the `count` axes `ks` not computed yet.
  void Compute(const Hexahedron& a, const EdgeDirections& da, const Hexahedron& b,
               const EdgeDirections& db, const int* ks, int count) {
    int todo[kNumAxes], n = 0;
    for (int i = 0; i < count; ++i) {
      if (Has(ks[i])) continue;
      computed[ks[i] / 64] |= std::uint64_t{1} << (ks[i] % 64);
      todo[n++] = ks[i];
    }
#if defined(RMS_DCP_X86)
    if (avx_enabled) {
      for (int i = 0; i < n; i += 4) {
        int ea[4], eb[4];
        for (int k = 0; k < 4; ++k) {
          const int axis = todo[std::min(i + k, n - 1)];  // the last again to fill the lanes
          ea[k] = axis / kNumEdges;
          eb[k] = axis % kNumEdges;
        }
        AxisExtents four[4];
        ExtentsFour(a, da, ea, b, db, eb, four);
        for (int k = 0; k < 4 && i + k < n; ++k) axes[todo[i + k]] = four[k];
      }
      return;
    }
#endif
    for (int i = 0; i < n; ++i)
      axes[todo[i]] = Extents(a, da, todo[i] / kNumEdges, b, db, todo[i] % kNumEdges);
  }
};

// The exhaustive search's step for one axis: B above A, then A above B, each
// taken when strictly wider than the widest so far.
void Consider(const AxisExtents& x, EdgeAxisPlane* best) {
  if (!x.usable) return;
  if (x.blo - x.ahi > best->gap_ft) {
    best->gap_ft = x.blo - x.ahi;
    best->n_R = x.n;
    best->d_ft = 0.5 * (x.ahi + x.blo);
  }
  if (x.alo - x.bhi > best->gap_ft) {
    best->gap_ft = x.alo - x.bhi;
    best->n_R = -x.n;
    best->d_ft = -0.5 * (x.bhi + x.alo);
  }
}

// How far above its representative's gap (rep) the computed gap of any axis
// of A's direction p and B's direction q can lie, ft; infinity when that
// cannot be bounded usefully (the directions' edges not near parallel among
// themselves, as a frustum's, or the representative's cross product ill
// conditioned). With R the reach (the largest |x| + |y| + |z| of a vertex
// of either solid), the exact gap along a direction moves at most 2 R a unit
// of the direction's change; a unit cross product moves at most
// 2 |c - c_rep| / |c_rep| exactly, with |c - c_rep| at most
// spread_a x longest_b + longest_a x spread_b; rounding adds at most a few
// units of 2^-53 times kappa = longest_a x longest_b / |c_rep| to each unit
// axis and a few times R to each gap. Each term is taken at least twice
// over, then the whole twice (docs/collision.md "The widest edge axis").
double ClassSlack(const EdgeDirections& da, int p, const EdgeDirections& db, int q,
                  const AxisExtents& rep, double reach) {
  if (!rep.usable) return kInf;
  const double c_len = rep.cross_len;
  // Only in the normal range, well inside: below, |c|^2 is subnormal and
  // the "unit" axis is off by tens of percent; above, it overflows. The
  // members' |c| is at least 3/4 of the representative's (below), so their
  // squares stay normal too.
  if (!(c_len >= kLeastCross && c_len <= kGreatestCross) || !(reach <= kGreatestCross)) return kInf;
  const double change = da.spread[p] * db.longest[q] + da.longest[p] * db.spread[q];
  const double kappa = da.longest[p] * db.longest[q] / c_len;
  if (!(change <= 0.25 * c_len) || !(kappa * kEps <= 1e-4)) return kInf;
  // kLeastCross: the absolute rounding of a subnormal product or projection
  // (2^-1074 each), far below it.
  return 2.0 * (2.0 * reach * (4.0 * change / c_len + 64.0 * kEps * kappa) + 64.0 * kEps * reach) +
         kLeastCross;
}

double Reach(const Hexahedron& h) {
  double r = 0.0;
  for (int i = 0; i < kNumVertices; ++i)
    r = std::max(r, std::abs(h.x[i]) + std::abs(h.y[i]) + std::abs(h.z[i]));
  return r;
}

}  // namespace

EdgeAxisPlane WidestEdgeAxisExhaustive(const Hexahedron& a, const Hexahedron& b) {
  const EdgeDirections da(a), db(b);
  EdgeAxisPlane best;
  for (int ea = 0; ea < kNumEdges; ++ea)
    for (int eb = 0; eb < kNumEdges; ++eb) Consider(Extents(a, da, ea, b, db, eb), &best);
  best.axes_computed = kNumAxes;
  return best;
}

// The representatives' axes first (one for each pair of directions, nine);
// a pair of directions whose every axis is bounded below the widest of
// those is skipped; the rest are computed in full; then the exhaustive
// search's steps over the computed axes in its order. A skipped axis's gap
// is below one computed, so it could not be the first of the widest.
EdgeAxisPlane WidestEdgeAxis(const Hexahedron& a, const Hexahedron& b) {
  const EdgeDirections da(a), db(b);
  const double reach = std::max(Reach(a), Reach(b));
  AxisTable t;
  int reps[9];
  for (int pq = 0; pq < 9; ++pq)
    reps[pq] = kEdgesAlong[pq / 3][0] * kNumEdges + kEdgesAlong[pq % 3][0];
  t.Compute(a, da, b, db, reps, 9);
  std::array<double, 9> ceiling;
  double widest = -kInf;
  for (int pq = 0; pq < 9; ++pq) {
    const AxisExtents& rep = t.axes[reps[pq]];
    ceiling[pq] = kInf;
    if (!rep.usable) continue;
    const double top = rep.Widest();
    if (top > widest) widest = top;
    ceiling[pq] = top + ClassSlack(da, pq / 3, db, pq % 3, rep, reach);
  }
  int rest[kNumAxes], n = 0;
  for (int pq = 0; pq < 9; ++pq) {
    if (ceiling[pq] < widest) continue;
    for (int ea : kEdgesAlong[pq / 3])
      for (int eb : kEdgesAlong[pq % 3]) rest[n++] = ea * kNumEdges + eb;
  }
  t.Compute(a, da, b, db, rest, n);
  EdgeAxisPlane best;
  for (std::size_t w = 0; w < t.computed.size(); ++w) {
    for (std::uint64_t m = t.computed[w]; m != 0; m &= m - 1) {
      Consider(t.axes[64 * w + std::countr_zero(m)], &best);
      ++best.axes_computed;
    }
  }
  return best;
}

}  // namespace rms::dcp_model::internal
