// Rates to angles (operator_station/src/arm_motion.h): the Jacobian against
// finite differences of the forward kinematics; a commanded velocity of the
// point of resolution and angular velocity give that motion; near singular
// poses the joints move smoothly (no jumps); a joint at its limit stops
// there and is reported.
#include "rms/operator_station/arm_motion.h"

#include <cstdio>
#include <gtest/gtest.h>
#include <random>

#include "rms/arm/kinematics.h"
#include "rms/base/config.h"

namespace rms::operator_station {
namespace {

constexpr double kDeg = M_PI / 180.0;

class ArmMotion : public ::testing::Test {
 protected:
  LabConfig config = LoadConfig(DefaultConfigPath());
  JointLimits limits = LimitsFromConfig(config, 12.0);
  const Eigen::Vector3d por{1.85, 0.1, 0.0};  // about the grasp point, in System Two
  const double h = 3.0;

  Eigen::Vector3d Point(const JointAngles& q) const { return ForwardPose(config.arm, q, h) * por; }
  Eigen::Matrix3d Rot(const JointAngles& q) const { return ForwardPose(config.arm, q, h).linear(); }
};

// A pose well inside the workspace and away from singularities.
JointAngles RandomPose(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return {40 * u(rng),       50 + 25 * u(rng), -80 + 30 * u(rng),
          -40 + 40 * u(rng), 40 * u(rng),      90 * u(rng)};
}

TEST_F(ArmMotion, TheJacobianIsTheForwardKinematicsDerivative) {
  constexpr unsigned kSeed = 20261201;
  std::printf("seed %u\n", kSeed);
  std::mt19937 rng(kSeed);
  for (int k = 0; k < 20; ++k) {
    const JointAngles q = RandomPose(rng);
    const Matrix6d J = ArmJacobian(config.arm, q, h, por);
    for (int i = 0; i < 6; ++i) {
      JointAngles a = q, b = q;
      const double e = 1e-4;  // deg
      a[i] -= e;
      b[i] += e;
      const Eigen::Vector3d v = (Point(b) - Point(a)) / (2 * e * kDeg);
      const Eigen::Vector3d w = RotationVector(Rot(b) * Rot(a).transpose()) / (2 * e * kDeg);
      EXPECT_NEAR((v - J.block<3, 1>(0, i)).norm(), 0.0, 1e-5) << "joint " << i;
      EXPECT_NEAR((w - J.block<3, 1>(3, i)).norm(), 0.0, 1e-7) << "joint " << i;
    }
  }
}

TEST_F(ArmMotion, ACommandedVelocityGivesThatVelocity) {
  constexpr unsigned kSeed = 7421;
  std::printf("seed %u\n", kSeed);
  std::mt19937 rng(kSeed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double dt = 1.0 / 30;
  for (int k = 0; k < 30; ++k) {
    const JointAngles q = RandomPose(rng);
    const Eigen::Vector3d v(u(rng), u(rng), u(rng));  // ft/s, up to 1.7
    const Eigen::Vector3d w = Eigen::Vector3d(u(rng), u(rng), u(rng)) * 4 * kDeg;  // up to 7 deg/s
    const RateResult r = ResolveRate(config.arm, limits, q, h, por, v, w, dt);
    ASSERT_EQ(r.at_limit, 0u);
    if (r.singular || r.rate_limited) continue;
    const Eigen::Vector3d v_fd = (Point(r.q_deg) - Point(q)) / dt;
    const Eigen::Vector3d w_fd = RotationVector(Rot(r.q_deg) * Rot(q).transpose()) / dt;
    // First order in dt: a frame's step is a few hundredths of a foot.
    EXPECT_LT((v_fd - v).norm(), 2e-3 * (1 + v.norm())) << "pose " << k;
    EXPECT_LT((w_fd - w).norm(), 1e-3 * (1 + w.norm())) << "pose " << k;
    EXPECT_LT((r.achieved.head<3>() - v).norm(), 1e-9);
  }
}

TEST_F(ArmMotion, NearSingularPosesTheJointsMoveWithoutJumps) {
  // Three singular poses: the straight arm (the stowed start: elbow 0), the
  // wrist's gimbal lock (wrist yaw 90), and the arm reaching straight up
  // over its shoulder; commanded every way, the joints never step more than
  // their rates allow, and move on smoothly.
  const std::vector<JointAngles> starts = {
      {0, 0, 0, 0, 0, 0}, {15, 60, -75, -30, 90, 0}, {0, 90, 0, 0, 0, 0}};
  const double dt = 1.0 / 30;
  for (const JointAngles& q0 : starts) {
    for (int axis = 0; axis < 6; ++axis) {
      for (double sign : {-1.0, 1.0}) {
        Eigen::Vector3d v = Eigen::Vector3d::Zero(), w = Eigen::Vector3d::Zero();
        if (axis < 3)
          v[axis] = sign * 2.0;
        else
          w[axis - 3] = sign * 8.0 * kDeg;
        JointAngles q = q0;
        JointAngles prev_rate{};
        std::uint32_t prev_limits = 0;
        double biggest_change = 0.0;
        for (int f = 0; f < 90; ++f) {
          const RateResult r = ResolveRate(config.arm, limits, q, h, por, v, w, dt);
          for (int i = 0; i < 6; ++i) {
            ASSERT_LE(std::abs(r.q_deg[i] - q[i]), limits.rate_deg_s[i] * dt + 1e-9)
                << "start " << q0[1] << "/" << q0[4] << " axis " << axis << " frame " << f
                << " joint " << i;
            // (A joint stopping at its limit changes the rates at once, rightly.)
            if (f > 0 && r.at_limit == prev_limits) {
              biggest_change = std::max(biggest_change, std::abs(r.rate_deg_s[i] - prev_rate[i]));
            }
          }
          prev_rate = r.rate_deg_s;
          prev_limits = r.at_limit;
          q = r.q_deg;
        }
        // No jumps: a joint's rate changes by less than 5 deg/s a frame (a
        // sixth of a degree of step), where no joint reached a limit.
        EXPECT_LT(biggest_change, 5.0) << "start " << q0[1] << "/" << q0[4] << " axis " << axis;
      }
    }
  }
  // From the straight arm, a command toward the shoulder (the singular
  // direction) bends the elbow and then moves the point that way.
  JointAngles q = {0, 0, 0, 0, 0, 0};
  const Eigen::Vector3d p0 = Point(q);
  for (int f = 0; f < 150; ++f)
    q = ResolveRate(config.arm, limits, q, h, por, {-1.0, 0, 0}, {0, 0, 0}, dt).q_deg;
  EXPECT_LT(q[2], -5.0) << "the elbow stayed straight";
  EXPECT_LT(Point(q).x() - p0.x(), -1.0) << "the arm did not come in";
}

TEST_F(ArmMotion, AJointAtItsLimitStopsThereAndIsReported) {
  // Wrist yaw 1 deg short of its limit, the end effector turned about the
  // axis that wrist yaw serves: the joint stops on the limit and stays.
  JointAngles q = {15, 60, -75, -30, limits.max_deg[4] - 1.0, 0};
  const double dt = 1.0 / 30;
  const Matrix6d J = ArmJacobian(config.arm, q, h, por);
  const Eigen::Vector3d w = 6.0 * kDeg * J.block<3, 1>(3, 4).normalized();
  bool stopped = false;
  for (int f = 0; f < 60; ++f) {
    const RateResult r = ResolveRate(config.arm, limits, q, h, por, Eigen::Vector3d::Zero(), w, dt);
    EXPECT_LE(r.q_deg[4], limits.max_deg[4] + 1e-12);
    if (r.at_limit & (1u << 4)) stopped = true;
    q = r.q_deg;
  }
  EXPECT_TRUE(stopped);
  EXPECT_DOUBLE_EQ(q[4], limits.max_deg[4]);
  // Every joint at its limit or not: a command back out moves it again.
  const RateResult back =
      ResolveRate(config.arm, limits, q, h, por, Eigen::Vector3d::Zero(), -w, dt);
  EXPECT_LT(back.q_deg[4], limits.max_deg[4]);
  EXPECT_EQ(back.at_limit & (1u << 4), 0u);
}

TEST_F(ArmMotion, JointMovesArriveTogetherAtTheirRates) {
  JointAngles q = {0, 0, 0, 0, 0, 0};
  const JointAngles target = {10, -20, 5, 0, 170, -170};
  int frames = 0;
  while (!StepJointsToward(&q, target, limits.rate_deg_s, 0.1) && frames < 1000) ++frames;
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(WrapDeg(q[i] - target[i]), 0.0, 1e-9);
  EXPECT_EQ(frames,
            141);  // 170 deg at 12 deg/s, 1.2 deg a step: 141 steps short, the 142nd arrives
}

}  // namespace
}  // namespace rms::operator_station
