// Forward kinematics against poses computed by hand (docs/kinematics.md).
#include "rms/arm/kinematics.h"

#include <gtest/gtest.h>
#include <random>

#include "rms/base/config.h"

namespace rms {
namespace {

using Eigen::Vector3d;

class Kinematics : public ::testing::Test {
 protected:
  Kinematics() {
    arm.p_RoB_R_ft = Vector3d(1.5, -9.0, 0.0);
    arm.upper_boom_ft = 20.0;
    arm.lower_boom_ft = 25.0;
    arm.wrist_to_palm_ft = 5.0;
  }
  arm::ArmPose Pose(std::array<double, 6> deg, double h = 3.0) {
    return arm::ComputeArmPose(arm, arm::SinCosFromDegrees(deg), h);
  }
  ArmGeometry arm;
};

#define EXPECT_VEC_NEAR(a, b, tol) \
  EXPECT_LT(((a) - (b)).norm(), tol) << (a).transpose() << " vs " << (b).transpose()

TEST_F(Kinematics, ZeroAnglesLayTheArmAftAlongXr) {
  const arm::ArmPose p = Pose({0, 0, 0, 0, 0, 0}, 3.0);
  const Vector3d S(1.5, -9.0, 3.0);
  EXPECT_VEC_NEAR(p.p_RoS_R, S, 1e-12);
  EXPECT_VEC_NEAR(p.p_RoE_R, S + Vector3d(20, 0, 0), 1e-12);
  EXPECT_VEC_NEAR(p.p_RoW_R, S + Vector3d(45, 0, 0), 1e-12);
  EXPECT_VEC_NEAR(p.X_RS2.translation(), S + Vector3d(50, 0, 0), 1e-12);
  EXPECT_LT((p.X_RS2.linear() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

TEST_F(Kinematics, ShoulderYawTurnsTheArmTowardPlusY) {
  const arm::ArmPose p = Pose({90, 0, 0, 0, 0, 0});
  const Vector3d S(1.5, -9.0, 3.0);
  EXPECT_VEC_NEAR(p.X_RS2.translation(), S + Vector3d(0, 50, 0), 1e-12);
  EXPECT_VEC_NEAR(p.X_RS2.linear().col(0), Vector3d(0, 1, 0), 1e-12);   // X2
  EXPECT_VEC_NEAR(p.X_RS2.linear().col(1), Vector3d(-1, 0, 0), 1e-12);  // Y2
  EXPECT_VEC_NEAR(p.X_RS2.linear().col(2), Vector3d(0, 0, 1), 1e-12);   // Z2
}

TEST_F(Kinematics, PositiveShoulderPitchRaisesTheArm) {
  const arm::ArmPose p = Pose({0, 90, 0, 0, 0, 0});
  const Vector3d S(1.5, -9.0, 3.0);
  EXPECT_VEC_NEAR(p.p_RoE_R, S + Vector3d(0, 0, 20), 1e-12);
  EXPECT_VEC_NEAR(p.X_RS2.translation(), S + Vector3d(0, 0, 50), 1e-12);
  EXPECT_VEC_NEAR(p.X_RS2.linear().col(0), Vector3d(0, 0, 1), 1e-12);
  EXPECT_VEC_NEAR(p.X_RS2.linear().col(2), Vector3d(-1, 0, 0), 1e-12);
}

TEST_F(Kinematics, ElbowDownFromAVerticalUpperBoom) {
  const arm::ArmPose p = Pose({0, 90, -90, 0, 0, 0});
  const Vector3d S(1.5, -9.0, 3.0);
  EXPECT_VEC_NEAR(p.p_RoE_R, S + Vector3d(0, 0, 20), 1e-12);
  EXPECT_VEC_NEAR(p.p_RoW_R, S + Vector3d(25, 0, 20), 1e-12);
  EXPECT_VEC_NEAR(p.X_RS2.translation(), S + Vector3d(30, 0, 20), 1e-12);
}

TEST_F(Kinematics, WristPitchYawAndRoll) {
  const Vector3d W = Vector3d(1.5, -9.0, 3.0) + Vector3d(45, 0, 0);
  {  // wrist pitch -90: X2 points down
    const arm::ArmPose p = Pose({0, 0, 0, -90, 0, 0});
    EXPECT_VEC_NEAR(p.X_RS2.translation(), W + Vector3d(0, 0, -5), 1e-12);
    EXPECT_VEC_NEAR(p.X_RS2.linear().col(0), Vector3d(0, 0, -1), 1e-12);
  }
  {  // wrist yaw +90: X2 along +Y
    const arm::ArmPose p = Pose({0, 0, 0, 0, 90, 0});
    EXPECT_VEC_NEAR(p.X_RS2.translation(), W + Vector3d(0, 5, 0), 1e-12);
  }
  {  // wrist roll +90 about X2: Y2 -> +Z, Z2 -> -Y
    const arm::ArmPose p = Pose({0, 0, 0, 0, 0, 90});
    EXPECT_VEC_NEAR(p.X_RS2.translation(), W + Vector3d(5, 0, 0), 1e-12);
    EXPECT_VEC_NEAR(p.X_RS2.linear().col(1), Vector3d(0, 0, 1), 1e-12);
    EXPECT_VEC_NEAR(p.X_RS2.linear().col(2), Vector3d(0, -1, 0), 1e-12);
  }
}

TEST_F(Kinematics, TheDemoGraspPoseComputedByHand) {
  // docs/kinematics.md works this pose by hand with the default arm: the
  // wrist above the receptacle at (32.5, 0, 7.39), X2 straight down.
  ArmGeometry def;
  def.p_RoB_R_ft = Vector3d(1.5, -9.0, 0.0);
  def.upper_boom_ft = 20.9;
  def.lower_boom_ft = 23.2;
  def.wrist_to_palm_ft = 6.15;
  const arm::ArmPose p = arm::ComputeArmPose(
      def, arm::SinCosFromDegrees({16.19, 52.93, -84.89, -58.04, 0, -73.81}), 3.0);
  EXPECT_VEC_NEAR(p.p_RoW_R, Vector3d(32.50, 0.0, 7.39), 0.02);
  EXPECT_VEC_NEAR(p.X_RS2.translation(), Vector3d(32.50, 0.0, 1.24), 0.02);
  EXPECT_VEC_NEAR(p.X_RS2.linear().col(0), Vector3d(0, 0, -1), 1e-3);
  // Before the roll Y2 heads 106.19 deg from +X_R; rolling -73.81 deg about
  // X2 (pointing down) turns it by +73.81 deg to 180: Y2 along -X_R, so the
  // fingers close along the payload's long axis.
  EXPECT_VEC_NEAR(p.X_RS2.linear().col(1), Vector3d(-1, 0, 0), 1e-3);
}

TEST_F(Kinematics, ShoulderHeightMovesEverythingUp) {
  const arm::ArmPose a = Pose({10, 20, -30, 40, 50, 60}, 2.0);
  const arm::ArmPose b = Pose({10, 20, -30, 40, 50, 60}, 7.5);
  EXPECT_VEC_NEAR(b.X_RS2.translation() - a.X_RS2.translation(), Vector3d(0, 0, 5.5), 1e-12);
}

TEST_F(Kinematics, RandomPosesAreRigidAndIgnoreThePairsScale) {
  const std::uint64_t seed = 5;
  std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ang(-180, 180), scale(0.99, 1.01);
  for (int i = 0; i < 10000; ++i) {
    std::array<double, 6> deg{};
    for (double& d : deg) d = ang(rng);
    arm::ArmSinCos sc = arm::SinCosFromDegrees(deg);
    const arm::ArmPose p = arm::ComputeArmPose(arm, sc, 3.0);
    const Eigen::Matrix3d R = p.X_RS2.linear();
    ASSERT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    ASSERT_NEAR(R.determinant(), 1.0, 1e-12);
    ASSERT_NEAR((p.p_RoE_R - p.p_RoS_R).norm(), 20.0, 1e-9);
    ASSERT_NEAR((p.p_RoW_R - p.p_RoE_R).norm(), 25.0, 1e-9);
    for (arm::SinCos& a : sc) {
      const double k = scale(rng);
      a.s *= k;
      a.c *= k;
    }
    const arm::ArmPose q = arm::ComputeArmPose(arm, sc, 3.0);
    ASSERT_LT((q.X_RS2.translation() - p.X_RS2.translation()).norm(), 1e-9);
  }
}

}  // namespace
}  // namespace rms

#include "rms/mission/arm_ik.h"

namespace rms {
namespace {

TEST(ArmIk, ForwardOfInverseIsTheTargetPose) {
  const LabConfig config = LoadConfig(DefaultConfigPath());
  const std::uint64_t seed = 17;
  std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ang(-170, 170), wy(-80, 80), h(0, 20);
  int solved = 0;
  for (int i = 0; i < 20000; ++i) {
    // A reachable target: forward kinematics of random angles.
    const std::array<double, 6> deg = {ang(rng), ang(rng), ang(rng), ang(rng), wy(rng), ang(rng)};
    const double height = h(rng);
    const arm::ArmPose p = arm::ComputeArmPose(config.arm, arm::SinCosFromDegrees(deg), height);
    for (mission::Elbow elbow : {mission::Elbow::kUp, mission::Elbow::kDown}) {
      const auto s = mission::SolveArmIk(config.arm, p.X_RS2, height, elbow);
      ASSERT_TRUE(s.has_value());
      const arm::ArmPose q =
          arm::ComputeArmPose(config.arm, arm::SinCosFromDegrees(s->angles_deg), height);
      ASSERT_LT((q.X_RS2.translation() - p.X_RS2.translation()).norm(), 1e-7);
      ASSERT_LT((q.X_RS2.linear() - p.X_RS2.linear()).norm(), 1e-7);
      ++solved;
    }
  }
  EXPECT_EQ(solved, 40000);
}

TEST(ArmIk, OutOfReachHasNoSolution) {
  const LabConfig config = LoadConfig(DefaultConfigPath());
  const auto X = mission::EndEffectorPose(Eigen::Vector3d(200, 0, 0), Eigen::Vector3d::UnitX(),
                                          Eigen::Vector3d::UnitY());
  EXPECT_FALSE(mission::SolveArmIk(config.arm, X, 3.0).has_value());
}

}  // namespace
}  // namespace rms
