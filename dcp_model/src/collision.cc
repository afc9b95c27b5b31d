#include "rms/dcp_model/collision.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "projection.h"
#include "simd.h"

namespace rms::dcp_model {

using internal::ProjectionRange;

namespace {

constexpr std::array<FaceList, 64> MakeFaceLists() {
  std::array<FaceList, 64> lists{};
  for (int m = 0; m < 64; ++m) {
    FaceList l{};
    for (int f = 0; f < kNumFaces; ++f) {
      if (m & (1 << f)) l.faces[l.count++] = static_cast<std::uint8_t>(f);
    }
    lists[m] = l;
  }
  return lists;
}

// The report's candidate separating plane: through a vertex of one solid and
// a bounding edge of the other (the first non-negative triple product).
struct PlaneCandidate {
  bool have = false;
  Eigen::Vector3d apex, q0, q1;
};

// The distance between the segments p + s u (0 <= s <= 1) and q + t v
// (0 <= t <= 1), ft, at any angle, parallel included (Ericson, Real-Time
// Collision Detection, 5.1.9), computed about p so that it is accurate far
// from the origin.
double SegmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& u, const Eigen::Vector3d& q,
                       const Eigen::Vector3d& v) {
  const Eigen::Vector3d r = p - q;
  const double a = u.squaredNorm(), e = v.squaredNorm(), f = v.dot(r);
  double s = 0.0, t = 0.0;
  if (a <= 0.0 && e <= 0.0) return r.norm();
  if (a <= 0.0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = u.dot(r);
    if (e <= 0.0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = u.dot(v), denom = a * e - b * b;
      s = denom > 0.0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return (r + s * u - t * v).norm();
}

// sqrt(dir_sq), computed once (the same bits as Eigen's norm()).
double DirLen(double dir_sq, double* dir_len) {
  if (*dir_len < 0) *dir_len = std::sqrt(dir_sq);
  return *dir_len;
}

// The four triple products of Section IV.A.1's edge test for face f of Q,
// T_j = h (b_j - v) x (b_j+1 - b_j) . V for j = 0..3 (h: Q's handedness),
// each computed as Eigen computes h * (q0 - apex).cross(e).dot(dir) -- the
// same operations in the same order, so the same bits -- four at a time in
// AVX where the processor has it.
#if defined(RMS_DCP_X86)
// Coordinate c of face f's four vertices from its s-th on (a helper, not a
// lambda: a lambda would not inherit the target).
__attribute__((target("avx"))) inline __m256d FaceLanes(const std::array<double, 8>& c, int f,
                                                        int s) {
  const auto& b = kFaceVertices[f];
  return _mm256_setr_pd(c[b[s]], c[b[(s + 1) % 4]], c[b[(s + 2) % 4]], c[b[(s + 3) % 4]]);
}

__attribute__((target("avx"))) void FaceProductsAvx(const Hexahedron& Q, int f,
                                                    const Eigen::Vector3d& v,
                                                    const Eigen::Vector3d& V, double t[4]) {
  const __m256d q0x = FaceLanes(Q.x, f, 0), q0y = FaceLanes(Q.y, f, 0), q0z = FaceLanes(Q.z, f, 0);
  const __m256d ex = _mm256_sub_pd(FaceLanes(Q.x, f, 1), q0x),
                ey = _mm256_sub_pd(FaceLanes(Q.y, f, 1), q0y),
                ez = _mm256_sub_pd(FaceLanes(Q.z, f, 1), q0z);
  const __m256d wx = _mm256_sub_pd(q0x, _mm256_set1_pd(v.x())),
                wy = _mm256_sub_pd(q0y, _mm256_set1_pd(v.y())),
                wz = _mm256_sub_pd(q0z, _mm256_set1_pd(v.z()));
  const __m256d cx = _mm256_sub_pd(_mm256_mul_pd(wy, ez), _mm256_mul_pd(wz, ey));
  const __m256d cy = _mm256_sub_pd(_mm256_mul_pd(wz, ex), _mm256_mul_pd(wx, ez));
  const __m256d cz = _mm256_sub_pd(_mm256_mul_pd(wx, ey), _mm256_mul_pd(wy, ex));
  const __m256d dot = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(cx, _mm256_set1_pd(V.x())),
                                                  _mm256_mul_pd(cy, _mm256_set1_pd(V.y()))),
                                    _mm256_mul_pd(cz, _mm256_set1_pd(V.z())));
  _mm256_storeu_pd(t, _mm256_mul_pd(_mm256_set1_pd(Q.handedness), dot));
}
#endif

void FaceProducts(const Hexahedron& Q, int f, const Eigen::Vector3d& v, const Eigen::Vector3d& V,
                  double t[4]) {
#if defined(RMS_DCP_X86)
  if (avx_enabled) return FaceProductsAvx(Q, f, v, V, t);
#endif
  for (int j = 0; j < 4; ++j) {
    const Eigen::Vector3d q0 = Q.vertex(kFaceVertices[f][j]);
    const Eigen::Vector3d e = Q.vertex(kFaceVertices[f][(j + 1) % 4]) - q0;
    t[j] = Q.handedness * (q0 - v).cross(e).dot(V);
  }
}

// A positive T_j at most `clear`: does the edge pass clear of face f's
// bounding edge j, by more than tau? T_j / (|e| |V|) is at most the distance between
// the two lines, so above tau x |e| x |V| it is clear; below, near-parallel
// edges can be far apart with a small T_j, and the segments' distance
// decides (docs/collision.md "Tolerance rule").
bool ClearOfBoundingEdge(const Hexahedron& Q, int f, int j, const Eigen::Vector3d& apex,
                         const Eigen::Vector3d& dir, double t, double dir_sq, double tau,
                         double* dir_len) {
  const Eigen::Vector3d q0 = Q.vertex(kFaceVertices[f][j]);
  const Eigen::Vector3d e = Q.vertex(kFaceVertices[f][(j + 1) % 4]) - q0;
  return t > tau * e.norm() * DirLen(dir_sq, dir_len) || SegmentDistance(apex, dir, q0, e) > tau;
}

// Section IV.A.1's edge test for the edge (i, k) of P against the faces of Q,
// given the two vertices' location words against Q. Returns the face of Q the
// edge pierces, or -1.
//
// The exclusive-or of the two words names the faces whose planes the edge
// crosses; fewer than two ones and the edge cannot pass through Q (it would
// have to enter through one face and leave through another, or end inside Q,
// which the vertex test caught). For each such face f the endpoint on f's TRUE
// side is the apex v, V runs to the other endpoint, and the edge pierces f iff
// V passes inside each of f's four bounding edges (b_j, b_j+1):
//   T_j = (b_j - v) x (b_j+1 - b_j) . V <= 0   for j = 0..3
// (the report's V_B x V_A . V_i with V_B = b_j - v, V_A = b_j+1 - v). A T_j
// above the tolerance ends the sequence for that face.
//
// `clear` is (tau x Q.scale) x P.scale: no larger than the bound
// tau |e| |V| of any of Q's edges e and P's V as computed (an edge is no
// longer than its solid's bounding-box diagonal, and rounding is monotonic),
// so a T_j above it is clear without the two square roots; the same
// decisions, bit for bit, as always computing them.
int EdgePiercesFace(const Hexahedron& P, int i, int k, LocationWord wi, LocationWord wk,
                    const Hexahedron& Q, double tau, double clear, PlaneCandidate* cand,
                    int* products) {
  // The faces whose planes the edge crosses: two or more, or it cannot pierce.
  const FaceList& faces = kFacesOfMask[wi ^ wk];
  if (faces.count < 2) return -1;
  const Eigen::Vector3d vi = P.vertex(i), vk = P.vertex(k);
  // The edge's length (|V| is the same either way round), when needed.
  const double dir_sq = (vk - vi).squaredNorm();
  if (!(dir_sq > 0)) return -1;
  double dir_len = -1.0;
  for (int n = 0; n < faces.count; ++n) {
    const int f = faces.faces[n];
    const bool apex_is_i = (wi & FaceBit(f)) != 0;
    const Eigen::Vector3d& apex = apex_is_i ? vi : vk;
    const Eigen::Vector3d dir = apex_is_i ? Eigen::Vector3d(vk - vi) : Eigen::Vector3d(vi - vk);
    double t4[4];
    FaceProducts(Q, f, apex, dir, t4);
    // T_j > 0: the edge passes outside the bounding edge. It still touches
    // when it comes within tau of it (docs/collision.md "Tolerance rule").
    // In the report's sequence, the first T_j that clears ends it.
    unsigned positive = 0, cleared = 0;
    for (int j = 0; j < 4; ++j) {
      positive |= static_cast<unsigned>(t4[j] > 0) << j;
      cleared |= static_cast<unsigned>(t4[j] > clear) << j;
    }
    int outside = -1;
    for (unsigned m = positive; m != 0; m &= m - 1) {
      const int j = std::countr_zero(m);
      if ((cleared >> j & 1u) ||
          ClearOfBoundingEdge(Q, f, j, apex, dir, t4[j], dir_sq, tau, &dir_len)) {
        outside = j;
        break;
      }
    }
    const bool inside = outside < 0;
    *products += inside ? 4 : outside + 1;
    if (!inside && !cand->have)
      *cand = {true, apex, Q.vertex(kFaceVertices[f][outside]),
               Q.vertex(kFaceVertices[f][(outside + 1) % 4])};
    if (inside) return f;
  }
  return -1;
}

void SetPlane(CollisionResult* r, const Eigen::Vector3d& n, double d) {
  r->plane_valid = true;
  r->plane = {n, d};
}

// A separating plane when no face of either solid is one: the report's
// candidate if it separates the whole solids, else the widest gap along the
// cross products of A's and B's edge directions (for convex solids whose
// faces do not separate them, one of these does).
void FindEdgePlane(const Hexahedron& a, const Hexahedron& b, const PlaneCandidate& cand, double tau,
                   CollisionResult* r) {
  if (cand.have) {
    Eigen::Vector3d n = (cand.q0 - cand.apex).cross(cand.q1 - cand.q0);
    const double len = n.norm();
    if (len > 0) {
      n /= len;
      const double d = n.dot(cand.q0);
      if (PlaneSeparates(a, b, n, d, tau)) return SetPlane(r, n, d);
      if (PlaneSeparates(a, b, -n, -d, tau)) return SetPlane(r, -n, -d);
    }
  }
  const internal::EdgeAxisPlane widest = internal::WidestEdgeAxis(a, b);
  if (widest.gap_ft >= -tau) SetPlane(r, widest.n_R, widest.d_ft);
}

}  // namespace

const std::array<FaceList, 64> kFacesOfMask = MakeFaceLists();

bool PlaneSeparates(const Hexahedron& a, const Hexahedron& b, const Eigen::Vector3d& n, double d,
                    double tol) {
  double alo, ahi, blo, bhi;
  ProjectionRange(a, n, &alo, &ahi);
  ProjectionRange(b, n, &blo, &bhi);
  return ahi <= d + tol && blo >= d - tol;
}

namespace {
#if defined(RMS_DCP_X86)
// Each vertex's projection (n.x x + n.y y) + n.z z, four at a time: the
// scalar code's bits.
__attribute__((target("avx"))) inline __m256d ProjectFour(const Hexahedron& h, int k,
                                                          const Eigen::Vector3d& n) {
  return _mm256_add_pd(
      _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(n.x()), _mm256_loadu_pd(&h.x[k])),
                    _mm256_mul_pd(_mm256_set1_pd(n.y()), _mm256_loadu_pd(&h.y[k]))),
      _mm256_mul_pd(_mm256_set1_pd(n.z()), _mm256_loadu_pd(&h.z[k])));
}

__attribute__((target("avx"))) double GapAlongAvx(const Hexahedron& a, const Hexahedron& b,
                                                  const Eigen::Vector3d& n) {
  const __m256d amax = _mm256_max_pd(ProjectFour(a, 0, n), ProjectFour(a, 4, n));
  const __m256d bmin = _mm256_min_pd(ProjectFour(b, 0, n), ProjectFour(b, 4, n));
  double ha[4], lb[4];
  _mm256_storeu_pd(ha, amax);
  _mm256_storeu_pd(lb, bmin);
  return std::min(std::min(lb[0], lb[1]), std::min(lb[2], lb[3])) -
         std::max(std::max(ha[0], ha[1]), std::max(ha[2], ha[3]));
}
#endif
}  // namespace

// The same extremes as ProjectionRange's, taken in another order: the same
// value, though an exactly zero gap may carry the other sign.
double GapAlong(const Hexahedron& a, const Hexahedron& b, const Eigen::Vector3d& n) {
#if defined(RMS_DCP_X86)
  if (avx_enabled) return GapAlongAvx(a, b, n);
#endif
  double alo, ahi, blo, bhi;
  ProjectionRange(a, n, &alo, &ahi);
  ProjectionRange(b, n, &blo, &bhi);
  return blo - ahi;
}

double MidGapOffset(const Hexahedron& a, const Hexahedron& b, const Eigen::Vector3d& n) {
  double alo, ahi, blo, bhi;
  ProjectionRange(a, n, &alo, &ahi);
  ProjectionRange(b, n, &blo, &bhi);
  return 0.5 * (ahi + blo);
}

double ToleranceFt(const Hexahedron& a, const Hexahedron& b, double relative_tolerance) {
  return relative_tolerance * std::max(a.scale, b.scale) +
         kRoundingPerFt * std::max(a.magnitude, b.magnitude);
}

namespace {

// Before the report's test (when enabled): the bounding spheres apart by
// more than tau means separate, with the plane midway between the spheres'
// surfaces along the centre line.
bool SpheresApart(const Hexahedron& a, const Hexahedron& b, double tau, bool want_plane,
                  CollisionResult* r) {
  const double dx = b.cx - a.cx, dy = b.cy - a.cy, dz = b.cz - a.cz;
  const double dist2 = dx * dx + dy * dy + dz * dz, reach = a.radius + b.radius + tau;
  if (dist2 <= reach * reach) return false;
  r->verdict = Verdict::kSeparate;
  r->decider = Decider::kSpheresApart;
  if (want_plane) {
    const double dist = std::sqrt(dist2);
    const Eigen::Vector3d n(dx / dist, dy / dist, dz / dist);
    const double gap_mid = 0.5 * (dist + a.radius - b.radius);
    SetPlane(r, n, n.x() * a.cx + n.y() * a.cy + n.z() * a.cz + gap_mid);
  }
  return true;
}

// The axis-aligned bounding boxes apart by more than tau along an axis:
// separate, with the plane normal to that axis midway in the gap.
bool BoxesApart(const Hexahedron& a, const Hexahedron& b, double tau, bool want_plane,
                CollisionResult* r) {
  // The boxes' gap along each axis: centre distance less both half extents.
  const double d[3] = {b.cx - a.cx, b.cy - a.cy, b.cz - a.cz};
  const double gap[3] = {std::abs(d[0]) - a.hx - b.hx, std::abs(d[1]) - a.hy - b.hy,
                         std::abs(d[2]) - a.hz - b.hz};
  const int k = gap[0] >= gap[1] ? (gap[0] >= gap[2] ? 0 : 2) : (gap[1] >= gap[2] ? 1 : 2);
  if (gap[k] <= tau) return false;
  r->verdict = Verdict::kSeparate;
  r->decider = Decider::kBoxesApart;
  if (want_plane) {
    const double sign = d[k] > 0 ? 1.0 : -1.0;  // from A toward B
    const double ha[3] = {a.hx, a.hy, a.hz};
    const double ca[3] = {a.cx, a.cy, a.cz};
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    n[k] = sign;
    SetPlane(r, n, sign * ca[k] + ha[k] + 0.5 * gap[k]);  // A's face plus half the gap
  }
  return true;
}

// Steps 1 and 2: the vertices of `verts` against the faces of `faces` (A's
// against B's when a_in_b). Decides, and ends the algorithm, when a face has
// a 1 in all eight words (separate: the lowest such face, as the full words
// would name) or a word is all zeros (collision). Computed face by face as
// masks of the eight vertices; the words themselves are formed only for the
// edge phase.
bool VertexPhase(const Hexahedron& faces, const Hexahedron& verts, bool a_in_b, double tau,
                 bool want_plane, std::array<std::uint8_t, 6>* masks, CollisionResult* r) {
  const int f = faces.FaceMasks(verts, tau, masks);
  if (f >= 0) {
    r->verdict = Verdict::kSeparate;
    r->decider = a_in_b ? Decider::kFaceOfBSeparates : Decider::kFaceOfASeparates;
    r->index = r->face = f;
    // The plane's normal points from A toward B: B's outward normal
    // reversed, or A's outward normal.
    if (want_plane) {
      if (a_in_b)
        SetPlane(r, -faces.normal(f), -faces.d[f]);
      else
        SetPlane(r, faces.normal(f), faces.d[f]);
    }
    return true;
  }
  unsigned beyond_some = 0;
  for (int k = 0; k < kNumFaces; ++k) beyond_some |= (*masks)[k];
  const unsigned inside = ~beyond_some & 0xFFu;
  if (!inside) return false;
  r->verdict = Verdict::kCollide;
  r->decider = a_in_b ? Decider::kVertexOfAInB : Decider::kVertexOfBInA;
  r->index = std::countr_zero(inside);
  return true;
}

// Step 3, one direction: the edges of `edges` (by their vertices' words)
// against the faces of `faces`; an edge that pierces one decides collision.
bool EdgePhase(const Hexahedron& edges, const std::array<LocationWord, 8>& words,
               const Hexahedron& faces, double tau, Decider decider, PlaneCandidate* cand,
               CollisionResult* r) {
  const double clear = tau * faces.scale * edges.scale;
  for (int e = 0; e < kNumEdges; ++e) {
    const int i = kEdges[e][0], k = kEdges[e][1];
    const int f = EdgePiercesFace(edges, i, k, words[i], words[k], faces, tau, clear, cand,
                                  &r->triple_products);
    if (f >= 0) {
      r->verdict = Verdict::kCollide;
      r->decider = decider;
      r->index = e;
      r->face = f;
      return true;
    }
  }
  return false;
}

}  // namespace

CollisionResult Collide(const Hexahedron& a, const Hexahedron& b, const CollideOptions& options) {
  CollisionResult r;
  if (!a.valid || !b.valid) return r;  // kInvalid, kNonFinite
  const double tau = ToleranceFt(a, b, options.relative_tolerance);
  if (options.sphere_reject && SpheresApart(a, b, tau, options.want_plane, &r)) return r;
  if (options.aabb_reject && BoxesApart(a, b, tau, options.want_plane, &r)) return r;
  // The hint decides only a pair it separates by more than tau on each side
  // (so touching pairs, which collide, always go to the report's test).
  if (options.hint && PlaneSeparates(a, b, options.hint->n_R, options.hint->d_ft, -tau)) {
    r.verdict = Verdict::kSeparate;
    r.decider = Decider::kHintPlane;
    if (options.want_plane) SetPlane(&r, options.hint->n_R, options.hint->d_ft);
    return r;
  }
  // 1. A's vertices against B's faces; 2. B's against A's.
  std::array<std::uint8_t, 6> masks_a{}, masks_b{};
  if (VertexPhase(b, a, /*a_in_b=*/true, tau, options.want_plane, &masks_a, &r)) return r;
  if (VertexPhase(a, b, /*a_in_b=*/false, tau, options.want_plane, &masks_b, &r)) return r;
  r.words_a = WordsFromMasks(masks_a);
  r.words_b = WordsFromMasks(masks_b);
  r.words_valid = true;
  // 3. Potential edge collisions, both directions.
  PlaneCandidate cand;
  if (EdgePhase(a, r.words_a, b, tau, Decider::kEdgeOfAPiercesB, &cand, &r)) return r;
  if (EdgePhase(b, r.words_b, a, tau, Decider::kEdgeOfBPiercesA, &cand, &r)) return r;
  // 4. Separate.
  r.verdict = Verdict::kSeparate;
  r.decider = Decider::kNoEdgePierces;
  if (options.want_plane) FindEdgePlane(a, b, cand, tau, &r);
  return r;
}

}  // namespace rms::dcp_model
