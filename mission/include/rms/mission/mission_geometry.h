#pragma once
// The standard mission's geometry, shared by the mission planner
// (tools/rms_mission, scripts/timelines/mission.tl) and the autopilot
// (operator_station): where System Two grasps the payload's bar receptacle,
// where the payload docks at the CAE's port, and whether a pose puts the arm
// or the payload into the orbiter or the CAE. docs/operator.md "The
// autopilot" describes the geometry.
#include <Eigen/Geometry>
#include <array>
#include <string>

#include "rms/base/config.h"
#include "rms/scene_model/scene_model.h"

namespace rms::mission {

struct MissionGeometry {
  Eigen::Isometry3d X_RS2_grasp;  // System Two at the grasp, the payload in the bay
  Eigen::Isometry3d X_S2P;        // the payload in System Two once grasped
  Eigen::Isometry3d X_RP_dock;    // the payload docked
  double shoulder_height_ft = 0;
};

// Where the planned grasp sits inside the acquisition tolerances (report
// IV.A.3, docs/operator.md "The autopilot"): the BAR this share of D3Y's
// margin over the bar's width inside the fixed finger, and the palm this
// share of TPOB above the BAR's top.
inline constexpr double kGraspD3yMarginShare = 0.4;
inline constexpr double kGraspTpobShare = 0.5;
// The palm's planned height above the BAR's top at the grasp, ft.
double GraspPalmAboveBarFt(const LabConfig& config);

// Grasp: approach down the payload's z axis, the fingers closing along its
// long axis, the bar just inside the fixed finger (40% of D3Y's margin over
// the bar's width) and the palm half TPOB above the bar. Docked: the probe
// along the port's axis, its tip 0.05 ft short of the port's centre, the
// payload's z axis (the grasp side) toward the shoulder at this height.
MissionGeometry PlanGeometry(const LabConfig& config);
MissionGeometry PlanGeometry(const LabConfig& config, double shoulder_height_ft);

// Where the payload is: held by the end effector (it moves with the arm), or
// in the bay (an obstacle for the arm, Mode 1).
enum class PayloadState { kHeld, kInBay };

// What a pose puts into something solid (the scene's clusters, docs/scene.md):
// the first moving cluster (the arm's; the payload's when held) that no plane
// separates from an obstacle (the orbiter's and the CAE's clusters; the
// payload's when in the bay) -- "upper_boom runs into cabin" -- or "" when
// all are clear. With margin_ft > 0, each must be apart by at least that
// along some separating axis.
std::string Interpenetration(const LabConfig& config, const scene_model::SceneModel& model,
                             const std::array<double, 6>& angles_deg, double shoulder_height_ft,
                             double finger_gap_ft, const Eigen::Isometry3d& X_RP,
                             PayloadState payload = PayloadState::kHeld, double margin_ft = 0.0);

}  // namespace rms::mission
