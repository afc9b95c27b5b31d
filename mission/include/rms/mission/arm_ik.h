#pragma once
// Inverse kinematics of the arm of docs/kinematics.md, in closed form: the
// three wrist joints meet at the wrist W, so W = A - L3 X2 fixes shoulder yaw,
// shoulder pitch and elbow pitch (a two-link arm in the vertical plane through
// the shoulder), and the wrist's rotation fixes the rest:
//   R_F3^T R_RS2 = R_y(-theta4) R_z(theta5) R_x(theta6).
#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <string>

#include "rms/base/config.h"

namespace rms::mission {

struct IkSolution {
  std::array<double, 6> angles_deg{};  // shoulder yaw .. wrist roll, each in (-180, 180]
};

enum class Elbow { kUp, kDown };

// Angles that put System Two at X_RS2 (its axes must be orthonormal, right
// handed) for the given shoulder height; nothing when the wrist point is out
// of the booms' reach. Wrist yaw is in [-90, 90] deg; at +-90 (gimbal lock)
// wrist pitch is taken as 0.
std::optional<IkSolution> SolveArmIk(const ArmGeometry& arm, const Eigen::Isometry3d& X_RS2,
                                     double shoulder_height_ft, Elbow elbow = Elbow::kUp);

// System Two's pose from point A, the approach axis X2 and the finger axis
// Y2 (made orthogonal to X2); Z2 = X2 x Y2.
Eigen::Isometry3d EndEffectorPose(const Eigen::Vector3d& p_RoA_R, const Eigen::Vector3d& x2,
                                  const Eigen::Vector3d& y2);

}  // namespace rms::mission
