#include "rms/operator_station/autopilot.h"

#include <algorithm>
#include <cmath>
#include <spdlog/spdlog.h>

#include "rms/arm/kinematics.h"
#include "rms/operator_station/guidance.h"
#include "rms/wire/acquisition_conditions.h"
#include "rms/wire/collision_bits.h"
#include "rms/wire/dcp_mode.h"

namespace rms::operator_station {

const char* AutopilotPhaseName(AutopilotPhase p) {
  switch (p) {
    case AutopilotPhase::kWaitTelemetry:
      return "waiting for the DCP";
    case AutopilotPhase::kReset:
      return "reset";
    case AutopilotPhase::kOpenFinger:
      return "open the finger";
    case AutopilotPhase::kApproach:
      return "approach";
    case AutopilotPhase::kDescend:
      return "descend onto the bar";
    case AutopilotPhase::kClose:
      return "close the finger";
    case AutopilotPhase::kLift:
      return "lift out of the bay";
    case AutopilotPhase::kTransfer:
      return "transfer under the port";
    case AutopilotPhase::kDock:
      return "dock";
    case AutopilotPhase::kDocked:
      return "docked";
    case AutopilotPhase::kRelieve:
      return "relieve a collision";
    case AutopilotPhase::kResync:
      return "resume from a checkpoint";
    case AutopilotPhase::kFailed:
      return "failed";
  }
  return "?";
}

namespace {

// After the descent the autopilot corrects once more when the palm is still
// above the BAR's top by more than this share of TPOB (the plan puts it at
// mission::kGraspTpobShare).
constexpr double kGraspCorrectTpobShare = 0.7;

Eigen::Isometry3d Shifted(Eigen::Isometry3d X, const Eigen::Vector3d& d) {
  X.translation() += d;
  return X;
}

}  // namespace

Autopilot::Autopilot(const LabConfig& config, AutopilotOptions options)
    : config_(config),
      opt_(options),
      limits_(LimitsFromConfig(config, options.joint_rate_deg_s)),
      model_(scene_model::BuildSceneModel(config)),
      dt_s_(1.0 / config.session.frame_rate_hz),
      follow_(config.session.frame_rate_hz),
      stations_(FindCameraStations(config.cameras)) {
  cmd_ = wire::InitialInputs(config.inputs);
  if (const int s = stations_[static_cast<int>(CameraView::kExternal)]) cmd_.camera_station = s;
  cmd_.overlay = true;
  // System Two at the grasp, in the payload's frame (body-fixed; the payload
  // itself is wherever the telemetry says it is).
  X_PS2_grasp_ = mission::PlanGeometry(config).X_S2P.inverse();
}

void Autopilot::Enter(AutopilotPhase p) {
  if (p != phase_) spdlog::info("autopilot: {} ({:.1f} s)", AutopilotPhaseName(p), t_s_);
  phase_ = p;
  phase_t0_s_ = t_s_;
}

void Autopilot::Fail(const std::string& why) {
  failure_ = why;
  spdlog::error("autopilot: {}", why);
  plan_.clear();
  phase_ = AutopilotPhase::kFailed;
}

void Autopilot::Camera(CameraView view, double zoom) {
  const int station = stations_[static_cast<int>(view)];
  if (!opt_.cameras || station == 0) return;  // none in the configuration: as it is
  cmd_.camera_station = station;
  cmd_.value[kCameraPan] = 0.0;
  cmd_.value[kCameraTilt] = 0.0;
  cmd_.value[kCameraZoom] = zoom;
}

std::array<double, 6> Autopilot::CommandedAngles() const {
  std::array<double, 6> q{};
  for (int i = 0; i < kNumJoints; ++i) q[i] = cmd_.value[i];
  return q;
}

Eigen::Isometry3d Autopilot::CommandedPose() const {
  return ForwardPose(config_.arm, CommandedAngles(), cmd_.value[kShoulderHeight]);
}

std::optional<std::array<double, 6>> Autopilot::Solve(const Eigen::Isometry3d& X_RS2) const {
  // Within the joints' travel and the master arm's range (arm_motion.h).
  return SolveWithinLimits(config_.arm, limits_, X_RS2, cmd_.value[kShoulderHeight]);
}

bool Autopilot::StepJoints(const std::array<double, 6>& target) {
  JointAngles q = CommandedAngles();
  const bool there = StepJointsToward(&q, target, limits_.rate_deg_s, dt_s_);
  for (int i = 0; i < kNumJoints; ++i) cmd_.value[i] = q[i];
  return there;
}

void Autopilot::PlanLine(const Eigen::Isometry3d& X1, double speed_ft_s) {
  Segment g;
  g.X1 = X1;
  g.speed_ft_s = speed_ft_s;
  plan_.push_back(g);
}

void Autopilot::PlanJoints(const std::array<double, 6>& q) {
  Segment g;
  g.joints = true;
  g.q = q;
  plan_.push_back(g);
}

Autopilot::PlanState Autopilot::StepPlan() {
  while (!plan_.empty()) {
    Segment& g = plan_.front();
    if (g.joints) {
      if (!StepJoints(g.q)) return PlanState::kMoving;
      plan_.erase(plan_.begin());
      return plan_.empty() ? PlanState::kDone : PlanState::kMoving;
    }
    if (!g.started) {
      g.started = true;
      g.X0 = CommandedPose();
      const double dist = (g.X1.translation() - g.X0.translation()).norm();
      const double turn = AngleBetweenDeg(g.X0.linear(), g.X1.linear());
      g.duration_s = std::max({dist / g.speed_ft_s, turn / opt_.turn_rate_deg_s, 2 * dt_s_});
    }
    const double s_next = std::min(1.0, g.s + dt_s_ / g.duration_s);
    const auto q = Solve(Interpolate(g.X0, g.X1, s_next));
    if (!q) return PlanState::kUnreachable;
    // Along the line only as fast as every joint can follow: a frame whose
    // step would be too large is spent catching up, the line's clock held.
    if (StepJoints(*q)) g.s = s_next;
    if (g.s < 1.0) return PlanState::kMoving;
    plan_.erase(plan_.begin());
    return plan_.empty() ? PlanState::kDone : PlanState::kMoving;
  }
  return PlanState::kDone;
}

bool Autopilot::Settled(const dcp_telemetry_t& tm) const {
  if (tm.held) return false;
  for (int i = 0; i < kNumJoints; ++i) {
    if (std::abs(WrapDeg(tm.master_angles_deg[i] - cmd_.value[i])) > 0.02) return false;
    if (std::abs(WrapDeg(tm.slave_angles_deg[i] - tm.master_angles_deg[i])) > 0.02) return false;
  }
  return std::abs(tm.master_finger - cmd_.value[kFinger]) < 0.002;
}

std::string Autopilot::JointPathHits(const std::array<double, 6>& q0,
                                     const std::array<double, 6>& q1, const dcp_telemetry_t& tm,
                                     mission::PayloadState payload) const {
  double m = 0.0;
  for (int i = 0; i < kNumJoints; ++i) m = std::max(m, std::abs(WrapDeg(q1[i] - q0[i])));
  const int n = std::max(1, static_cast<int>(std::ceil(m / 1.0)));  // a sample a degree
  const Eigen::Isometry3d X_RP = TelemetryPose(tm.p_RoPo_R_ft, tm.R_RP);
  const double margin = payload == mission::PayloadState::kInBay ? margin_ft_ : opt_.clearance_ft;
  for (int k = 1; k <= n; ++k) {
    std::array<double, 6> q{};
    for (int i = 0; i < kNumJoints; ++i) q[i] = q0[i] + WrapDeg(q1[i] - q0[i]) * k / n;
    std::string hit = mission::Interpenetration(config_, model_, q, cmd_.value[kShoulderHeight],
                                                tm.finger_gap_ft, X_RP, payload, margin);
    if (!hit.empty()) return hit;
  }
  return "";
}

std::string Autopilot::LinePathHits(const Eigen::Isometry3d& X0, const Eigen::Isometry3d& X1,
                                    const dcp_telemetry_t& tm,
                                    mission::PayloadState payload) const {
  const double len = (X1.translation() - X0.translation()).norm() +
                     AngleBetweenDeg(X0.linear(), X1.linear()) / 10.0;
  const double margin = payload == mission::PayloadState::kInBay ? margin_ft_ : opt_.clearance_ft;
  const int n = std::max(1, static_cast<int>(std::ceil(len / 0.5)));  // a sample every half foot
  // The payload: where it is (in the bay), or carried along with System Two.
  const Eigen::Isometry3d X_RP_bay = TelemetryPose(tm.p_RoPo_R_ft, tm.R_RP);
  for (int k = 1; k <= n; ++k) {
    const Eigen::Isometry3d X = Interpolate(X0, X1, static_cast<double>(k) / n);
    const auto q = Solve(X);
    if (!q) return "out of reach";
    const Eigen::Isometry3d X_RP = payload == mission::PayloadState::kHeld ? X * X_S2P_ : X_RP_bay;
    std::string hit = mission::Interpenetration(config_, model_, *q, cmd_.value[kShoulderHeight],
                                                tm.finger_gap_ft, X_RP, payload, margin);
    if (!hit.empty()) return hit;
  }
  return "";
}

void Autopilot::PlanApproach(const dcp_telemetry_t& tm) {
  plan_.clear();
  const Eigen::Isometry3d X_grasp = TelemetryPose(tm.p_RoPo_R_ft, tm.R_RP) * X_PS2_grasp_;
  const Eigen::Isometry3d X_hover = Shifted(X_grasp, -opt_.hover_ft * X_grasp.linear().col(0));
  const auto q_hover = Solve(X_hover);
  if (!q_hover) return Fail("the pose above the bar receptacle is out of the arm's reach");
  const std::array<double, 6> q0 = CommandedAngles();
  constexpr auto kInBay = mission::PayloadState::kInBay;
  if (!opt_.plan_clear_paths) {
    // Unplanned, but not blind: after a collision, up above the hover height
    // first and in from above, as an operator would.
    if (collisions_ > 0) {
      const Eigen::Isometry3d X0 = CommandedPose();
      const double rise = std::max(2.0, X_hover.translation().z() + 2.0 - X0.translation().z());
      PlanLine(Shifted(X0, Eigen::Vector3d(0, 0, rise)), 1.0);
    }
    return PlanJoints(*q_hover);
  }
  // Starting closer than the margin (after a relief, or an arm left near the
  // payload), paths are only asked not to run into anything.
  margin_ft_ = opt_.clearance_ft;
  if (!mission::Interpenetration(config_, model_, q0, cmd_.value[kShoulderHeight], tm.finger_gap_ft,
                                 TelemetryPose(tm.p_RoPo_R_ft, tm.R_RP), kInBay, margin_ft_)
           .empty()) {
    margin_ft_ = 0.0;
  }
  // Straight there in joint space if that is clear; else first straight up
  // above the hover height; else by way of the stowed arm.
  const std::string direct = JointPathHits(q0, *q_hover, tm, kInBay);
  if (direct.empty()) return PlanJoints(*q_hover);
  const Eigen::Isometry3d X0 = CommandedPose();
  const double rise = std::max(0.0, X_hover.translation().z() + 2.0 - X0.translation().z());
  const Eigen::Isometry3d X_up = Shifted(X0, Eigen::Vector3d(0, 0, std::max(rise, 2.0)));
  if (const auto q_up = Solve(X_up); q_up && LinePathHits(X0, X_up, tm, kInBay).empty() &&
                                     JointPathHits(*q_up, *q_hover, tm, kInBay).empty()) {
    counters_.Add(Counter::kAutopilotViaPoints);
    spdlog::info("autopilot: the direct approach would bring the {}; going up first", direct);
    PlanLine(X_up, 1.0);
    return PlanJoints(*q_hover);
  }
  const std::array<double, 6> stowed{};
  if (JointPathHits(q0, stowed, tm, kInBay).empty() &&
      JointPathHits(stowed, *q_hover, tm, kInBay).empty()) {
    counters_.Add(Counter::kAutopilotViaPoints);
    spdlog::info("autopilot: the direct approach would bring the {}; going by the stowed arm",
                 direct);
    PlanJoints(stowed);
    return PlanJoints(*q_hover);
  }
  counters_.Add(Counter::kAutopilotUnplanned);
  spdlog::warn("autopilot: no clear approach found ({}); going straight, relieving collisions",
               direct);
  PlanJoints(*q_hover);
}

void Autopilot::PlanTransfer(const dcp_telemetry_t& tm) {
  plan_.clear();
  // The payload as the DCP holds it, in System Two.
  X_S2P_ =
      TelemetryPose(tm.p_RoA_R_ft, tm.R_RS2).inverse() * TelemetryPose(tm.p_RoPo_R_ft, tm.R_RP);
  X_RP_dock_ = mission::PlanGeometry(config_, cmd_.value[kShoulderHeight]).X_RP_dock;
  const Eigen::Vector3d yC = config_.cae.R_RC.col(1);
  const Eigen::Isometry3d X_predock = Shifted(X_RP_dock_ * X_S2P_.inverse(), -opt_.predock_ft * yC);
  const Eigen::Isometry3d X0 = CommandedPose();
  constexpr auto kHeld = mission::PayloadState::kHeld;
  if (!opt_.plan_clear_paths) return PlanLine(X_predock, opt_.transfer_speed_ft_s);
  // The straight line, if it keeps the arm and the payload clear and in
  // reach; else through a point higher up.
  const std::string direct = LinePathHits(X0, X_predock, tm, kHeld);
  if (direct.empty()) return PlanLine(X_predock, opt_.transfer_speed_ft_s);
  for (double up : {6.0, 12.0}) {
    const Eigen::Isometry3d X_up = Shifted(X0, Eigen::Vector3d(0, 0, up));
    if (LinePathHits(X0, X_up, tm, kHeld).empty() &&
        LinePathHits(X_up, X_predock, tm, kHeld).empty()) {
      counters_.Add(Counter::kAutopilotViaPoints);
      spdlog::info("autopilot: the straight transfer would bring the {}; going {} ft higher first",
                   direct, up);
      PlanLine(X_up, opt_.transfer_speed_ft_s);
      return PlanLine(X_predock, opt_.transfer_speed_ft_s);
    }
  }
  Fail("no clear path from above the bay to under the CAE's port (" + direct + ")");
}

void Autopilot::StartPhase(AutopilotPhase p, const dcp_telemetry_t& tm) {
  Enter(p);
  plan_.clear();
  switch (p) {
    case AutopilotPhase::kApproach:
      Camera(CameraView::kOverTheBay);
      PlanApproach(tm);
      break;
    case AutopilotPhase::kDescend:
      Camera(CameraView::kWrist, 0.3);
      PlanLine(TelemetryPose(tm.p_RoPo_R_ft, tm.R_RP) * X_PS2_grasp_, opt_.descend_speed_ft_s);
      break;
    case AutopilotPhase::kClose:
      Camera(CameraView::kForwardBulkhead);
      finger_full_frames_ = 0;
      break;
    case AutopilotPhase::kLift:
      Camera(CameraView::kAftBulkhead);
      seen_mode3_ = tm.mode == wire::DcpMode::kManoeuvring;
      mode3_height_ft_ = CommandedPose().translation().z();
      PlanLine(Shifted(CommandedPose(), Eigen::Vector3d(0, 0, 40.0)), opt_.lift_speed_ft_s);
      break;
    case AutopilotPhase::kTransfer:
      Camera(CameraView::kPortAftWindow);
      PlanTransfer(tm);
      break;
    case AutopilotPhase::kDock:
      Camera(CameraView::kCaeDockingPort);
      PlanLine(X_RP_dock_ * X_S2P_.inverse(), opt_.dock_speed_ft_s);
      break;
    case AutopilotPhase::kDocked:
      Camera(CameraView::kExternal);
      docked_at_s_ = t_s_;
      break;
    default:
      break;
  }
}

void Autopilot::Relieve(const dcp_telemetry_t& tm) {
  ++collisions_;
  counters_.Add(Counter::kAutopilotCollisionsRelieved);
  const std::string kinds = wire::CollisionNames(static_cast<std::uint32_t>(tm.collisions));
  spdlog::info("autopilot: collision ({}) in {}: back to the pose the slave holds, then away",
               kinds, AutopilotPhaseName(phase_));
  if (collisions_ > opt_.max_collisions) {
    return Fail("gave up after " + std::to_string(opt_.max_collisions) +
                " collisions (last: " + kinds + ")");
  }
  // What the operator must do: bring the master back to where the slave
  // stopped, which ends the collision (unless the slave itself started in
  // one), then move away from the contact.
  if (tm.slave_collisions == 0) {
    for (int i = 0; i < kNumJoints; ++i) cmd_.value[i] = tm.slave_angles_deg[i];
    cmd_.value[kFinger] = tm.slave_finger;
  }
  relieved_at_frame_ = tm.frame;
  const Eigen::Isometry3d X = CommandedPose();
  plan_.clear();
  if (tm.mode == wire::DcpMode::kAcquisition) {
    // Up and away from the payload's axis, horizontally.
    const Eigen::Isometry3d X_RP = TelemetryPose(tm.p_RoPo_R_ft, tm.R_RP);
    const Eigen::Vector3d axis = X_RP.linear().col(1);
    Eigen::Vector3d away = X.translation() - X_RP.translation();
    away -= away.dot(axis) * axis;
    away.z() = 0.0;
    away = away.norm() > 1e-6 ? away.normalized() : Eigen::Vector3d::UnitY();
    PlanLine(Shifted(X, 1.5 * away + Eigen::Vector3d(0, 0, 1.5)), 0.5);
    resume_ = AutopilotPhase::kApproach;
  } else if (tm.mode == wire::DcpMode::kExtraction) {
    const Eigen::Vector3d to_centre(0, -0.3 * std::copysign(1.0, tm.p_RoPo_R_ft[1]), 0.5);
    PlanLine(Shifted(X, to_centre), 0.5);  // up and toward the bay's centre line
    resume_ = AutopilotPhase::kLift;
  } else {
    PlanLine(Shifted(X, -1.0 * config_.cae.R_RC.col(1)), 0.5);  // back down the port's axis
    resume_ = AutopilotPhase::kDock;
  }
  Enter(AutopilotPhase::kRelieve);
}

void Autopilot::Resync(const wire::OperatorInputs& restored) {
  const int camera = cmd_.camera_station;
  cmd_ = restored;
  cmd_.reset = false;
  if (opt_.cameras) cmd_.camera_station = camera;
  plan_.clear();
  retries_ = 0;
  relieved_at_frame_ = -1000;
  failure_.clear();
  follow_.Forget();
  Enter(AutopilotPhase::kResync);
}

bool Autopilot::CommandedWhereItIs(const dcp_telemetry_t& tm) const {
  for (int i = 0; i < kNumJoints; ++i) {
    if (std::abs(tm.master_angles_deg[i] - tm.slave_angles_deg[i]) >
        FollowWatch::kRecoverToleranceDeg)
      return false;
  }
  return std::abs(tm.master_shoulder_height_ft - tm.slave_shoulder_height_ft) <= 1e-6;
}

wire::OperatorInputs Autopilot::Step(const dcp_telemetry_t* tm_ptr) {
  t_s_ += dt_s_;
  cmd_.reset = false;
  if (phase_ == AutopilotPhase::kFailed) return cmd_;
  if (t_s_ > opt_.timeout_s) {
    Fail("timed out in phase '" + std::string(AutopilotPhaseName(phase_)) + "'");
    return cmd_;
  }
  if (!tm_ptr) return cmd_;
  const dcp_telemetry_t& tm = *tm_ptr;

  // A collision: the DCP holds the slave arm. (The finger stopping on the
  // bar while closing is the essential contact, not a collision.)
  const bool moving_phase = phase_ != AutopilotPhase::kWaitTelemetry &&
                            phase_ != AutopilotPhase::kReset && phase_ != AutopilotPhase::kDocked &&
                            phase_ != AutopilotPhase::kResync;
  // A part that does not follow: said, and the command held until it does
  // (a repair; a slowed joint catching up); said again every 30 s.
  for (const FollowWatch::Change& c : follow_.Observe(tm)) {
    if (c.failing) {
      spdlog::warn("autopilot: {}: holding its command in phase '{}' until it follows", c.text,
                   AutopilotPhaseName(phase_));
      holding_since_s_ = t_s_;
    } else {
      spdlog::info("autopilot: {}: carrying on", c.text);
    }
  }
  if (moving_phase && follow_.failing()) {
    if (t_s_ - holding_since_s_ >= 30.0) {
      holding_since_s_ = t_s_;
      spdlog::warn(
          "autopilot: still holding: a part does not follow its command (repair it: "
          "scripts/lab control repair all; the autopilot gives up {:.0f} s into the "
          "session)",
          opt_.timeout_s);
    }
    return cmd_;
  }
  if (moving_phase && tm.held && tm.frame > relieved_at_frame_ + 3) {
    // Held though commanded where the arm is: no relief can help (a
    // drifting joint pushes it); the watch says so. Hold, do not count it.
    if (CommandedWhereItIs(tm)) return cmd_;
    Relieve(tm);
    return cmd_;
  }

  switch (phase_) {
    case AutopilotPhase::kWaitTelemetry:
      StepWaitTelemetry(tm);
      break;
    case AutopilotPhase::kReset:
      StepReset(tm);
      break;
    case AutopilotPhase::kOpenFinger:
      StepOpenFinger(tm);
      break;
    case AutopilotPhase::kApproach:
      StepApproach(tm);
      break;
    case AutopilotPhase::kDescend:
      StepDescend(tm);
      break;
    case AutopilotPhase::kClose:
      StepClose(tm);
      break;
    case AutopilotPhase::kLift:
      StepLift(tm);
      break;
    case AutopilotPhase::kTransfer:
      StepTransfer(tm);
      break;
    case AutopilotPhase::kDock:
      StepDock(tm);
      break;
    case AutopilotPhase::kDocked:
      StepDocked(tm);
      break;
    case AutopilotPhase::kRelieve:
      StepRelieve(tm);
      break;
    case AutopilotPhase::kResync:
      StepResync(tm);
      break;
    case AutopilotPhase::kFailed:
      break;
  }
  return cmd_;
}

void Autopilot::StepWaitTelemetry(const dcp_telemetry_t& tm) {
  // Take the arm as it is, so the first command moves nothing.
  for (int i = 0; i < kNumJoints; ++i) cmd_.value[i] = tm.slave_angles_deg[i];
  cmd_.value[kShoulderHeight] = tm.slave_shoulder_height_ft;
  cmd_.value[kFinger] = tm.slave_finger;
  Camera(CameraView::kExternal);
  if (tm.mode != wire::DcpMode::kAcquisition || tm.acquired || tm.docked) {
    Enter(AutopilotPhase::kReset);
    reset_frames_ = 0;
  } else {
    Enter(AutopilotPhase::kOpenFinger);
  }
}

void Autopilot::StepReset(const dcp_telemetry_t& tm) {
  // The reset button, one frame; then wait for Mode 1.
  if (reset_frames_++ == 0)
    cmd_.reset = true;
  else if (reset_frames_ > 3 && tm.mode == wire::DcpMode::kAcquisition && !tm.acquired &&
           !tm.docked)
    Enter(AutopilotPhase::kOpenFinger);
  else if (reset_frames_ > 60)
    Fail("the DCP did not return to Mode 1 after a reset");
}

void Autopilot::StepOpenFinger(const dcp_telemetry_t& tm) {
  cmd_.value[kFinger] = std::max(0.0, cmd_.value[kFinger] - opt_.finger_rate_per_s * dt_s_);
  if (cmd_.value[kFinger] <= 0.0 && Settled(tm)) StartPhase(AutopilotPhase::kApproach, tm);
}

void Autopilot::StepApproach(const dcp_telemetry_t& tm) {
  const PlanState ps = StepPlan();
  if (ps == PlanState::kUnreachable) return Fail("the approach left the arm's reach");
  if (ps == PlanState::kDone && Settled(tm)) StartPhase(AutopilotPhase::kDescend, tm);
}

void Autopilot::StepDescend(const dcp_telemetry_t& tm) {
  const PlanState ps = StepPlan();
  if (ps == PlanState::kUnreachable) return Fail("the grasp is out of the arm's reach");
  if (ps != PlanState::kDone || !Settled(tm)) return;
  // Closing the loop: the palm must be within TPOB of the bar's top;
  // well short of it (kGraspCorrectTpobShare), descend to the planned height.
  if (tm.palm_to_bar_ft > kGraspCorrectTpobShare * config_.dcp.tpob_ft &&
      retries_ < opt_.max_retries) {
    ++retries_;
    counters_.Add(Counter::kAutopilotGraspCorrections);
    const Eigen::Isometry3d X = CommandedPose();
    PlanLine(
        Shifted(X, (tm.palm_to_bar_ft - mission::GraspPalmAboveBarFt(config_)) * X.linear().col(0)),
        0.2);
    return;
  }
  StartPhase(AutopilotPhase::kClose, tm);
}

void Autopilot::StepClose(const dcp_telemetry_t& tm) {
  if (tm.acquired && tm.mode == wire::DcpMode::kExtraction) {
    StartPhase(AutopilotPhase::kLift, tm);
    return;
  }
  cmd_.value[kFinger] = std::min(1.0, cmd_.value[kFinger] + opt_.finger_rate_per_s * dt_s_);
  if (cmd_.value[kFinger] >= 1.0 && ++finger_full_frames_ > static_cast<int>(1.5 / dt_s_)) {
    // Closed and not acquired: which conditions fail? Open and try again.
    std::string failing;
    for (int i = 0; i < wire::kNumAcquisitionConditions; ++i) {
      if (!tm.acquisition_conditions[i])
        failing += (failing.empty() ? "" : ", ") + std::to_string(i + 1);
    }
    if (++retries_ > opt_.max_retries)
      return Fail("no acquisition (conditions " + failing + " fail)");
    counters_.Add(Counter::kAutopilotGraspRetries);
    spdlog::info(
        "autopilot: finger closed, no acquisition (conditions {} fail): open and grasp again",
        failing);
    Enter(AutopilotPhase::kOpenFinger);
  }
}

void Autopilot::StepLift(const dcp_telemetry_t& tm) {
  if (tm.mode == wire::DcpMode::kManoeuvring && !seen_mode3_) {
    seen_mode3_ = true;
    mode3_height_ft_ = CommandedPose().translation().z();
    Camera(CameraView::kElbow);
  }
  if (seen_mode3_ && CommandedPose().translation().z() >= mode3_height_ft_ + opt_.lift_margin_ft)
    plan_.clear();
  const PlanState ps = StepPlan();
  if (ps == PlanState::kUnreachable && !seen_mode3_)
    return Fail("the arm cannot lift the payload out of the bay");
  if (ps == PlanState::kUnreachable) plan_.clear();  // as high as it goes
  if (plan_.empty() && seen_mode3_ && Settled(tm)) StartPhase(AutopilotPhase::kTransfer, tm);
}

void Autopilot::StepTransfer(const dcp_telemetry_t& tm) {
  const PlanState ps = StepPlan();
  if (ps == PlanState::kUnreachable) return Fail("the transfer path left the arm's reach");
  if (t_s_ - phase_t0_s_ > 6.0 &&
      cmd_.camera_station == stations_[static_cast<int>(CameraView::kPortAftWindow)])
    Camera(CameraView::kExternal);
  if (ps == PlanState::kDone && Settled(tm)) StartPhase(AutopilotPhase::kDock, tm);
}

void Autopilot::StepDock(const dcp_telemetry_t& tm) {
  if (tm.docked) {
    StartPhase(AutopilotPhase::kDocked, tm);
    return;
  }
  const PlanState ps = StepPlan();
  if (ps == PlanState::kUnreachable) return Fail("the port is out of the arm's reach");
  if (ps != PlanState::kDone || !Settled(tm)) return;
  // At the dock pose and not docked: correct by what the telemetry shows.
  if (++retries_ > opt_.max_retries) {
    return Fail("not docked after " + std::to_string(opt_.max_retries) + " corrections (distance " +
                std::to_string(tm.dock_distance_ft) + " ft, angle " +
                std::to_string(tm.dock_angle_deg) + " deg)");
  }
  counters_.Add(Counter::kAutopilotDockCorrections);
  X_S2P_ =
      TelemetryPose(tm.p_RoA_R_ft, tm.R_RS2).inverse() * TelemetryPose(tm.p_RoPo_R_ft, tm.R_RP);
  PlanLine(X_RP_dock_ * X_S2P_.inverse(), opt_.dock_speed_ft_s);
}

void Autopilot::StepDocked(const dcp_telemetry_t& /*tm*/) { ++docked_frames_; }

void Autopilot::StepRelieve(const dcp_telemetry_t& tm) {
  const PlanState ps = StepPlan();
  if (ps == PlanState::kUnreachable) return Fail("cannot back away from the collision");
  if (ps == PlanState::kDone && Settled(tm)) {
    if (resume_ == AutopilotPhase::kDock) {
      // Re-aim at the dock from here.
      Enter(AutopilotPhase::kDock);
      PlanLine(X_RP_dock_ * X_S2P_.inverse(), opt_.dock_speed_ft_s);
    } else {
      StartPhase(resume_, tm);
    }
  }
}

void Autopilot::StepResync(const dcp_telemetry_t& tm) {
  // The first telemetry that answers the restored command says where
  // the task stands.
  if (!Settled(tm)) return;
  if (tm.docked) {
    StartPhase(AutopilotPhase::kDocked, tm);
  } else if (tm.mode == wire::DcpMode::kManoeuvring) {
    StartPhase(AutopilotPhase::kTransfer, tm);
  } else if (tm.mode == wire::DcpMode::kExtraction) {
    StartPhase(AutopilotPhase::kLift, tm);
  } else {
    Enter(AutopilotPhase::kOpenFinger);
  }
}

}  // namespace rms::operator_station
