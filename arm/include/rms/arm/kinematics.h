#pragma once
// Forward kinematics of the arm: the reconstruction of the report's Appendix
// (the sequence of rotations). docs/kinematics.md is the one description;
// this implements it.
//
// A vertical fixed arm of variable length h rises along Z_R from its foot B
// to the shoulder S. Then, each rotation about the current frame's axis:
//   theta1 shoulder yaw   about +Z   F1 = R_z(theta1)
//   theta2 shoulder pitch about -Y   F2 = F1 R_y(-theta2)   upper boom along X_F2, S -> E
//   theta3 elbow pitch    about -Y   F3 = F2 R_y(-theta3)   lower boom along X_F3, E -> W
//   theta4 wrist pitch    about -Y   F4 = F3 R_y(-theta4)
//   theta5 wrist yaw      about +Z   F5 = F4 R_z(theta5)
//   theta6 wrist roll     about +X   F6 = F5 R_x(theta6)
// System Two (X2, Y2, Z2) = F6's axes, origin at point A = W + wrist_to_palm X_F6.
// Positive pitch raises a link (tips its X toward +Z); positive yaw turns X
// toward +Y; with all angles zero the arm lies along +X_R (aft).
#include <Eigen/Geometry>
#include <array>

#include "rms/base/config.h"

namespace rms::arm {

struct SinCos {
  double s = 0.0;
  double c = 1.0;
};
using ArmSinCos = std::array<SinCos, 6>;

ArmSinCos SinCosFromDegrees(const std::array<double, 6>& angles_deg);

struct ArmPose {
  Eigen::Vector3d p_RoB_R;  // foot of the vertical fixed arm
  Eigen::Vector3d p_RoS_R;  // shoulder S
  Eigen::Vector3d p_RoE_R;  // elbow E
  Eigen::Vector3d p_RoW_R;  // wrist W
  Eigen::Isometry3d X_RF1;  // after shoulder yaw, origin S
  Eigen::Isometry3d X_RF2;  // upper boom frame, origin S, X along the boom to E
  Eigen::Isometry3d X_RF3;  // lower boom frame, origin E, X along the boom to W
  Eigen::Isometry3d X_RF4;  // after wrist pitch, origin W
  Eigen::Isometry3d X_RF5;  // after wrist yaw, origin W
  Eigen::Isometry3d X_RF6;  // after wrist roll, origin W
  Eigen::Isometry3d X_RS2;  // System Two, origin A (centre of EFF HEX 1's top face)
};

// Each (s, c) pair is normalised to the unit circle first (the 24-bit words
// are not exactly on it); a pair of norm below 1e-6 is an invariant breach
// (callers validate words first).
ArmPose ComputeArmPose(const ArmGeometry& arm, const ArmSinCos& sc, double shoulder_height_ft);

// The pose with rotation R and translation p.
Eigen::Isometry3d MakeIsometry(const Eigen::Matrix3d& R, const Eigen::Vector3d& p);

// Elementary rotations from a sine and cosine.
Eigen::Matrix3d RotZ(const SinCos& a);
Eigen::Matrix3d RotX(const SinCos& a);
// Pitch: rotation about -Y by the angle (X tips toward +Z for positive angles).
Eigen::Matrix3d RotPitch(const SinCos& a);

}  // namespace rms::arm
