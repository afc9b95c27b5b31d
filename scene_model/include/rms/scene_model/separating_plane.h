#pragma once
// The one plane type: a separating plane in Reference coordinates. The DCP
// finds its three dynamic planes with the report's collision test (IV.A.1;
// docs/collision.md); the Visual Scene Program finds the others between the
// scene's convex clusters (docs/scene.md "Visual priority"); the ESG frame
// and the DCP frame carry them (docs/protocol.md).
#include <Eigen/Geometry>
#include <optional>
#include <vector>

namespace rms::scene_model {

struct Cluster;

// Points p with n_R . p = d_ft. n_R is a unit normal in R pointing to the
// plane's TRUE side: from the pair's first solid (A, the lower cluster id;
// the end effector for the DCP's planes) toward the second (B).
struct SeparatingPlane {
  Eigen::Vector3d n_R = Eigen::Vector3d::UnitZ();
  double d_ft = 0.0;
  // Signed distance of p_R (a point in R, ft) from the plane: > 0 on B's side.
  double SignedDistanceFt(const Eigen::Vector3d& p_R) const { return n_R.dot(p_R) - d_ft; }
};

// A cluster's separating-plane data, posed in R (ft).
struct PosedHull {
  std::vector<Eigen::Vector3d> points_R, normals_R, edges_R;
  Eigen::Vector3d centroid_R = Eigen::Vector3d::Zero();
  double scale_ft = 0.0;  // the largest distance of a point from the centroid
};
// X_RC: the cluster's frame C in R (affine: the vertical fixed arm is scaled).
PosedHull PoseHull(const Cluster& c, const Eigen::Affine3d& X_RC);

// A plane with A at or below it and B at or above it (touching allowed
// within eps_ft), or nothing when they interpenetrate. `hint` (last frame's
// plane) is tried first. Candidate axes: the hint, the centroids' difference,
// the face normals (and a flat cluster's in-plane edge normals), then the
// cross products of the edge directions.
std::optional<SeparatingPlane> FindSeparatingPlane(const PosedHull& a, const PosedHull& b,
                                                   double eps_ft, const SeparatingPlane* hint,
                                                   int* axes_tried = nullptr);

}  // namespace rms::scene_model
