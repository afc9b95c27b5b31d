#pragma once
// The Visual Scene Program's visual priority (docs/scene.md "Visual
// priority"), after Schumacker et al. (1969) as General Electric's ESG did
// it: each frame, one bit a cluster pair, set when the viewpoint is on the
// side of the pair's first cluster (rms/scene_model/cluster_pairs.h). The
// planes of fixed or rigidly joined pairs are found once; the others every
// frame, last frame's plane tried first; the DCP's three come with its frame.
#include <Eigen/Geometry>
#include <array>
#include <cstdint>

#include "rms/base/counters.h"
#include "rms/scene_model/cluster_pairs.h"
#include "rms/scene_model/scene_model.h"
#include "rms/scene_model/separating_plane.h"

namespace rms::scene_proc {

// How a pair's plane is set: the priority table of docs/scene.md.
enum class PlaneSource : std::uint8_t {
  kFixed,    // both clusters fixed (orbiter, CAE): computed once
  kRigid,    // rigidly joined (the payload's parts; wrist, palm, fixed finger; elbow, lower boom)
  kDcp,      // the DCP's dynamic plane (falls back to kDynamic when the DCP has none)
  kDynamic,  // found every frame by scene_proc, last frame's plane tried first
};
const char* PlaneSourceName(PlaneSource s);

class PriorityPlanner {
 public:
  explicit PriorityPlanner(const scene_model::SceneModel& model);
  // dcp_planes / dcp_valid: the DCP's three planes (valid bits 0-2).
  // Counters: "priority.dynamic_searches" (planes searched afresh),
  // "priority.unresolved" (pairs no plane separates: decided by distance).
  scene_model::PriorityBits Compute(const scene_model::ClusterPoses& poses,
                                    const Eigen::Vector3d& p_RoEye_R,
                                    const std::array<scene_model::SeparatingPlane, 3>& dcp_planes,
                                    std::uint32_t dcp_valid, Counters* counters);
  PlaneSource source(int pair) const { return source_[pair]; }
  // A fixed or rigid pair's plane as found (in R), and the pose of the
  // pair's first cluster then (X_RA): the plane moves with that cluster.
  bool has_fixed_plane(int pair) const { return have_last_[pair]; }
  const scene_model::SeparatingPlane& fixed_plane(int pair) const { return last_[pair]; }
  const Eigen::Affine3d& fixed_plane_pose(int pair) const { return X_RA_found_[pair]; }

 private:
  bool FixedPlaneBit(int pair, const scene_model::ClusterPoses& poses,
                     const Eigen::Vector3d& p_RoEye_R, const scene_model::PosedHull& a,
                     const scene_model::PosedHull& b, bool* bit);
  const scene_model::SceneModel& model_;
  std::array<PlaneSource, scene_model::kNumPairs> source_{};
  // kFixed / kRigid: the plane as found and the first cluster's pose then;
  // kDynamic: last frame's plane. Both in R.
  std::array<scene_model::SeparatingPlane, scene_model::kNumPairs> last_{};
  std::array<Eigen::Affine3d, scene_model::kNumPairs> X_RA_found_{};
  std::array<bool, scene_model::kNumPairs> have_last_{};
};

}  // namespace rms::scene_proc
