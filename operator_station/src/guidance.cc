#include "rms/operator_station/guidance.h"

#include <cmath>

#include "rms/arm/kinematics.h"
#include "rms/mission/mission_geometry.h"
#include "rms/operator_station/arm_motion.h"
#include "rms/wire/dcp_mode.h"

namespace rms::operator_station {

namespace {

// The wrist camera's image axes (right, down) as the end effector's command
// axes, with x exactly X2; (X2, -Y2, -Z2) when no camera rides the wrist.
Eigen::Matrix3d HandAxesInSystemTwo(const LabConfig& c) {
  Eigen::Vector3d right = -Eigen::Vector3d::UnitY();
  for (const CameraStationConfig& cam : c.cameras) {
    if (cam.mount != CameraMount::kWrist) continue;
    // docs/scene.md: image right = line of sight x the mount's z axis.
    const Eigen::Vector3d look = (cam.p_MoAim_M_ft - cam.p_MoCam_M_ft).normalized();
    right = look.cross(Eigen::Vector3d::UnitZ());
    break;
  }
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  right -= right.dot(x) * x;
  if (right.norm() < 1e-6) right = -Eigen::Vector3d::UnitY();
  Eigen::Matrix3d R;
  R.col(0) = x;
  R.col(1) = right.normalized();
  R.col(2) = x.cross(R.col(1));
  return R;
}

}  // namespace

Eigen::Isometry3d TelemetryPose(const double p[3], const double R_rowmajor[9]) {
  Eigen::Matrix3d R;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) R(i, j) = R_rowmajor[3 * i + j];
  }
  return arm::MakeIsometry(R, Eigen::Vector3d(p[0], p[1], p[2]));
}

GuidanceGeometry MakeGuidanceGeometry(const LabConfig& c) {
  GuidanceGeometry g;
  g.R_S2H = HandAxesInSystemTwo(c);
  const mission::MissionGeometry m = mission::PlanGeometry(c);
  g.p_S2oG_S2 = m.X_S2P * c.payload.p_PoBar_P_ft;
  // (The bar is symmetric, but only this grasp puts the wrist camera on the
  // grapple target's side: docs/scene.md "Targets".)
  g.X_RS2_grasp = m.X_RS2_grasp;
  g.p_PoT_P = Eigen::Vector3d(0, 0.5 * c.payload.length_ft + c.payload.probe_length_ft, 0);
  g.p_RoPort_R = c.cae.p_RoCo_R_ft;
  g.y_port_R = c.cae.R_RC.col(1);
  const Eigen::Vector3d bc = c.payload.p_PoBar_P_ft, half = 0.5 * c.payload.bar_size_P_ft;
  for (int k = 0; k < 8; ++k) {
    g.bar_P[k] =
        bc + Eigen::Vector3d((k & 1) ? half.x() : -half.x(), (k & 2) ? half.y() : -half.y(),
                             (k & 4) ? half.z() : -half.z());
  }
  g.fixed_finger_face_Y2_ft =
      c.end_effector.palm_half_width_ft - c.end_effector.finger_thickness_ft;
  g.body_radius_ft = 0.5 * c.payload.diameter_ft;
  g.body_half_length_ft = 0.5 * c.payload.length_ft;
  g.probe_root_radius_ft = 0.5 * c.payload.probe_diameter_ft;
  g.probe_tip_radius_ft = 0.6 * g.probe_root_radius_ft;  // docs/scene.md: the drawn probe
  return g;
}

ArmState ArmStateFrom(const dcp_telemetry_t& t) {
  ArmState s;
  s.mode = t.mode;
  s.bay_clearance_ft = t.bay_clearance_ft;
  s.X_RS2 = TelemetryPose(t.p_RoA_R_ft, t.R_RS2);
  s.X_RP = TelemetryPose(t.p_RoPo_R_ft, t.R_RP);
  return s;
}

Eigen::Matrix3d CommandAxes(const GuidanceGeometry& g, CommandFrame f, const ArmState& s) {
  switch (f) {
    case CommandFrame::kOrbiter: {
      Eigen::Matrix3d R;
      R.col(0) = -Eigen::Vector3d::UnitX();
      R.col(1) = Eigen::Vector3d::UnitY();
      R.col(2) = -Eigen::Vector3d::UnitZ();
      return R;
    }
    case CommandFrame::kPayload:
      if (s.mode >= wire::DcpMode::kExtraction) return s.X_RP.linear();
      [[fallthrough]];
    case CommandFrame::kEndEffector:
      break;
  }
  return s.X_RS2.linear() * g.R_S2H;
}

Eigen::Vector3d PointOfResolution(const GuidanceGeometry& g, const ArmState& s) {
  if (s.mode == wire::DcpMode::kAcquisition) return g.p_S2oG_S2;
  return s.X_RS2.inverse() * (s.X_RP * g.p_PoT_P);
}

namespace {

// The lowest point of a circle (centre c, radius r, normal a; unit) in z.
double CircleLowestZ(const Eigen::Vector3d& c, double r, const Eigen::Vector3d& a) {
  return c.z() - r * std::sqrt(std::max(0.0, 1.0 - a.z() * a.z()));
}

// The axis to fly next: the largest turn beyond kTurnTolDeg; then, of the
// translations beyond kMoveTolFt, the two across the approach line (the
// axis most along approach_F goes last) by size, then the one along it.
int NextAxis(const Guidance& out, const Eigen::Vector3d& approach_F) {
  constexpr double kTurnTolDeg = 0.5, kMoveTolFt = 0.05;
  int best = -1;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(out.rotation_deg[i]) > kTurnTolDeg &&
        (best < 0 || std::abs(out.rotation_deg[i]) > std::abs(out.rotation_deg[best - 3])))
      best = 3 + i;
  }
  if (best >= 0) return best;
  int along = 0;
  approach_F.cwiseAbs().maxCoeff(&along);
  for (int i = 0; i < 3; ++i) {
    if (i == along || std::abs(out.offset_ft[i]) <= kMoveTolFt) continue;
    if (best < 0 || std::abs(out.offset_ft[i]) > std::abs(out.offset_ft[best])) best = i;
  }
  if (best >= 0) return best;
  return std::abs(out.offset_ft[along]) > kMoveTolFt ? along : -1;
}

}  // namespace

double PayloadLowestZ(const GuidanceGeometry& g, const Eigen::Isometry3d& X_RP) {
  const Eigen::Vector3d y = X_RP.linear().col(1);
  const Eigen::Vector3d o = X_RP.translation();
  const Eigen::Vector3d root = o + g.body_half_length_ft * y, tip = X_RP * g.p_PoT_P;
  return std::min({CircleLowestZ(o - g.body_half_length_ft * y, g.body_radius_ft, y),
                   CircleLowestZ(root, g.body_radius_ft, y),
                   CircleLowestZ(tip, g.probe_tip_radius_ft, y)});
}

double TurnClearance(const GuidanceGeometry& g, const Eigen::Isometry3d& X_RP,
                     const Eigen::Vector3d& p_R, const Eigen::Vector3d& phi_R) {
  const double angle = phi_R.norm();
  const int n = std::max(1, static_cast<int>(std::ceil(angle * 180.0 / M_PI)));
  double least = PayloadLowestZ(g, X_RP);
  for (int k = 1; k <= n && angle > 0; ++k) {
    const Eigen::AngleAxisd turn(angle * k / n, phi_R / angle);
    Eigen::Isometry3d X = X_RP;
    X.linear() = turn.toRotationMatrix() * X_RP.linear();
    X.translation() = p_R + turn * (X_RP.translation() - p_R);
    least = std::min(least, PayloadLowestZ(g, X));
  }
  return least;
}

bool WouldAcquire(const dcp_telemetry_t& t, const Guidance& g, double d3y_ft) {
  if (t.mode != wire::DcpMode::kAcquisition || g.close_gap_ft <= 0 || g.close_gap_ft >= d3y_ft)
    return false;
  for (int i : {0, 1, 2, 4, 5})  // all but 4, the finger's own (docs/collision.md)
    if (!t.acquisition_conditions[i]) return false;
  return true;
}

Guidance ComputeGuidance(const GuidanceGeometry& g, const ArmState& s, CommandFrame f,
                         const Eigen::Vector3d* turn_F_deg) {
  Guidance out;
  out.frame = f;
  const Eigen::Matrix3d R_RF = CommandAxes(g, f, s);
  Eigen::Vector3d d_R, phi_R;
  if (s.mode == wire::DcpMode::kAcquisition) {
    out.target = GuidanceTarget::kGrasp;
    const Eigen::Vector3d Q = s.X_RS2 * g.p_S2oG_S2;
    phi_R = RotationVector(g.X_RS2_grasp.linear() * s.X_RS2.linear().transpose());
    d_R = g.X_RS2_grasp * g.p_S2oG_S2 - Q;
    // Where the finger would stop: on the BAR's corner nearest it along Y2.
    const Eigen::Vector3d y2 = s.X_RS2.linear().col(1);
    double y_min = 1e30;
    for (const Eigen::Vector3d& v : g.bar_P)
      y_min = std::min(y_min, y2.dot(s.X_RP * v - s.X_RS2.translation()));
    const double gap = g.fixed_finger_face_Y2_ft - y_min;
    out.close_gap_ft = gap > 0 ? gap : -1.0;
  } else {
    out.target = GuidanceTarget::kPort;
    const Eigen::Vector3d tip = s.X_RP * g.p_PoT_P;
    d_R = g.p_RoPort_R - tip;
    const Eigen::Vector3d y = s.X_RP.linear().col(1);
    const Eigen::Vector3d axis = y.cross(g.y_port_R);
    const double angle = std::atan2(axis.norm(), y.dot(g.y_port_R));
    if (axis.norm() > 1e-12)
      phi_R = angle * axis.normalized();
    else if (angle > 1.0)
      phi_R = M_PI * s.X_RP.linear().col(0);  // exactly reversed: half a turn about x_P
    else
      phi_R.setZero();
  }
  if (s.mode == wire::DcpMode::kExtraction) {
    out.leave_bay = true;
    const double up = std::max(0.0, kLeaveBayMarginFt - s.bay_clearance_ft);
    out.leave_bay_ft = R_RF.transpose() * Eigen::Vector3d(0, 0, up);
  }
  out.offset_ft = R_RF.transpose() * d_R;
  out.rotation_deg = R_RF.transpose() * phi_R * (180.0 / M_PI);
  out.distance_ft = d_R.norm();
  out.angle_deg = phi_R.norm() * 180.0 / M_PI;
  if (s.mode >= wire::DcpMode::kExtraction) {
    const Eigen::Vector3d turn_R =
        turn_F_deg ? Eigen::Vector3d(R_RF * *turn_F_deg * (M_PI / 180.0)) : phi_R;
    out.turn_clearance_ft = TurnClearance(g, s.X_RP, s.X_RP * g.p_PoT_P, turn_R);
    out.clearance_warning =
        s.mode == wire::DcpMode::kManoeuvring && out.turn_clearance_ft < kClearanceMarginFt;
  }
  const Eigen::Vector3d approach_R = s.mode == wire::DcpMode::kAcquisition
                                         ? Eigen::Vector3d(g.X_RS2_grasp.linear().col(0))
                                         : g.y_port_R;
  out.next_axis = NextAxis(out, R_RF.transpose() * approach_R);
  if (out.leave_bay && out.leave_bay_ft.norm() > 1e-9) {
    int up = 0;
    out.leave_bay_ft.cwiseAbs().maxCoeff(&up);
    out.next_axis = up;
  }
  return out;
}

}  // namespace rms::operator_station
