#include "manual_control.h"

#include <algorithm>
#include <cmath>
#include <spdlog/spdlog.h>

#include "rms/arm_ik.h"
#include "rms/arm_kinematics.h"

namespace rms::op {

ManualControl::ManualControl(const LabConfig& config, const Bindings& bindings)
    : config_(config), b_(bindings), target_(InitialInputs(config.inputs)), out_(target_) {}

void ManualControl::AddDevice(std::unique_ptr<InputDevice> device) {
  spdlog::info("device: {}", device->Describe());
  devices_.push_back(std::move(device));
  reported_gone_.push_back(false);
}

OperatorInputs ManualControl::Step(double dt_s) {
  DeviceCommands cmd;
  for (std::size_t i = 0; i < devices_.size(); ++i) {
    if (!devices_[i]->connected()) {
      if (!reported_gone_[i]) {
        spdlog::warn("device gone: {}", devices_[i]->Describe());
        counters_.Add("device.disconnected");
        reported_gone_[i] = true;
      }
      continue;
    }
    devices_[i]->Poll(&cmd);
  }
  return Apply(cmd, dt_s);
}

void ManualControl::SetInputs(const OperatorInputs& in) {
  target_ = in;
  target_.reset = false;
  out_ = target_;
}

void ManualControl::PollFrozen() {
  freeze_requested_ = step_requested_ = false;
  DeviceCommands cmd;
  for (std::size_t i = 0; i < devices_.size(); ++i) {
    if (devices_[i]->connected()) devices_[i]->Poll(&cmd);
  }
  bool ignored = false;
  for (const Action& a : cmd.events) {
    if (a.kind == ActionKind::kFreeze) freeze_requested_ = true;
    else if (a.kind == ActionKind::kStep) step_requested_ = true;
    else if (a.kind == ActionKind::kQuit) quit_ = true;
    else ignored = true;
  }
  for (int i = 0; i < kNumAnalogInputs; ++i) ignored = ignored || cmd.step[i] != 0 || cmd.rate[i] != 0;
  ignored = ignored || cmd.v_R_ft_s.squaredNorm() > 0 || cmd.w_S2_deg_s.squaredNorm() > 0;
  if (ignored) counters_.Add("frozen.inputs_ignored");
}

OperatorInputs ManualControl::Apply(const DeviceCommands& cmd, double dt_s) {
  const InputCalibrations& cal = config_.inputs;
  out_.reset = false;
  freeze_requested_ = step_requested_ = false;
  for (const Action& a : cmd.events) {
    switch (a.kind) {
      case ActionKind::kCamera: target_.camera_station = a.camera; break;
      case ActionKind::kCameraNext: target_.camera_station = target_.camera_station % kNumCameraStations + 1; break;
      case ActionKind::kCameraPrev:
        target_.camera_station = (target_.camera_station + kNumCameraStations - 2) % kNumCameraStations + 1;
        break;
      case ActionKind::kReset: out_.reset = true; break;
      case ActionKind::kOverlay: target_.overlay = !target_.overlay; break;
      case ActionKind::kQuit: quit_ = true; break;
      case ActionKind::kFreeze: freeze_requested_ = true; break;
      case ActionKind::kStep: step_requested_ = true; break;
      default: break;
    }
  }
  // Resolved rate (3D mouse): System Two's velocity to the arm's targets.
  if (cmd.v_R_ft_s.squaredNorm() > 0 || cmd.w_S2_deg_s.squaredNorm() > 0) {
    std::array<double, 6> q{};
    for (int i = 0; i < 6; ++i) q[i] = target_.value[i];
    Eigen::Isometry3d X = ComputeArmPose(config_.arm, SinCosFromDegrees(q), target_.value[kShoulderHeight]).X_RS2;
    X.translation() += cmd.v_R_ft_s * dt_s;
    const Eigen::Vector3d w = cmd.w_S2_deg_s * (M_PI / 180.0) * dt_s;
    if (w.norm() > 0) X.linear() = X.linear() * Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
    if (const auto s = SolveArmIk(config_.arm, X, target_.value[kShoulderHeight], Elbow::kUp)) {
      for (int i = 0; i < 6; ++i) target_.value[i] = s->angles_deg[i];
    } else {
      counters_.Add("resolved_rate.unreachable");
    }
  }
  for (int i = 0; i < kNumAnalogInputs; ++i) {
    double t = target_.value[i] + cmd.step[i] + cmd.rate[i] * dt_s;
    // Clamping to the calibrated range, reported once per excursion.
    const double c = std::clamp(t, cal[i].min, cal[i].max);
    if (c != t) {
      counters_.Add("clamped." + std::string(kAnalogInputNames[i]));
      if (!clamping_[i]) {
        spdlog::warn("{} command {:.3f} beyond its range [{}, {}] {}: clamped", kAnalogInputNames[i], t, cal[i].min,
                     cal[i].max, cal[i].unit);
      }
    }
    clamping_[i] = c != t;
    target_.value[i] = c;
    // The rate limit: the output follows the target at no more than max_rate.
    const double lim = b_.max_rate[i] * dt_s;
    out_.value[i] += std::clamp(target_.value[i] - out_.value[i], -lim, lim);
  }
  out_.camera_station = target_.camera_station;
  out_.overlay = target_.overlay;
  return out_;
}

}  // namespace rms::op
