#include "rms/mission/mission_plan.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "rms/arm/kinematics.h"
#include "rms/base/camera_view.h"
#include "rms/base/check.h"
#include "rms/mission/arm_ik.h"
#include "rms/mission/mission_geometry.h"
#include "rms/scene_model/scene_model.h"
#include "rms/scene_model/separating_plane.h"

namespace rms::mission {

namespace {

// The pose a fraction u of the way from X_RA to X_RB: the rotation by slerp,
// the position in a straight line.
Eigen::Isometry3d Between(const Eigen::Isometry3d& X_RA, const Eigen::Isometry3d& X_RB, double u) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::Quaterniond(X_RA.linear())
                   .slerp(u, Eigen::Quaterniond(X_RB.linear()))
                   .toRotationMatrix();
  X.translation() = (1 - u) * X_RA.translation() + u * X_RB.translation();
  return X;
}

}  // namespace

std::vector<Keyframe> PlanMission(const LabConfig& c) {
  const MissionGeometry g = PlanGeometry(c);
  const double h = g.shoulder_height_ft;
  std::vector<Keyframe> keys;
  const scene_model::SceneModel model = scene_model::BuildSceneModel(c);
  const Eigen::Isometry3d X_RP_bay = arm::MakeIsometry(c.payload.R_RP, c.payload.p_RoPo_R_ft);
  // Each view's camera station, by its mount (0: the configuration has none;
  // the keyframe then keeps the station it has).
  const CameraStations stations = FindCameraStations(c.cameras);
  const auto station = [&](CameraView v) { return stations[static_cast<int>(v)]; };
  using V = CameraView;
  // Elbow up (one branch all along, so joint interpolation between close
  // waypoints stays smooth); a waypoint that puts the arm or the payload
  // into the orbiter or the CAE is refused.
  auto solve = [&](const Eigen::Isometry3d& X_RS2, double finger, const std::string& note) {
    const double gap =
        c.end_effector.finger_gap_open_ft -
        finger * (c.end_effector.finger_gap_open_ft - c.end_effector.finger_gap_closed_ft);
    const Eigen::Isometry3d X_RP = finger > 0.5 ? X_RS2 * g.X_S2P : X_RP_bay;
    const auto s = SolveArmIk(c.arm, X_RS2, h, Elbow::kUp);
    if (!s) throw InputError("mission waypoint '" + note + "' is out of the arm's reach");
    const std::string why = Interpenetration(c, model, s->angles_deg, h, gap, X_RP);
    if (!why.empty()) throw InputError("mission waypoint '" + note + "': " + why);
    return s->angles_deg;
  };
  auto add = [&](double t, const Eigen::Isometry3d& X_RS2, double finger, int camera,
                 const std::string& note, const std::string& extra = "") {
    keys.push_back({t, solve(X_RS2, finger, note), h, finger, camera, note, extra});
  };
  Keyframe stowed;
  stowed.shoulder_height_ft = h;
  stowed.camera = station(V::kExternal);
  stowed.note = "stowed, external camera";
  stowed.extra = "overlay=on";
  keys.push_back(stowed);

  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  auto shifted = [](Eigen::Isometry3d X, const Eigen::Vector3d& d) {
    X.translation() += d;
    return X;
  };
  // Mode 1: over the receptacle, down, close the finger.
  add(5.0, shifted(g.X_RS2_grasp, 8 * up), 0, station(V::kOverTheBay),
      "over the receptacle, aft flight deck camera", "camera_zoom=0 camera_pan=0 camera_tilt=0");
  add(8.0, shifted(g.X_RS2_grasp, 2 * up), 0, station(V::kWrist), "just above it, wrist camera",
      "camera_zoom=0.3");
  add(11.0, g.X_RS2_grasp, 0, 0, "grasp position", "camera_zoom=0.3");
  add(12.0, g.X_RS2_grasp, 0, 0, "finger open", "camera_zoom=0");
  add(15.0, g.X_RS2_grasp, 1, station(V::kForwardBulkhead),
      "finger closed on the bar: acquisition; forward bulkhead camera");
  // Mode 2: straight up out of the bay in small steps (joint interpolation
  // between close waypoints keeps the path straight).
  const double r = 0.5 * c.payload.diameter_ft + c.payload.probe_diameter_ft;
  const double lift = (c.payload.p_RoPo_R_ft.z() < 0 ? -c.payload.p_RoPo_R_ft.z() : 0) + r + 3.0;
  const int steps = 6;
  for (int i = 1; i <= steps; ++i) {
    add(15.0 + 1.5 * i, shifted(g.X_RS2_grasp, (lift * i / steps) * up), 1,
        i == 1   ? station(V::kAftBulkhead)
        : i == 4 ? station(V::kElbow)
                 : 0,
        i == steps ? "clear of the bay"
        : i == 1   ? "lifting, aft bulkhead camera"
        : i == 4   ? "lifting, elbow camera"
                   : "lifting");
  }
  double t = 15.0 + 1.5 * steps;
  // Mode 3: up and over, the probe turned toward the port, then rise to it.
  const Eigen::Isometry3d X_RS2_dock = g.X_RP_dock * g.X_S2P.inverse();
  const Eigen::Vector3d yC = c.cae.R_RC.col(1);
  const Eigen::Isometry3d X_RS2_predock = shifted(X_RS2_dock, -3.0 * yC);
  const Eigen::Isometry3d X_high = shifted(g.X_RS2_grasp, (lift + 6.0) * up);
  add(t += 3.0, X_high, 1, station(V::kPortAftWindow),
      "high above the bay, port aft window: pan and tilt up",
      "camera_pan=0 camera_tilt=0 camera_zoom=0");
  // Turn in steps: interpolate the payload's pose from high to pre-dock.
  const Eigen::Isometry3d X_RP_high = X_high * g.X_S2P, X_RP_pre = X_RS2_predock * g.X_S2P;
  const int turn = 6;
  for (int i = 1; i <= turn; ++i) {
    const Eigen::Isometry3d X_RP = Between(X_RP_high, X_RP_pre, static_cast<double>(i) / turn);
    add(t += 1.5, X_RP * g.X_S2P.inverse(), 1,
        i == turn ? station(V::kCaeDockingPort)
        : i == 3  ? station(V::kExternal)
                  : 0,
        i == turn ? "under the port, CAE camera"
        : i == 3  ? "turning toward the port, external camera"
                  : "turning toward the port",
        i == 2   ? "camera_pan=15 camera_tilt=30 camera_zoom=0.4"
        : i == 3 ? "camera_pan=0 camera_tilt=0 camera_zoom=0"
                 : "");
  }
  const int rise = 6;
  for (int i = 1; i <= rise; ++i) {
    add(t += 1.0, shifted(X_RS2_predock, (3.0 * i / rise) * yC), 1, 0,
        i == rise ? "docked" : "rising to the port", i == rise ? "camera_zoom=0.5" : "");
  }
  add(t += 2.0, X_RS2_dock, 1, station(V::kExternal), "hold, external camera", "camera_zoom=0");
  return keys;
}

std::string FormatTimeline(const std::vector<Keyframe>& keys, const std::string& header) {
  std::ostringstream os;
  os << header;
  for (const Keyframe& k : keys) {
    char line[512];
    std::snprintf(line, sizeof line,
                  "%-6.2f shoulder_yaw=%.4f shoulder_pitch=%.4f elbow_pitch=%.4f wrist_pitch=%.4f "
                  "wrist_yaw=%.4f wrist_roll=%.4f shoulder_height=%.3f finger=%.2f",
                  k.t_s, k.angles_deg[0], k.angles_deg[1], k.angles_deg[2], k.angles_deg[3],
                  k.angles_deg[4], k.angles_deg[5], k.shoulder_height_ft, k.finger);
    os << line;
    if (k.camera) os << " camera=" << k.camera;
    if (!k.extra.empty()) os << " " << k.extra;
    os << "   # " << k.note << "\n";
  }
  os << keys.back().t_s + 1.0 << " end\n";
  return os.str();
}

}  // namespace rms::mission
