#pragma once
// How the operator station moves the arm (docs/operator.md "Control modes",
// "The autopilot"): one module for the hand controllers' resolved rate and
// single-joint drive and for the autopilot's joint moves and straight lines.
//
//  - JointLimits: each joint's travel (config [arm] joint_min_deg /
//    joint_max_deg) and rate.
//  - ArmJacobian: the velocity of a point of resolution fixed in System Two
//    and System Two's angular velocity, per joint rate.
//  - ResolveRate: a commanded velocity of that point and angular velocity
//    turned into the six joint angles of the next frame, by damped least
//    squares (no jumps near singular poses), rates limited with the direction
//    kept, joints stopped at their limits and reported.
//  - StepJointsToward: a joint move, every joint at most its rate, all
//    arriving together.
//  - SolveWithinLimits: the closed form (rms/arm_ik.h) kept within the limits.
//
// Angles in degrees, lengths in feet, the Reference frame R throughout.
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>

#include "rms/base/config.h"

namespace rms::operator_station {

using JointAngles = std::array<double, 6>;  // shoulder yaw .. wrist roll, deg
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

struct JointLimits {
  JointAngles min_deg{};
  JointAngles max_deg{};
  JointAngles rate_deg_s{};  // at most, each joint
};
// The joints' travel: config [arm] joint_min_deg / joint_max_deg within the
// master arm's input ranges ([inputs.*] min / max); every joint at most
// `rate_deg_s`.
JointLimits LimitsFromConfig(const LabConfig& config, double rate_deg_s);

// The six joint axes' contributions at the point p_S2oQ_S2 (fixed in System
// Two): column i is [v_Q; w] in R for joint i turning at 1 rad/s.
Matrix6d ArmJacobian(const ArmGeometry& arm, const JointAngles& q_deg, double shoulder_height_ft,
                     const Eigen::Vector3d& p_S2oQ_S2);

struct ResolveOptions {
  // Rotation rows are weighted by this length, so the least squares compare
  // feet with feet (an angular error of 1 rad at this radius counts as this
  // many feet).
  double rotation_weight_ft = 10.0;
  // Damping: none while the smallest weighted singular value is above
  // epsilon; rising smoothly to lambda_max as it falls to zero.
  double epsilon_ft = 2.5;
  double lambda_max_ft = 1.5;
  // While a motion is commanded and the elbow is within this of straight,
  // the arm's self-motion (no first-order end-effector motion) bends it
  // toward the elbow-up side at elbow_bend_deg_s, so a straight arm never
  // stays stuck at its singularity.
  double elbow_straight_deg = 15.0;
  double elbow_bend_deg_s = 6.0;
};

struct RateResult {
  JointAngles q_deg{};                   // the next frame's angles
  JointAngles rate_deg_s{};              // what each joint does this frame
  std::uint32_t at_limit = 0;            // bit i: joint i is stopped at a limit this frame
  bool singular = false;                 // damped: near a singular pose, some direction is slowed
  bool rate_limited = false;             // scaled down to keep every joint within its rate
  double sigma_min_ft = 0.0;             // the smallest weighted singular value, ft/rad
  Vector6d achieved = Vector6d::Zero();  // [v_Q ft/s; w rad/s], R, to first order
};

// One frame of resolved rate: the point Q (p_S2oQ_S2) to move at v_R (ft/s)
// and System Two to turn at w_R (rad/s), both in R. A zero command returns
// q unchanged. Joints already beyond a limit may only move back.
RateResult ResolveRate(const ArmGeometry& arm, const JointLimits& limits, const JointAngles& q_deg,
                       double shoulder_height_ft, const Eigen::Vector3d& p_S2oQ_S2,
                       const Eigen::Vector3d& v_R, const Eigen::Vector3d& w_R, double dt_s,
                       const ResolveOptions& options = {});

// Moves *q toward `target` by at most each joint's rate over dt (the joint
// with the longest way sets the pace; all arrive together). Angles wrap.
// True once there.
bool StepJointsToward(JointAngles* q, const JointAngles& target, const JointAngles& rate_deg_s,
                      double dt_s);

// Angles putting System Two at X_RS2 (elbow up), or nothing when out of
// reach or beyond a joint limit.
std::optional<JointAngles> SolveWithinLimits(const ArmGeometry& arm, const JointLimits& limits,
                                             const Eigen::Isometry3d& X_RS2,
                                             double shoulder_height_ft);

// System Two's pose for these angles.
Eigen::Isometry3d ForwardPose(const ArmGeometry& arm, const JointAngles& q_deg,
                              double shoulder_height_ft);

// Pose interpolation: the translation linearly, the rotation by slerp.
Eigen::Isometry3d Interpolate(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double s);
// The angle between two rotations, deg.
double AngleBetweenDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);
// d wrapped into [-180, 180).
double WrapDeg(double d);
// A rotation matrix's rotation vector (axis times angle, rad).
Eigen::Vector3d RotationVector(const Eigen::Matrix3d& R);

}  // namespace rms::operator_station
