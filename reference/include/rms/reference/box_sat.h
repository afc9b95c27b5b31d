#pragma once
// Reference for boxes: the 15-axis separating-axis test in long double
// (independent of the DCP's algorithm). Closed boxes: touching intersects.
#include <Eigen/Core>
#include <array>
#include <cmath>

namespace rms::reference {

using Vec3L = Eigen::Matrix<long double, 3, 1>;

struct RefBox {
  Vec3L centre;
  std::array<Vec3L, 3> axis;  // unit axes
  std::array<long double, 3> half;
};

// Signed separation along the best of the 15 axes: > 0 is a gap (the boxes
// are disjoint, and the distance is at least this), <= 0 is minus the
// penetration depth (exact for boxes: the 15 axes are all the Minkowski face
// normals).
inline long double BoxSatSeparation(const RefBox& a, const RefBox& b) {
  const Vec3L t = b.centre - a.centre;
  long double best = -INFINITY;
  auto test = [&](Vec3L l) {
    const long double len = l.norm();
    if (!(len > 1e-30L)) return;  // parallel edges: no axis
    l /= len;
    long double ra = 0, rb = 0;
    for (int i = 0; i < 3; ++i) {
      ra += a.half[i] * std::fabs(a.axis[i].dot(l));
      rb += b.half[i] * std::fabs(b.axis[i].dot(l));
    }
    best = std::max(best, std::fabs(t.dot(l)) - ra - rb);
  };
  for (int i = 0; i < 3; ++i) test(a.axis[i]);
  for (int i = 0; i < 3; ++i) test(b.axis[i]);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) test(a.axis[i].cross(b.axis[j]));
  return best;
}

inline bool BoxesIntersect(const RefBox& a, const RefBox& b) { return BoxSatSeparation(a, b) <= 0; }

}  // namespace rms::reference
