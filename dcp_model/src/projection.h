#pragma once
// A solid's extent along a direction (private to the DCP's library): shared
// by the collision test's planes (collision.cc) and the widest edge-axis
// search (widest_edge_axis.cc), which must compute it with the same
// operations in the same order (docs/performance.md, "the same bits").
#include <Eigen/Core>
#include <algorithm>
#include <limits>

#include "rms/dcp_model/hexahedron.h"

namespace rms::dcp_model::internal {

// The least and greatest of n . v over h's vertices v, each projection
// (n.x x + n.y y) + n.z z, the extremes taken vertex by vertex in order.
inline void ProjectionRange(const Hexahedron& h, const Eigen::Vector3d& n, double* lo, double* hi) {
  *lo = std::numeric_limits<double>::infinity();
  *hi = -*lo;
  for (int i = 0; i < kNumVertices; ++i) {
    const double p = n.x() * h.x[i] + n.y() * h.y[i] + n.z() * h.z[i];
    *lo = std::min(*lo, p);
    *hi = std::max(*hi, p);
  }
}

}  // namespace rms::dcp_model::internal
