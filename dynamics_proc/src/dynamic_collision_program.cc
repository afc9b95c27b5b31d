#include "dynamic_collision_program.h"

#include "rms/word_codec.h"

namespace rms::dcp {

ArmSinCos TransmittedArmWords(const std::array<double, 6>& angles_deg) {
  ArmSinCos sc = SinCosFromDegrees(angles_deg);
  for (SinCos& a : sc) {
    a.s = wire::Decode(wire::kSC22, static_cast<std::int32_t>(wire::Encode(wire::kSC22, a.s).word));
    a.c = wire::Decode(wire::kSC22, static_cast<std::int32_t>(wire::Encode(wire::kSC22, a.c).word));
  }
  return sc;
}

DynamicCollisionProgram::DynamicCollisionProgram(const LabConfig& config) : config_(config) {
  X_RP_bay_ = Eigen::Isometry3d::Identity();
  X_RP_bay_.linear() = config.payload.R_RP;
  X_RP_bay_.translation() = config.payload.p_RoPo_R_ft;
  Reset();
}

void DynamicCollisionProgram::Reset() {
  mode_ = 1;
  X_RP_ = X_RP_bay_;
}

double DynamicCollisionProgram::FingerGapFt(double lever) const {
  const auto& e = config_.end_effector;
  return e.finger_gap_open_ft - lever * (e.finger_gap_open_ft - e.finger_gap_closed_ft);
}

void DynamicCollisionProgram::UpdateModes(const OperatorInputs& /*in*/) {
  // Section IV.A: collision detection and the Mode 1 -> 2 -> 3 transitions
  // belong here (its own issue). Until then: Mode 1, no collisions.
}

DcpFrameData DynamicCollisionProgram::Step(const OperatorInputs& in) {
  if (in.reset) Reset();
  std::array<double, 6> angles{};
  for (int i = 0; i < 6; ++i) angles[i] = in.value[i];
  DcpFrameData out;
  out.arm = TransmittedArmWords(angles);
  const double height = in.value[kShoulderHeight];
  pose_ = ComputeArmPose(config_.arm, out.arm, height);

  UpdateModes(in);

  out.control.camera_station = in.camera_station;
  out.control.reset = in.reset;
  out.control.overlay = in.overlay;
  out.control.mode = mode_;
  out.shoulder_height_ft = height;
  out.finger_gap_ft = FingerGapFt(in.value[kFinger]);
  out.camera_pan_deg = in.value[kCameraPan];
  out.camera_tilt_deg = in.value[kCameraTilt];
  out.camera_zoom = in.value[kCameraZoom];
  out.p_RoPo_R_ft = X_RP_.translation();
  out.R_RP = X_RP_.linear();
  out.plane_valid = 0;
  return out;
}

}  // namespace rms::dcp
