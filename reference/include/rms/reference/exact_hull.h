#pragma once
// Exact reference for general convex hexahedra: do the convex hulls of two
// sets of eight points (double coordinates) intersect? Closed sets: touching
// intersects. A separating-axis test over the hulls' facet normals and the
// cross products of their edges, every sign decided exactly: interval
// arithmetic first (CGAL::Interval_nt), exact rationals (CGAL::Gmpq) when an
// interval cannot decide. Hull facets come from CGAL's exact orientation
// predicate. Independent of the DCP's algorithm.
#include <Eigen/Core>
#include <array>

namespace rms::reference {

bool ExactHullsIntersect(const std::array<Eigen::Vector3d, 8>& a,
                         const std::array<Eigen::Vector3d, 8>& b);

// How many axis decisions needed exact rationals (for the test's report).
long ExactFallbacks();

}  // namespace rms::reference
