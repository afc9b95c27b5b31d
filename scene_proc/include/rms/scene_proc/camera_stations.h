#pragma once
// The eight camera stations of the VISUAL SCENE PROGRAM (docs/scene.md).
// A station sits on a mount (the shuttle, the elbow, the wrist, the CAE); its
// default aim looks from its position to its aim point with the mount's +Z
// up; the operator pans (about the camera's down axis, positive right), tilts
// (about its right axis, positive up) and zooms (vertical field of view from
// fov_max at zoom 0 to fov_min at zoom 1).
//
// Eye frame E: X_E the line of sight, Y_E image right, Z_E image down.
#include <Eigen/Geometry>

#include "rms/arm/kinematics.h"
#include "rms/base/config.h"
#include "rms/base/counters.h"

namespace rms::scene_proc {

struct CameraView {
  Eigen::Vector3d p_RoEye_R_ft;
  Eigen::Matrix3d R_RE;
  double fov_deg;
};

// The mount frame's pose in R for a station.
Eigen::Isometry3d MountPose(CameraMount mount, const arm::ArmPose& arm, const CaeConfig& cae);

// The eye rotation for a default aim direction (in the mount frame, not
// parallel to +Z_M) before pan and tilt, in the mount frame.
Eigen::Matrix3d AimRotation(const Eigen::Vector3d& look_M);

// Pan and tilt clamped to a station's limits; a clamp is counted
// ("clamped.camera_pan", "clamped.camera_tilt") when counters is given.
void ClampPanTilt(const CameraStationConfig& cam, double* pan_deg, double* tilt_deg,
                  Counters* counters);

// The view of station `station` (1..8). Pan and tilt outside the station's
// limits are clamped and counted ("clamped.camera_pan", "clamped.camera_tilt").
CameraView ComputeCameraView(const LabConfig& config, int station, double pan_deg, double tilt_deg,
                             double zoom, const arm::ArmPose& arm, Counters* counters);

}  // namespace rms::scene_proc
