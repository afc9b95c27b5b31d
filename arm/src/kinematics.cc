#include "rms/arm/kinematics.h"

#include <cmath>

#include "rms/base/check.h"

namespace rms::arm {

ArmSinCos SinCosFromDegrees(const std::array<double, 6>& angles_deg) {
  ArmSinCos sc;
  for (int i = 0; i < kNumJoints; ++i) {
    const double a = angles_deg[i] * (M_PI / 180.0);
    sc[i] = {std::sin(a), std::cos(a)};
  }
  return sc;
}

namespace {
SinCos Normalized(const SinCos& a) {
  // The pair is near the unit circle: no overflow, so the plain root
  // (several times cheaper than hypot).
  const double n = std::sqrt(a.s * a.s + a.c * a.c);
  RMS_CHECK_MSG(n > 1e-6, "arm sine/cosine pair is not on the unit circle");
  return {a.s / n, a.c / n};
}
}  // namespace

Eigen::Isometry3d MakeIsometry(const Eigen::Matrix3d& R, const Eigen::Vector3d& p) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = R;
  X.translation() = p;
  return X;
}

Eigen::Matrix3d RotZ(const SinCos& a) {
  Eigen::Matrix3d r;
  r << a.c, -a.s, 0, a.s, a.c, 0, 0, 0, 1;
  return r;
}

Eigen::Matrix3d RotX(const SinCos& a) {
  Eigen::Matrix3d r;
  r << 1, 0, 0, 0, a.c, -a.s, 0, a.s, a.c;
  return r;
}

Eigen::Matrix3d RotPitch(const SinCos& a) {
  // R_y(-theta): X -> (c, 0, s).
  Eigen::Matrix3d r;
  r << a.c, 0, -a.s, 0, 1, 0, a.s, 0, a.c;
  return r;
}

ArmPose ComputeArmPose(const ArmGeometry& arm, const ArmSinCos& raw, double shoulder_height_ft) {
  ArmSinCos sc;
  for (int i = 0; i < kNumJoints; ++i) sc[i] = Normalized(raw[i]);
  ArmPose p;
  p.p_RoB_R = arm.p_RoB_R_ft;
  p.p_RoS_R = arm.p_RoB_R_ft + Eigen::Vector3d(0, 0, shoulder_height_ft);

  const Eigen::Matrix3d R1 = RotZ(sc[0]);
  const Eigen::Matrix3d R2 = R1 * RotPitch(sc[1]);
  const Eigen::Matrix3d R3 = R2 * RotPitch(sc[2]);
  const Eigen::Matrix3d R4 = R3 * RotPitch(sc[3]);
  const Eigen::Matrix3d R5 = R4 * RotZ(sc[4]);
  const Eigen::Matrix3d R6 = R5 * RotX(sc[5]);

  p.p_RoE_R = p.p_RoS_R + arm.upper_boom_ft * R2.col(0);
  p.p_RoW_R = p.p_RoE_R + arm.lower_boom_ft * R3.col(0);
  const Eigen::Vector3d p_RoA_R = p.p_RoW_R + arm.wrist_to_palm_ft * R6.col(0);

  p.X_RF1 = MakeIsometry(R1, p.p_RoS_R);
  p.X_RF2 = MakeIsometry(R2, p.p_RoS_R);
  p.X_RF3 = MakeIsometry(R3, p.p_RoE_R);
  p.X_RF4 = MakeIsometry(R4, p.p_RoW_R);
  p.X_RF5 = MakeIsometry(R5, p.p_RoW_R);
  p.X_RF6 = MakeIsometry(R6, p.p_RoW_R);
  p.X_RS2 = MakeIsometry(R6, p_RoA_R);
  return p;
}

}  // namespace rms::arm
