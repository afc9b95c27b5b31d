#pragma once
// The DCP unit tests' common ground: the default configuration, the planned
// mission's geometry, and operator inputs that put System Two at a pose.
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "rms/arm/kinematics.h"
#include "rms/base/config.h"
#include "rms/mission/arm_ik.h"
#include "rms/mission/mission_plan.h"
#include "rms/wire/input_block.h"

namespace rms::dcp_model::testing {

class DcpFixture : public ::testing::Test {
 protected:
  LabConfig config = LoadConfig(DefaultConfigPath());
  mission::MissionGeometry geo = mission::PlanGeometry(config);

  // The payload in the bay (Mode 1).
  Eigen::Isometry3d X_RP_bay() const {
    return arm::MakeIsometry(config.payload.R_RP, config.payload.p_RoPo_R_ft);
  }
  // Inputs that put System Two at X_RS2 (inverse kinematics) with the finger
  // lever, at the mission's shoulder height unless one is given.
  wire::OperatorInputs Inputs(const Eigen::Isometry3d& X_RS2, double finger,
                              double height = -1) const {
    if (height < 0) height = geo.shoulder_height_ft;
    wire::OperatorInputs in = wire::InitialInputs(config.inputs);
    const auto s = mission::SolveArmIk(config.arm, X_RS2, height);
    EXPECT_TRUE(s.has_value());
    for (int i = 0; i < 6; ++i) in.value[i] = s->angles_deg[i];
    in.value[kShoulderHeight] = height;
    in.value[kFinger] = finger;
    return in;
  }
  static Eigen::Isometry3d Shifted(Eigen::Isometry3d X, const Eigen::Vector3d& d) {
    X.translation() += d;
    return X;
  }
};

}  // namespace rms::dcp_model::testing
