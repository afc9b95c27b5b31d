#include "rms/scene_proc/camera_stations.h"

#include <algorithm>
#include <cmath>

#include "rms/base/check.h"

namespace rms::scene_proc {

Eigen::Isometry3d MountPose(CameraMount mount, const arm::ArmPose& arm, const CaeConfig& cae) {
  switch (mount) {
    case CameraMount::kShuttle:
      return Eigen::Isometry3d::Identity();
    case CameraMount::kElbow:
      return arm.X_RF3;
    case CameraMount::kWrist:
      return arm.X_RS2;
    case CameraMount::kCae:
      return arm::MakeIsometry(cae.R_RC, cae.p_RoCo_R_ft);
  }
  RMS_CHECK(false);
  return {};
}

Eigen::Matrix3d AimRotation(const Eigen::Vector3d& look_M) {
  const Eigen::Vector3d x = look_M.normalized();
  const Eigen::Vector3d y = x.cross(Eigen::Vector3d::UnitZ()).normalized();  // right
  const Eigen::Vector3d z = x.cross(y);                                      // down
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = y;
  r.col(2) = z;
  return r;
}

void ClampPanTilt(const CameraStationConfig& cam, double* pan_deg, double* tilt_deg,
                  Counters* counters) {
  if (*pan_deg < cam.pan_min_deg || *pan_deg > cam.pan_max_deg) {
    if (counters) counters->Add(Counter::kClampedCameraPan);
    *pan_deg = std::clamp(*pan_deg, cam.pan_min_deg, cam.pan_max_deg);
  }
  if (*tilt_deg < cam.tilt_min_deg || *tilt_deg > cam.tilt_max_deg) {
    if (counters) counters->Add(Counter::kClampedCameraTilt);
    *tilt_deg = std::clamp(*tilt_deg, cam.tilt_min_deg, cam.tilt_max_deg);
  }
}

CameraView ComputeCameraView(const LabConfig& config, int station, double pan_deg, double tilt_deg,
                             double zoom, const arm::ArmPose& arm, Counters* counters) {
  RMS_CHECK(station >= 1 && station <= kNumCameraStations);
  const CameraStationConfig& cam = config.cameras[station - 1];
  ClampPanTilt(cam, &pan_deg, &tilt_deg, counters);
  zoom = std::clamp(zoom, 0.0, 1.0);
  const Eigen::Isometry3d X_RM = MountPose(cam.mount, arm, config.cae);
  const Eigen::Matrix3d R_MA = AimRotation(cam.p_MoAim_M_ft - cam.p_MoCam_M_ft);
  const double pan = pan_deg * M_PI / 180.0, tilt = tilt_deg * M_PI / 180.0;
  // Pan about the aim frame's down axis (+Z: positive turns right), then tilt
  // about the panned right axis (R_y(+tilt) tips X toward -Z, i.e. up).
  const Eigen::Matrix3d R_AE = (Eigen::AngleAxisd(pan, Eigen::Vector3d::UnitZ()) *
                                Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitY()))
                                   .toRotationMatrix();
  CameraView v;
  v.p_RoEye_R_ft = X_RM * cam.p_MoCam_M_ft;
  v.R_RE = X_RM.linear() * R_MA * R_AE;
  v.fov_deg = cam.fov_max_deg - zoom * (cam.fov_max_deg - cam.fov_min_deg);
  return v;
}

}  // namespace rms::scene_proc
