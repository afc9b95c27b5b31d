#pragma once
// Separation of two convex hexahedra in long double, by brute force over
// features: the distance when disjoint (closest points are realised by a
// vertex and a face or by two edges), minus the penetration depth when they
// overlap (the smallest overlap over the separating-axis candidates: face
// normals and edge cross products). Used only to say whether a disagreement
// lies inside the documented band, never for a verdict.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>

namespace rms::reference {

using V3 = Eigen::Matrix<long double, 3, 1>;

inline V3 L(const Eigen::Vector3d& v) { return v.cast<long double>(); }

// Ericson, Real-Time Collision Detection, 5.1.5.
inline long double PointTriangleDistance(const V3& p, const V3& a, const V3& b, const V3& c) {
  const V3 ab = b - a, ac = c - a, ap = p - a;
  const long double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return (p - a).norm();
  const V3 bp = p - b;
  const long double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return (p - b).norm();
  const long double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + ab * (d1 / (d1 - d3)))).norm();
  const V3 cp = p - c;
  const long double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return (p - c).norm();
  const long double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + ac * (d2 / (d2 - d6)))).norm();
  const long double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return (p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))))).norm();
  }
  const long double denom = 1 / (va + vb + vc);
  return (p - (a + ab * (vb * denom) + ac * (vc * denom))).norm();
}

// Ericson 5.1.9.
inline long double SegmentSegmentDistance(const V3& p1, const V3& q1, const V3& p2, const V3& q2) {
  const V3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const long double a = d1.dot(d1), e = d2.dot(d2), f = d2.dot(r);
  long double s = 0, t = 0;
  if (a <= 0 && e <= 0) return r.norm();
  if (a <= 0) {
    t = std::clamp(f / e, 0.0L, 1.0L);
  } else {
    const long double c = d1.dot(r);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0L, 1.0L);
    } else {
      const long double b = d1.dot(d2), denom = a * e - b * b;
      s = denom != 0 ? std::clamp((b * f - c * e) / denom, 0.0L, 1.0L) : 0.0L;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0L, 1.0L);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0L, 1.0L);
      }
    }
  }
  return ((p1 + d1 * s) - (p2 + d2 * t)).norm();
}

struct Topology {
  std::array<std::array<int, 4>, 6> faces;
  std::array<std::array<int, 2>, 12> edges;
};

// Distance between two disjoint convex hexahedra (0 if they touch).
inline long double HullDistance(const std::array<Eigen::Vector3d, 8>& A,
                                const std::array<Eigen::Vector3d, 8>& B, const Topology& topo) {
  long double best = INFINITY;
  auto vertex_faces = [&](const std::array<Eigen::Vector3d, 8>& P,
                          const std::array<Eigen::Vector3d, 8>& Q) {
    for (const auto& p : P) {
      for (const auto& f : topo.faces) {
        // Both diagonals' triangles cover a slightly non-planar quad.
        for (const auto& tri :
             {std::array<int, 3>{f[0], f[1], f[2]}, std::array<int, 3>{f[0], f[2], f[3]},
              std::array<int, 3>{f[0], f[1], f[3]}, std::array<int, 3>{f[1], f[2], f[3]}}) {
          best =
              std::min(best, PointTriangleDistance(L(p), L(Q[tri[0]]), L(Q[tri[1]]), L(Q[tri[2]])));
        }
      }
    }
  };
  vertex_faces(A, B);
  vertex_faces(B, A);
  for (const auto& ea : topo.edges)
    for (const auto& eb : topo.edges)
      best = std::min(best,
                      SegmentSegmentDistance(L(A[ea[0]]), L(A[ea[1]]), L(B[eb[0]]), L(B[eb[1]])));
  return best;
}

// Penetration depth of two overlapping convex hexahedra: the smallest
// overlap over face normals and edge cross products.
inline long double PenetrationDepth(const std::array<Eigen::Vector3d, 8>& A,
                                    const std::array<Eigen::Vector3d, 8>& B, const Topology& topo) {
  long double best = INFINITY;
  auto axis = [&](V3 n) {
    const long double len = n.norm();
    if (!(len > 1e-30L)) return;
    n /= len;
    long double alo = INFINITY, ahi = -INFINITY, blo = INFINITY, bhi = -INFINITY;
    for (const auto& p : A) {
      const long double v = n.dot(L(p));
      alo = std::min(alo, v);
      ahi = std::max(ahi, v);
    }
    for (const auto& p : B) {
      const long double v = n.dot(L(p));
      blo = std::min(blo, v);
      bhi = std::max(bhi, v);
    }
    best = std::min(best, std::min(ahi - blo, bhi - alo));
  };
  for (const auto* P : {&A, &B})
    for (const auto& f : topo.faces)
      axis((L((*P)[f[2]]) - L((*P)[f[0]])).cross(L((*P)[f[3]]) - L((*P)[f[1]])));
  for (const auto& ea : topo.edges)
    for (const auto& eb : topo.edges)
      axis((L(A[ea[1]]) - L(A[ea[0]])).cross(L(B[eb[1]]) - L(B[eb[0]])));
  return best;
}

}  // namespace rms::reference
