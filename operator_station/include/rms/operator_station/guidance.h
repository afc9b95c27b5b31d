#pragma once
// What the operator needs to see to fly by hand (docs/operator.md
// "Guidance"): the command frames of manual augmented control, the point of
// resolution the hand controllers move and rotate about, and the offset from
// it to its target -- the grasp on the bar receptacle in Mode 1, the CAE's
// docking port in Modes 2 and 3 -- in the command frame's axes, so that the
// controller that reduces an offset is the one the offset names.
#include <Eigen/Geometry>
#include <array>
#include <limits>

#include "rms/base/config.h"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/operator_station/control_modes.h"

namespace rms::operator_station {

// What of the configuration guidance needs, computed once.
struct GuidanceGeometry {
  Eigen::Matrix3d R_S2H = Eigen::Matrix3d::Identity();  // end-effector command axes in System Two
  Eigen::Vector3d p_S2oG_S2 =
      Eigen::Vector3d::Zero();  // the grasp point: the bar's centre at the grasp
  Eigen::Isometry3d X_RS2_grasp =
      Eigen::Isometry3d::Identity();                  // System Two at the grasp (the mission's: the
                                                      // wrist camera on the grapple target's side)
  Eigen::Vector3d p_PoT_P = Eigen::Vector3d::Zero();  // the probe's tip centre, payload frame
  Eigen::Vector3d p_RoPort_R = Eigen::Vector3d::Zero();  // the docking port's centre
  Eigen::Vector3d y_port_R = Eigen::Vector3d::UnitZ();   // the port's axis (into the CAE)
  std::array<Eigen::Vector3d, 8> bar_P;                  // the BAR's corners, payload frame
  double fixed_finger_face_Y2_ft = 0.0;  // face b of EFF HEX 2 (the fixed finger's inside), Y2
  // The payload as drawn (docs/scene.md): a cylinder along y_P and the
  // probe, a frustum from its root (the body's +y end) to its tip; ft.
  double body_radius_ft = 0.0, body_half_length_ft = 0.0;
  double probe_root_radius_ft = 0.0, probe_tip_radius_ft = 0.0;
};
GuidanceGeometry MakeGuidanceGeometry(const LabConfig& config);

// A pose as the telemetry carries it: a position and a row-major rotation.
Eigen::Isometry3d TelemetryPose(const double p[3], const double R_rowmajor[9]);

// The poses guidance reads from one telemetry message.
struct ArmState {
  int mode = 1;
  double bay_clearance_ft = 0.0;  // the payload's lowest vertex above the bay's top
  Eigen::Isometry3d X_RS2 = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d X_RP = Eigen::Isometry3d::Identity();
};
ArmState ArmStateFrom(const dcp_telemetry_t& t);

// The command frame's axes (columns x, y, z) in R. kPayload before the
// payload is held falls back to the end effector's.
Eigen::Matrix3d CommandAxes(const GuidanceGeometry& g, CommandFrame f, const ArmState& s);

// The point the hand controllers move and rotate about, in System Two: the
// grasp point in Mode 1, the probe's tip once the payload is held.
Eigen::Vector3d PointOfResolution(const GuidanceGeometry& g, const ArmState& s);

enum class GuidanceTarget : int { kGrasp = 1, kPort = 2 };

struct Guidance {
  GuidanceTarget target = GuidanceTarget::kGrasp;
  CommandFrame frame = CommandFrame::kEndEffector;
  Eigen::Vector3d offset_ft =
      Eigen::Vector3d::Zero();  // target - point of resolution, command axes
  Eigen::Vector3d rotation_deg =
      Eigen::Vector3d::Zero();  // about x (roll), y (pitch), z (yaw) to align
  double distance_ft = 0.0;     // |offset|
  double angle_deg = 0.0;       // |rotation|
  // Mode 2: the way out of the bay first -- straight up (+Z_R) until the
  // payload is kLeaveBayMarginFt clear -- in the command frame's axes.
  bool leave_bay = false;
  Eigen::Vector3d leave_bay_ft = Eigen::Vector3d::Zero();
  // Mode 1: the gap at which the closing finger would stop on the BAR (face
  // b to the BAR's far side along Y2): condition 4 needs it below D3Y. -1
  // when the BAR is not between the fingers' planes.
  double close_gap_ft = -1.0;
  // The axis to fly next, one at a time (0..5: x, y, z, roll, pitch, yaw;
  // -1: at the target): the largest turn first, then across the approach
  // line, then along it (docs/operator.md "Guidance").
  int next_axis = -1;
  // Modes 2 and 3: the least height of the payload above the orbiter's
  // sill line over the rest of the turn (ComputeGuidance's turn_F_deg; the
  // whole turn shown when none is given); NaN in Mode 1.
  double turn_clearance_ft = std::numeric_limits<double>::quiet_NaN();
  bool clearance_warning = false;  // Mode 3: it is under kClearanceMarginFt
};
// In Mode 1: to the grasp. In Modes 2 and 3: from the probe's tip to the
// port's centre, and the turn that brings the probe's axis onto the port's
// (roll about the port's axis is free: 0); in Mode 2 also the way up out of
// the bay, which comes first.
inline constexpr double kLeaveBayMarginFt = 2.0;
// Mode 3: a warning when the payload is, or a turn would take it, nearer
// the sill line than this (docs/operator.md "Clearance in Mode 3").
inline constexpr double kClearanceMarginFt = 2.0;
// turn_F_deg: the turn in flight (command axes, deg; about the point of
// resolution) for the clearance; null: the guidance's own turn.
Guidance ComputeGuidance(const GuidanceGeometry& g, const ArmState& s, CommandFrame f,
                         const Eigen::Vector3d* turn_F_deg = nullptr);

// The payload's lowest point above the sill line (the bay's top face c,
// z_R = 0), the payload at X_RP.
double PayloadLowestZ(const GuidanceGeometry& g, const Eigen::Isometry3d& X_RP);
// The least of it over a turn phi_R (a rotation vector, rad, in R) about
// the point p_R, sampled every degree.
double TurnClearance(const GuidanceGeometry& g, const Eigen::Isometry3d& X_RP,
                     const Eigen::Vector3d& p_R, const Eigen::Vector3d& phi_R);

// Mode 1: closing the finger now acquires -- it would stop on the BAR
// below D3Y and conditions 1, 2, 3, 5 and 6 hold (the telemetry's).
bool WouldAcquire(const dcp_telemetry_t& t, const Guidance& g, double d3y_ft);

}  // namespace rms::operator_station
