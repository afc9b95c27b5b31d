#pragma once
// The ESG's visual priority (docs/esg.md "Visibility"): the clusters to draw,
// back to front, from the frame's priority bits (rms/scene_model/cluster_pairs.h)
// with no depth buffer, as General Electric's ESG did after Schumacker et al.
// (1969).
#include <Eigen/Core>
#include <array>
#include <vector>

#include "rms/scene_model/cluster_pairs.h"

namespace rms::esg_renderer {

// A pair's bit orders its clusters only when their silhouettes overlap; a cycle (which a
// well-formed scene does not have) is broken at the cluster with the fewest
// clusters still to be drawn behind it, and counted.
struct ScreenBox {
  bool visible = false;     // anything of it inside the view volume
  bool everywhere = false;  // it reaches behind the eye: it may cover any part of the screen
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // its screen rectangle, normalised device coordinates
  // Its silhouette: the convex hull of its projected points, counter-clockwise.
  std::vector<Eigen::Vector2f> outline;
};
// The convex hull of 2D points (Andrew's monotone chain), counter-clockwise.
std::vector<Eigen::Vector2f> ConvexHull2d(std::vector<Eigen::Vector2f> points);
// Do two silhouettes overlap by more than `tol` (a separating-axis test on
// their outlines' edge normals)?
bool OutlinesOverlap(const ScreenBox& a, const ScreenBox& b, float tol);
// overlap_tol: how far (NDC) silhouettes must overlap to be ordered.
std::vector<int> DrawOrder(const scene_model::PriorityBits& bits,
                           const std::array<ScreenBox, scene_model::kNumClusters>& boxes,
                           int* cycles_broken, float overlap_tol = 1e-3f);

}  // namespace rms::esg_renderer
