#include "rms/scene_proc/priority_planner.h"

#include <algorithm>
#include <optional>
#include <spdlog/spdlog.h>

namespace rms::scene_proc {

using scene_model::PosedHull;
using scene_model::SeparatingPlane;

const char* PlaneSourceName(PlaneSource s) {
  switch (s) {
    case PlaneSource::kFixed:
      return "fixed";
    case PlaneSource::kRigid:
      return "rigid";
    case PlaneSource::kDcp:
      return "DCP";
    case PlaneSource::kDynamic:
      return "dynamic";
  }
  return "?";
}

namespace {

// Frames that move together: fixed clusters; the payload; the wrist, palm
// and fixed finger; the elbow and the lower boom.
int RigidGroup(scene_model::ClusterFrame f) {
  switch (f) {
    case scene_model::ClusterFrame::kReference:
    case scene_model::ClusterFrame::kCae:
      return 0;
    case scene_model::ClusterFrame::kPayload:
      return 1;
    case scene_model::ClusterFrame::kF6:
    case scene_model::ClusterFrame::kSystemTwo:
      return 2;
    case scene_model::ClusterFrame::kF3:
      return 3;
    default:
      return -1;  // scaled (the post) or alone
  }
}

// How far two clusters may overlap and still be "touching": the ESG words
// carry positions to 2.4e-4 ft (FT12), so touching parts can come out that
// far into each other.
double PlaneTolerance(const scene_model::PosedHull& a, const scene_model::PosedHull& b) {
  return std::max(1e-6 * std::max(a.scale_ft, b.scale_ft), 5e-4);
}

}  // namespace

PriorityPlanner::PriorityPlanner(const scene_model::SceneModel& model) : model_(model) {
  for (int p = 0; p < scene_model::kNumPairs; ++p) {
    const auto [a, b] = scene_model::PairOf(p);
    const int ga = RigidGroup(model[a].frame), gb = RigidGroup(model[b].frame);
    if (scene_model::DcpPairSlot(p) >= 0)
      source_[p] = PlaneSource::kDcp;
    else if (ga == 0 && gb == 0)
      source_[p] = PlaneSource::kFixed;
    else if (ga >= 0 && ga == gb)
      source_[p] = PlaneSource::kRigid;
    else
      source_[p] = PlaneSource::kDynamic;
  }
}

// A fixed or rigid pair: its plane is found the first time it is needed,
// from that frame's poses, and moves with the pair's first cluster after
// (the eye is carried back into that frame's pose). False when no plane
// separates the pair: it becomes dynamic.
bool PriorityPlanner::FixedPlaneBit(int p, const scene_model::ClusterPoses& poses,
                                    const Eigen::Vector3d& eye, const scene_model::PosedHull& ha,
                                    const scene_model::PosedHull& hb, bool* bit) {
  const int a = scene_model::PairOf(p).first;
  if (!have_last_[p]) {
    const std::optional<scene_model::SeparatingPlane> plane =
        scene_model::FindSeparatingPlane(ha, hb, PlaneTolerance(ha, hb), nullptr);
    if (!plane) {
      spdlog::warn("no plane separates {} and {}: the scene model overlaps",
                   scene_model::ClusterName(a),
                   scene_model::ClusterName(scene_model::PairOf(p).second));
      source_[p] = PlaneSource::kDynamic;
      return false;
    }
    last_[p] = *plane;
    X_RA_found_[p] = poses.X_RC[a];
    have_last_[p] = true;
  }
  const Eigen::Affine3d& X_now = poses.X_RC[a];
  const Eigen::Vector3d eye_then =
      X_RA_found_[p] * (X_now.linear().transpose() * (eye - X_now.translation()));
  *bit = last_[p].SignedDistanceFt(eye_then) < 0;
  return true;
}

scene_model::PriorityBits PriorityPlanner::Compute(
    const scene_model::ClusterPoses& poses, const Eigen::Vector3d& eye,
    const std::array<scene_model::SeparatingPlane, 3>& dcp_planes, std::uint32_t dcp_valid,
    Counters* counters) {
  std::array<std::optional<scene_model::PosedHull>, scene_model::kNumClusters> hulls;
  auto hull = [&](int c) -> const scene_model::PosedHull& {
    if (!hulls[c]) hulls[c] = scene_model::PoseHull(model_[c], poses.X_RC[c]);
    return *hulls[c];
  };
  scene_model::PriorityBits bits;
  for (int p = 0; p < scene_model::kNumPairs; ++p) {
    const auto [a, b] = scene_model::PairOf(p);
    if (!poses.present[a] || !poses.present[b]) continue;
    if (source_[p] == PlaneSource::kDcp) {
      const int k = scene_model::DcpPairSlot(p);
      if (dcp_valid & (1u << k)) {
        bits[p] = dcp_planes[k].SignedDistanceFt(eye) < 0;
        continue;
      }
    } else if (source_[p] == PlaneSource::kFixed || source_[p] == PlaneSource::kRigid) {
      bool bit = false;
      if (FixedPlaneBit(p, poses, eye, hull(a), hull(b), &bit)) {
        bits[p] = bit;
        continue;
      }
    }
    // Dynamic: last frame's plane if it still separates, else a fresh search.
    const scene_model::PosedHull& ha = hull(a);
    const scene_model::PosedHull& hb = hull(b);
    int tried = 0;
    const std::optional<scene_model::SeparatingPlane> plane = scene_model::FindSeparatingPlane(
        ha, hb, PlaneTolerance(ha, hb), have_last_[p] ? &last_[p] : nullptr, &tried);
    if (tried > 1 && counters) counters->Add(Counter::kPriorityDynamicSearches);
    if (plane) {
      last_[p] = *plane;
      have_last_[p] = true;
      bits[p] = plane->SignedDistanceFt(eye) < 0;
    } else {
      have_last_[p] = false;
      if (counters) counters->Add(Counter::kPriorityUnresolved);
      bits[p] = (eye - ha.centroid_R).norm() < (eye - hb.centroid_R).norm();
    }
  }
  return bits;
}

}  // namespace rms::scene_proc
