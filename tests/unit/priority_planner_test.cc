// The Visual Scene Program's PriorityPlanner (rms/scene_proc/
// priority_planner.h) on its own: each pair's source as docs/scene.md's
// table says, the DCP's planes taken as sent, fixed planes found once and
// followed, last frame's plane kept, and a pair no plane separates decided
// by distance and counted.
#include "rms/scene_proc/priority_planner.h"

#include <gtest/gtest.h>

#include "rms/arm/kinematics.h"
#include "rms/base/config.h"
#include "rms/base/counters.h"

namespace rms::scene_proc {
namespace {

using scene_model::PairIndex;

class PriorityPlannerTest : public ::testing::Test {
 protected:
  PriorityPlannerTest() : config_(LoadConfig(DefaultConfigPath())) {
    model_ = scene_model::BuildSceneModel(config_);
    pose_.arm = arm::SinCosFromDegrees({0, 30, -60, -60, 0, 0});
    pose_.shoulder_height_ft = 3.0;
    pose_.finger_gap_ft = config_.end_effector.finger_gap_open_ft;
    pose_.p_RoPo_R_ft = config_.payload.p_RoPo_R_ft;
    pose_.R_RP = config_.payload.R_RP;
    poses_ = scene_model::ComputeClusterPoses(config_, pose_);
  }
  LabConfig config_;
  scene_model::SceneModel model_;
  scene_model::ScenePose pose_;
  scene_model::ClusterPoses poses_;
  std::array<scene_model::SeparatingPlane, 3> no_planes_{};
};

TEST_F(PriorityPlannerTest, EachPairTakesItsPlaneFromWhereTheTableSays) {
  const PriorityPlanner planner(model_);
  using namespace scene_model;
  EXPECT_EQ(planner.source(PairIndex(kFloor, kCabin)), PlaneSource::kFixed);
  EXPECT_EQ(planner.source(PairIndex(kWallPort, kCaeModule)), PlaneSource::kFixed);
  EXPECT_EQ(planner.source(PairIndex(kPayloadBody, kProbe)), PlaneSource::kRigid);
  EXPECT_EQ(planner.source(PairIndex(kFloor, kPayloadBody)), PlaneSource::kDynamic);
  EXPECT_EQ(planner.source(PairIndex(kUpperBoom, kLowerBoom)), PlaneSource::kDynamic);
  for (const auto& [a, b] : kDcpPairs)
    EXPECT_EQ(planner.source(PairIndex(a, b)), PlaneSource::kDcp);
}

TEST_F(PriorityPlannerTest, TheDcpsPlanesAreTakenAsSentAndSearchedForWhenNotValid) {
  PriorityPlanner planner(model_);
  Counters counters;
  const auto [a, b] = scene_model::kDcpPairs[0];
  const int pair = PairIndex(a, b);
  const Eigen::Vector3d eye(0, 0, 30);
  std::array<scene_model::SeparatingPlane, 3> planes{};
  planes[0] = {Eigen::Vector3d::UnitZ(), 100.0};  // the eye below it: on A's side
  EXPECT_TRUE(planner.Compute(poses_, eye, planes, 0b001, &counters)[pair]);
  planes[0] = {-Eigen::Vector3d::UnitZ(), -100.0};  // the same plane facing the other way
  EXPECT_FALSE(planner.Compute(poses_, eye, planes, 0b001, &counters)[pair]);
  const std::int64_t searches = counters.Get(Counter::kPriorityDynamicSearches);
  planner.Compute(poses_, eye, planes, 0b000, &counters);  // not valid: its own search
  EXPECT_GT(counters.Get(Counter::kPriorityDynamicSearches), searches);
}

TEST_F(PriorityPlannerTest, AFixedPlaneIsFoundOnceAndTheEyesSideDecides) {
  PriorityPlanner planner(model_);
  Counters counters;
  const Eigen::Vector3d eye(10, 40, 25);
  planner.Compute(poses_, eye, no_planes_, 0, &counters);
  int checked = 0;
  for (int p = 0; p < scene_model::kNumPairs; ++p) {
    if (planner.source(p) != PlaneSource::kFixed || !planner.has_fixed_plane(p)) continue;
    const scene_model::SeparatingPlane& plane = planner.fixed_plane(p);
    const Eigen::Vector3d on_plane = plane.n_R * plane.d_ft;
    const auto behind_a =
        planner.Compute(poses_, on_plane - 1000 * plane.n_R, no_planes_, 0, nullptr);
    const auto behind_b =
        planner.Compute(poses_, on_plane + 1000 * plane.n_R, no_planes_, 0, nullptr);
    EXPECT_TRUE(behind_a[p]) << "pair " << p << ": the eye on A's side, A in front";
    EXPECT_FALSE(behind_b[p]) << "pair " << p;
    ++checked;
  }
  EXPECT_GT(checked, 50);
  // The same frame again: every plane is last frame's, nothing searched
  // but the pairs no plane separates (touching parts: each searched and
  // counted unresolved every frame).
  const auto first = planner.Compute(poses_, eye, no_planes_, 0, &counters);
  const std::int64_t searches = counters.Get(Counter::kPriorityDynamicSearches);
  const std::int64_t unresolved = counters.Get(Counter::kPriorityUnresolved);
  const auto again = planner.Compute(poses_, eye, no_planes_, 0, &counters);
  EXPECT_EQ(first, again);
  EXPECT_EQ(counters.Get(Counter::kPriorityDynamicSearches) - searches,
            counters.Get(Counter::kPriorityUnresolved) - unresolved);
}

TEST_F(PriorityPlannerTest, APairNoPlaneSeparatesIsDecidedByDistanceAndCounted) {
  PriorityPlanner planner(model_);
  Counters counters;
  // The payload sunk through the bay's floor: no plane separates the two.
  scene_model::ScenePose sunk = pose_;
  sunk.p_RoPo_R_ft.z() -= 3.0;
  const scene_model::ClusterPoses poses = scene_model::ComputeClusterPoses(config_, sunk);
  const int pair = PairIndex(scene_model::kFloor, scene_model::kPayloadBody);
  const Eigen::Vector3d eye = poses.X_RC[scene_model::kPayloadBody].translation() +
                              Eigen::Vector3d(0, 0, 40);  // nearer the payload's centre
  const auto bits = planner.Compute(poses, eye, no_planes_, 0, &counters);
  EXPECT_GT(counters.Get(Counter::kPriorityUnresolved), 0);
  const scene_model::PosedHull floor =
      scene_model::PoseHull(model_[scene_model::kFloor], poses.X_RC[scene_model::kFloor]);
  const scene_model::PosedHull body = scene_model::PoseHull(model_[scene_model::kPayloadBody],
                                                            poses.X_RC[scene_model::kPayloadBody]);
  ASSERT_FALSE(scene_model::FindSeparatingPlane(floor, body, 1e-3, nullptr).has_value());
  EXPECT_EQ(bits[pair], (eye - floor.centroid_R).norm() < (eye - body.centroid_R).norm());
}

}  // namespace
}  // namespace rms::scene_proc
