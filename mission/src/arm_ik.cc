#include "rms/mission/arm_ik.h"

#include <cmath>

#include "rms/arm/kinematics.h"

namespace rms::mission {

namespace {
double Deg(double rad) {
  double d = rad * 180.0 / M_PI;
  if (d <= -180.0) d += 360.0;
  if (d > 180.0) d -= 360.0;
  return d;
}
}  // namespace

Eigen::Isometry3d EndEffectorPose(const Eigen::Vector3d& p, const Eigen::Vector3d& x2_in,
                                  const Eigen::Vector3d& y2_in) {
  const Eigen::Vector3d x2 = x2_in.normalized();
  const Eigen::Vector3d y2 = (y2_in - y2_in.dot(x2) * x2).normalized();
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear().col(0) = x2;
  X.linear().col(1) = y2;
  X.linear().col(2) = x2.cross(y2);
  X.translation() = p;
  return X;
}

std::optional<IkSolution> SolveArmIk(const ArmGeometry& arm, const Eigen::Isometry3d& X_RS2,
                                     double h, Elbow elbow) {
  const Eigen::Matrix3d R = X_RS2.linear();
  const Eigen::Vector3d W = X_RS2.translation() - arm.wrist_to_palm_ft * R.col(0);
  const Eigen::Vector3d S = arm.p_RoB_R_ft + Eigen::Vector3d(0, 0, h);
  const Eigen::Vector3d d = W - S;
  const double rho = std::hypot(d.x(), d.y());
  const double r2 = rho * rho + d.z() * d.z(), r = std::sqrt(r2);
  const double L1 = arm.upper_boom_ft, L2 = arm.lower_boom_ft;
  if (r > L1 + L2 || r < std::abs(L1 - L2) || r == 0) return std::nullopt;
  IkSolution s;
  const double t1 = rho > 1e-12 ? std::atan2(d.y(), d.x()) : 0.0;
  const double elev = std::atan2(d.z(), rho);
  const double alpha = std::acos(std::clamp((L1 * L1 + r2 - L2 * L2) / (2 * L1 * r), -1.0, 1.0));
  const double beta = std::acos(std::clamp((L1 * L1 + L2 * L2 - r2) / (2 * L1 * L2), -1.0, 1.0));
  const double t2 = elbow == Elbow::kUp ? elev + alpha : elev - alpha;
  const double t3 = elbow == Elbow::kUp ? -(M_PI - beta) : (M_PI - beta);
  // The wrist's rotation relative to the lower boom's frame F3.
  const Eigen::Matrix3d R3 = arm::RotZ({std::sin(t1), std::cos(t1)}) *
                             arm::RotPitch({std::sin(t2 + t3), std::cos(t2 + t3)});
  const Eigen::Matrix3d M = R3.transpose() * R;
  // M = R_y(-t4) R_z(t5) R_x(t6): first column (cos t4 cos t5, sin t5, sin t4 cos t5).
  const double t5 = std::asin(std::clamp(M(1, 0), -1.0, 1.0));
  const double t4 = std::abs(std::cos(t5)) > 1e-9 ? std::atan2(M(2, 0), M(0, 0)) : 0.0;
  const Eigen::Matrix3d N =
      (arm::RotPitch({std::sin(t4), std::cos(t4)}) * arm::RotZ({std::sin(t5), std::cos(t5)}))
          .transpose() *
      M;
  const double t6 = std::atan2(N(2, 1), N(1, 1));
  s.angles_deg = {Deg(t1), Deg(t2), Deg(t3), Deg(t4), Deg(t5), Deg(t6)};
  return s;
}

}  // namespace rms::mission
