#include "rms/operator_station/arm_motion.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "rms/arm/kinematics.h"
#include "rms/mission/arm_ik.h"

namespace rms::operator_station {

namespace {
constexpr double kDeg = M_PI / 180.0;
}  // namespace

double WrapDeg(double d) {
  d = std::fmod(d + 180.0, 360.0);
  if (d < 0) d += 360.0;
  return d - 180.0;
}

JointLimits LimitsFromConfig(const LabConfig& config, double rate_deg_s) {
  JointLimits l;
  for (int i = 0; i < kNumJoints; ++i) {
    l.min_deg[i] = std::max(config.arm.joint_min_deg[i], config.inputs[i].min);
    l.max_deg[i] = std::min(config.arm.joint_max_deg[i], config.inputs[i].max);
    l.rate_deg_s[i] = rate_deg_s;
  }
  return l;
}

Eigen::Isometry3d ForwardPose(const ArmGeometry& arm, const JointAngles& q, double h) {
  return arm::ComputeArmPose(arm, arm::SinCosFromDegrees(q), h).X_RS2;
}

Matrix6d ArmJacobian(const ArmGeometry& arm, const JointAngles& q, double h,
                     const Eigen::Vector3d& p_S2oQ_S2) {
  const arm::ArmPose pose = arm::ComputeArmPose(arm, arm::SinCosFromDegrees(q), h);
  const Eigen::Vector3d Q = pose.X_RS2 * p_S2oQ_S2;
  // docs/kinematics.md: yaw about +Z (R) at S; the pitches about -Y of the
  // frame before, at S, E and W; wrist yaw about +Z of F4 and wrist roll
  // about +X of F5, both at W.
  const std::array<Eigen::Vector3d, 6> axis = {
      Eigen::Vector3d::UnitZ(),    -pose.X_RF1.linear().col(1), -pose.X_RF2.linear().col(1),
      -pose.X_RF3.linear().col(1), pose.X_RF4.linear().col(2),  pose.X_RF5.linear().col(0)};
  const std::array<Eigen::Vector3d, 6> at = {pose.p_RoS_R, pose.p_RoS_R, pose.p_RoE_R,
                                             pose.p_RoW_R, pose.p_RoW_R, pose.p_RoW_R};
  Matrix6d J;
  for (int i = 0; i < kNumJoints; ++i) {
    J.block<3, 1>(0, i) = axis[i].cross(Q - at[i]);
    J.block<3, 1>(3, i) = axis[i];
  }
  return J;
}

namespace {

// The damped pseudo-inverse of J (the columns of `locked` joints zeroed):
// sum over singular values of sigma / (sigma^2 + lambda^2) v u^T.
Matrix6d DampedPseudoInverse(const Matrix6d& J, double lambda) {
  const Eigen::JacobiSVD<Matrix6d> svd(J, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vector6d& s = svd.singularValues();
  Vector6d g = Vector6d::Zero();
  for (int i = 0; i < kNumJoints; ++i) {
    if (s[i] > 1e-12) g[i] = s[i] / (s[i] * s[i] + lambda * lambda);
  }
  return svd.matrixV() * g.asDiagonal() * svd.matrixU().transpose();
}

double SmallestSingularValue(const Matrix6d& J) {
  return Eigen::JacobiSVD<Matrix6d>(J).singularValues()[5];
}

// A nearly straight elbow: the direction the damping slows is the arm's
// reach, and the joint motion that gives no end-effector motion to first
// order (the last right singular vector) bends the elbow. The rate, rad/s a
// joint, that moves along it, elbow-up, so the arm leaves the singularity
// while it flies; faded in smoothly (by how singular, how straight, how
// much of the self-motion is the elbow's) so it never jumps. Zero when the
// elbow is not nearly straight or the arm not singular.
Vector6d ElbowBend(const Matrix6d& Jl, const JointAngles& q, double ratio,
                   const ResolveOptions& o) {
  if (!(std::abs(q[2]) < o.elbow_straight_deg && ratio < 1.0)) return Vector6d::Zero();
  // Among the weak directions (the arm may be singular twice over, the
  // elbow straight and the wrist roll in line with the yaw), the one that
  // is most the elbow's.
  const Eigen::JacobiSVD<Matrix6d> svd(Jl, Eigen::ComputeFullV);
  int best = -1;
  for (int k = 5; k >= 0 && svd.singularValues()[k] < o.epsilon_ft; --k) {
    if (best < 0 || std::abs(svd.matrixV()(2, k)) > std::abs(svd.matrixV()(2, best))) best = k;
  }
  if (best < 0) return Vector6d::Zero();
  Vector6d n = svd.matrixV().col(best);
  const double elbow_part = std::clamp((std::abs(n[2]) - 0.2) / 0.3, 0.0, 1.0);
  if (elbow_part <= 0) return Vector6d::Zero();
  if (n[2] > 0) n = -n;
  const double weak = 1.0 - svd.singularValues()[best] / o.epsilon_ft;
  const double fade = weak * (1.0 - std::abs(q[2]) / o.elbow_straight_deg) * elbow_part;
  return n * (o.elbow_bend_deg_s * kDeg / std::abs(n[2])) * fade;
}

// The joint rates (rad/s) for the weighted twist xw: joints at (or beyond) a
// limit and pushed further out are locked (their bits in *locked) and the
// rest solved again, until none is pushed out.
Vector6d SolveWithLimits(const Matrix6d& Jw, const Vector6d& xw, const JointLimits& limits,
                         const JointAngles& q, double lambda, double ratio, double dt_s,
                         const ResolveOptions& o, std::uint32_t* locked) {
  *locked = 0;
  Vector6d dq = Vector6d::Zero();
  for (int pass = 0; pass < 7; ++pass) {
    Matrix6d Jl = Jw;
    for (int i = 0; i < kNumJoints; ++i) {
      if (*locked & (1u << i)) Jl.col(i).setZero();
    }
    dq = DampedPseudoInverse(Jl, lambda) * xw;
    if (!(*locked & (1u << 2))) dq += ElbowBend(Jl, q, ratio, o);
    for (int i = 0; i < kNumJoints; ++i) {
      if (*locked & (1u << i)) dq[i] = 0.0;
    }
    std::uint32_t pushed = 0;
    for (int i = 0; i < kNumJoints; ++i) {
      const double next = q[i] + dq[i] / kDeg * dt_s;
      if ((dq[i] > 0 && next > limits.max_deg[i] && q[i] >= limits.max_deg[i] - 1e-9) ||
          (dq[i] < 0 && next < limits.min_deg[i] && q[i] <= limits.min_deg[i] + 1e-9)) {
        pushed |= 1u << i;
      }
    }
    if (pushed == 0) break;
    *locked |= pushed;
  }
  return dq;
}

// Every joint within its rate, the direction kept; a joint reaching its
// limit this frame stops on it. Fills r's rates, angles and limits.
void TakeRates(Vector6d dq, const JointLimits& limits, const JointAngles& q, double dt_s,
               RateResult* r) {
  double k = 1.0;
  for (int i = 0; i < kNumJoints; ++i) {
    const double rate = std::abs(dq[i]) / kDeg;
    if (rate > limits.rate_deg_s[i]) k = std::min(k, limits.rate_deg_s[i] / rate);
  }
  r->rate_limited = k < 1.0;
  dq *= k;
  for (int i = 0; i < kNumJoints; ++i) {
    double next = q[i] + dq[i] / kDeg * dt_s;
    if (next > limits.max_deg[i] && dq[i] > 0) {
      next = std::max(q[i], limits.max_deg[i]);
      r->at_limit |= 1u << i;
    } else if (next < limits.min_deg[i] && dq[i] < 0) {
      next = std::min(q[i], limits.min_deg[i]);
      r->at_limit |= 1u << i;
    }
    r->rate_deg_s[i] = (next - q[i]) / dt_s;
    r->q_deg[i] = next;
  }
}

}  // namespace

RateResult ResolveRate(const ArmGeometry& arm, const JointLimits& limits, const JointAngles& q,
                       double h, const Eigen::Vector3d& p_S2oQ_S2, const Eigen::Vector3d& v_R,
                       const Eigen::Vector3d& w_R, double dt_s, const ResolveOptions& o) {
  RateResult r;
  r.q_deg = q;
  const Matrix6d J = ArmJacobian(arm, q, h, p_S2oQ_S2);
  Vector6d weight;
  weight << 1, 1, 1, o.rotation_weight_ft, o.rotation_weight_ft, o.rotation_weight_ft;
  const Matrix6d Jw = weight.asDiagonal() * J;
  r.sigma_min_ft = SmallestSingularValue(Jw);
  const double ratio = r.sigma_min_ft / o.epsilon_ft;
  const double lambda = ratio >= 1.0 ? 0.0 : o.lambda_max_ft * std::sqrt(1.0 - ratio * ratio);
  r.singular = lambda > 0.0;
  if (v_R.squaredNorm() == 0.0 && w_R.squaredNorm() == 0.0) return r;
  Vector6d x;
  x << v_R, w_R;
  std::uint32_t locked = 0;
  const Vector6d dq =
      SolveWithLimits(Jw, weight.asDiagonal() * x, limits, q, lambda, ratio, dt_s, o, &locked);
  r.at_limit = locked;
  TakeRates(dq, limits, q, dt_s, &r);
  Vector6d done;
  for (int i = 0; i < kNumJoints; ++i) done[i] = r.rate_deg_s[i] * kDeg;
  r.achieved = J * done;
  return r;
}

bool StepJointsToward(JointAngles* q, const JointAngles& target, const JointAngles& rate_deg_s,
                      double dt_s) {
  double k = 1.0;
  JointAngles d{};
  for (int i = 0; i < kNumJoints; ++i) {
    d[i] = WrapDeg(target[i] - (*q)[i]);
    const double lim = rate_deg_s[i] * dt_s;
    if (std::abs(d[i]) > lim) k = std::min(k, lim / std::abs(d[i]));
  }
  for (int i = 0; i < kNumJoints; ++i) (*q)[i] = WrapDeg((*q)[i] + k * d[i]);
  return k == 1.0;
}

std::optional<JointAngles> SolveWithinLimits(const ArmGeometry& arm, const JointLimits& limits,
                                             const Eigen::Isometry3d& X_RS2, double h) {
  const auto s = mission::SolveArmIk(arm, X_RS2, h, mission::Elbow::kUp);
  if (!s) return std::nullopt;
  for (int i = 0; i < kNumJoints; ++i) {
    if (s->angles_deg[i] < limits.min_deg[i] || s->angles_deg[i] > limits.max_deg[i])
      return std::nullopt;
  }
  return s->angles_deg;
}

Eigen::Isometry3d Interpolate(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double s) {
  const Eigen::Quaterniond qa(a.linear()), qb(b.linear());
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = qa.slerp(s, qb).toRotationMatrix();
  X.translation() = (1 - s) * a.translation() + s * b.translation();
  return X;
}

double AngleBetweenDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() / kDeg;
}

Eigen::Vector3d RotationVector(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

}  // namespace rms::operator_station
