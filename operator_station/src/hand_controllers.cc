#include "rms/operator_station/hand_controllers.h"

#include <algorithm>
#include <cmath>
#include <spdlog/spdlog.h>

#include "rms/arm/kinematics.h"
#include "rms/wire/dcp_mode.h"

namespace rms::operator_station {

namespace {
constexpr double kDeg = M_PI / 180.0;
// An automatic motion (docs/operator.md "Nulling an axis, squaring up,
// unwinding") flies at error / kNullTimeS, at most the scale's full rate,
// and has arrived within kNullTolFt / kNullTolDeg.
constexpr double kNullTimeS = 0.4;
constexpr double kNullTolFt = 0.005;
constexpr double kNullTolDeg = 0.02;
// The commanded motion's reference waits while the arm lags it by more
// than this (a joint at its rate, a singular pose), so a press moves the
// distance asked.
constexpr double kLagFt = 0.25;
constexpr double kLagDeg = 1.0;
// Given up after this long without headway (a joint at its limit, the end
// of the reach).
constexpr double kBlockedS = 1.5;
// A reference the arm has not kept up with for this long starts again from
// the arm (what it had counted beyond the arm given back to the press).
constexpr double kRebaseS = 0.3;

constexpr const char* kAxisWords[kNumHandAxes] = {"x", "y", "z", "roll", "pitch", "yaw"};

// Mode 2, the payload still in the bay: the way out comes first, so a
// translation's 0 is the way up out of the bay's, and there is no turn.
bool InTheBay(const Guidance& g) { return g.leave_bay && g.leave_bay_ft.norm() > 1e-9; }

double AxisError(const Guidance& g, int i) {
  if (InTheBay(g)) return i < 3 ? g.leave_bay_ft[i] : 0.0;
  return i < 3 ? g.offset_ft[i] : g.rotation_deg[i - 3];
}

}  // namespace

std::optional<Eigen::Vector3d> TurnInFlight(const HandStatus& h, const Guidance& g) {
  if (h.automatic & kAutoSquareUp) return std::nullopt;
  Eigen::Vector3d turn = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    turn[i] = h.pending[kRhcRoll + i];
    if (h.automatic & (1u << (kRhcRoll + i))) turn[i] = g.rotation_deg[i];
  }
  if (turn.isZero()) return std::nullopt;
  return turn;
}

HandControllers::HandControllers(const LabConfig& config, const Bindings& bindings)
    : config_(config),
      b_(bindings),
      geometry_(MakeGuidanceGeometry(config)),
      limits_(LimitsFromConfig(config, 0.0)),
      target_(wire::InitialInputs(config.inputs)),
      out_(target_) {
  for (int i = 0; i < kNumJoints; ++i) limits_.rate_deg_s[i] = bindings.max_rate[i];
  status_.mode = bindings.initial_mode;
  status_.frame = bindings.initial_frame;
  status_.scale = bindings.initial_scale;
  status_.cameras = bindings.cameras;
  if (status_.cameras.empty())
    for (int st = 1; st <= kNumCameraStations; ++st) status_.cameras.push_back(st);
  // A camera set without the first station starts on the set's first.
  if (std::find(status_.cameras.begin(), status_.cameras.end(), target_.camera_station) ==
      status_.cameras.end())
    target_.camera_station = out_.camera_station = status_.cameras.front();
  target_.crosshairs = out_.crosshairs = true;
}

void HandControllers::AddDevice(std::unique_ptr<InputDevice> device) {
  spdlog::info("device: {}", device->Describe());
  devices_.push_back(std::move(device));
  reported_gone_.push_back(false);
  device_actions_.push_back(0);
}

wire::OperatorInputs HandControllers::Step(double dt_s, const dcp_telemetry_t* telemetry) {
  DeviceCommands cmd;
  for (std::size_t i = 0; i < devices_.size(); ++i) {
    if (!devices_[i]->connected()) {
      if (!reported_gone_[i]) {
        spdlog::warn("device gone: {}", devices_[i]->Describe());
        counters_.Add(Counter::kDeviceDisconnected);
        reported_gone_[i] = true;
      }
      continue;
    }
    const int before = cmd.key_actions;
    devices_[i]->Poll(&cmd);
    device_actions_[i] += cmd.key_actions - before;
  }
  return Apply(cmd, dt_s, telemetry);
}

void HandControllers::SetInputs(const wire::OperatorInputs& in) {
  const bool crosshairs = target_.crosshairs;
  target_ = in;
  target_.reset = false;
  target_.crosshairs = crosshairs;
  out_ = target_;
  status_.pending = {};
  status_.rate = {};
  X_ref_.reset();
}

void HandControllers::PollFrozen() {
  freeze_requested_ = false;
  step_requests_ = 0;
  DeviceCommands cmd;
  for (std::size_t i = 0; i < devices_.size(); ++i) {
    if (!devices_[i]->connected()) continue;
    const int before = cmd.key_actions;
    devices_[i]->Poll(&cmd);
    device_actions_[i] += cmd.key_actions - before;
  }
  key_actions_ += cmd.key_actions;
  bool ignored = !cmd.hand_presses.empty() || !cmd.input_presses.empty();
  for (const Action& a : cmd.events) {
    if (a.kind == ActionKind::kFreeze)
      freeze_requested_ = true;
    else if (a.kind == ActionKind::kStep)
      ++step_requests_;
    else if (a.kind == ActionKind::kQuit)
      quit_ = true;
    else if (a.kind == ActionKind::kStop)
      StopAndRelease(cmd);  // nothing resumes when the session runs again
    else
      ignored = true;
  }
  if (ignored) {
    counters_.Add(Counter::kFrozenInputsIgnored);
    if (!frozen_noted_) {
      spdlog::info(
          "frozen: only freeze (to run again), step, stop and quit act; other keys do nothing");
      frozen_noted_ = true;
    }
  }
}

void HandControllers::Announce(const char* what) {
  std::string s = std::string(ControlModeName(status_.mode));
  if (status_.mode == ControlMode::kManualAugmented)
    s += ", " + std::string(CommandFrameName(status_.frame)) + " frame";
  else
    s += " (" + std::string(kAnalogInputNames[status_.joint]) + ")";
  s += ", " + std::string(RateScaleName(status_.scale));
  spdlog::info("{}: {}", what, s);
}

void HandControllers::StopAndRelease(const DeviceCommands& cmd) {
  StopMotion();
  for (int i = 0; i < kNumHandAxes; ++i)
    hand_suppressed_[i] = hand_suppressed_[i] || cmd.hand[i] != 0.0;
  for (int i = 0; i < kNumAnalogInputs; ++i)
    input_suppressed_[i] = input_suppressed_[i] || cmd.input_rate[i] != 0.0;
}

void HandControllers::FollowHeldArm(const dcp_telemetry_t& tm) {
  for (int i = 0; i < kNumJoints; ++i) target_.value[i] = tm.slave_angles_deg[i];
  X_ref_.reset();
}

// The DCP holds the arm (the command collides): a terminal's presses in
// flight end there, said so -- flown on, they would count their distance
// into the contact.
void HandControllers::CutPressesShort() {
  for (int i = 0; i < kNumHandAxes; ++i) {
    if (status_.pending[i] == 0.0) continue;
    spdlog::warn("{}: press cut short by a collision, {:.2f} {} of it not flown", kAxisWords[i],
                 std::abs(status_.pending[i]), i < 3 ? "ft" : "deg");
    status_.pending[i] = 0.0;
    counters_.Add(Counter::kIncrementsBlocked);
  }
}

void HandControllers::StopMotion() {
  status_.pending = {};
  status_.rate = {};
  status_.automatic = 0;
  for (int i = kFinger; i < kNumAnalogInputs; ++i) target_.value[i] = out_.value[i];
}

double HandControllers::Increment(int axis) const {
  const HandIncrements& k = b_.increments;
  const RateScale sc = status_.scale;
  if (status_.mode == ControlMode::kSingleJoint) {
    return sc == RateScale::kCoarse    ? k.joint_coarse_deg
           : sc == RateScale::kVernier ? k.joint_vernier_deg
                                       : k.joint_fine_deg;
  }
  if (axis < 3) {
    return sc == RateScale::kCoarse    ? k.coarse_ft
           : sc == RateScale::kVernier ? k.vernier_ft
                                       : k.fine_ft;
  }
  return sc == RateScale::kCoarse    ? k.coarse_deg
         : sc == RateScale::kVernier ? k.vernier_deg
                                     : k.fine_deg;
}

double HandControllers::FullRate(int axis) const {
  const HandRates& r = b_.rates;
  const bool coarse = status_.scale == RateScale::kCoarse;  // fine flies at vernier's rates
  if (status_.mode == ControlMode::kSingleJoint)
    return coarse ? r.joint_coarse_deg_s : r.joint_vernier_deg_s;
  if (axis < 3) return coarse ? r.coarse_ft_s : r.vernier_ft_s;
  return coarse ? r.coarse_deg_s : r.vernier_deg_s;
}

void HandControllers::HandleEvents(const DeviceCommands& cmd, const dcp_telemetry_t* tm) {
  const bool held = tm && tm->mode >= wire::DcpMode::kExtraction;
  for (const Action& a : cmd.events) {
    switch (a.kind) {
      case ActionKind::kCamera:
        SelectCamera(a.camera);
        break;
      case ActionKind::kCameraNext:
        StepCamera(+1);
        break;
      case ActionKind::kCameraPrev:
        StepCamera(-1);
        break;
      case ActionKind::kReset:
        out_.reset = true;
        StopMotion();
        break;
      case ActionKind::kOverlay:
        target_.overlay = !target_.overlay;
        break;
      case ActionKind::kCrosshairs:
        target_.crosshairs = !target_.crosshairs;
        break;
      case ActionKind::kGuidance:
        show_guidance_ = !show_guidance_;
        break;
      case ActionKind::kStop:
        StopAndRelease(cmd);
        counters_.Add(Counter::kControlStops);
        break;
      case ActionKind::kMode:
        StopMotion();
        status_.mode = status_.mode == ControlMode::kManualAugmented
                           ? ControlMode::kSingleJoint
                           : ControlMode::kManualAugmented;
        counters_.Add(Counter::kControlModeChanges);
        Announce("control mode");
        break;
      case ActionKind::kFrame: {
        StopMotion();
        int f = static_cast<int>(status_.frame) % 3 + 1;
        if (f == static_cast<int>(CommandFrame::kPayload) && !held)
          f = static_cast<int>(CommandFrame::kEndEffector);
        status_.frame = static_cast<CommandFrame>(f);
        counters_.Add(Counter::kControlFrameChanges);
        Announce("command frame");
        break;
      }
      case ActionKind::kVernier:
        StopMotion();
        status_.scale = NextRateScale(status_.scale);
        counters_.Add(Counter::kControlScaleChanges);
        Announce("rate scale");
        break;
      case ActionKind::kNull:
      case ActionKind::kSquareUp:
      case ActionKind::kUnwind:
      case ActionKind::kStow:
        StartAutomatic(a);
        break;
      case ActionKind::kJointNext:
      case ActionKind::kJointPrev:
        StopMotion();
        status_.joint = (status_.joint + (a.kind == ActionKind::kJointNext ? 1 : 5)) % 6;
        if (status_.mode == ControlMode::kSingleJoint) Announce("joint");
        break;
      case ActionKind::kQuit:
        quit_ = true;
        break;
      case ActionKind::kFreeze:
        freeze_requested_ = true;
        break;
      case ActionKind::kStep:
        ++step_requests_;
        break;
      case ActionKind::kHand:
      case ActionKind::kInput:
        break;  // not events
    }
  }
}

void HandControllers::StartAutomatic(const Action& a) {
  if (a.kind == ActionKind::kStow && (dcp_mode_ != wire::DcpMode::kAcquisition || X_S2P_)) {
    // With the payload held the arm's way back would carry it through the
    // bay's sill and the orbiter (docs/operator.md "Stowing the arm").
    counters_.Add(Counter::kIncrementsBlocked);
    spdlog::warn("stow: only in Mode 1, the payload left in the bay (reset first)");
    return;
  }
  if (a.kind == ActionKind::kUnwind || a.kind == ActionKind::kStow) {
    // docs/operator.md "Nulling an axis, squaring up, unwinding": in either
    // control mode; every other motion stops.
    const bool stow = a.kind == ActionKind::kStow;
    StopMotion();
    status_.automatic = stow ? kAutoStow : kAutoUnwind;
    auto_best_.fill(1e30);
    auto_stalled_s_.fill(0.0);
    counters_.Add(stow ? Counter::kControlStows : Counter::kControlUnwinds);
    spdlog::info(stow ? "stow: every joint back to where the session started it"
                      : "unwind: the wrist's pitch, yaw and roll to the middle of their travel");
    return;
  }
  if (status_.mode == ControlMode::kSingleJoint) {
    counters_.Add(Counter::kSingleJointPressesIgnored);
    spdlog::info("{}: manual augmented only (m)", ActionName(a));
    return;
  }
  status_.automatic &= ~(kAutoUnwind | kAutoStow);
  if (a.kind == ActionKind::kSquareUp) {
    for (int i = kRhcRoll; i <= kRhcYaw; ++i) {
      status_.pending[i] = 0.0;
      status_.automatic &= ~(1u << i);
    }
    status_.automatic |= kAutoSquareUp;
    counters_.Add(Counter::kControlSquareUps);
    spdlog::info("square up: the whole turn the guidance shows, in one rotation");
  } else {
    status_.pending[a.index] = 0.0;
    if (a.index >= kRhcRoll) status_.automatic &= ~kAutoSquareUp;
    status_.automatic |= 1u << a.index;
    counters_.Add(Counter::kControlNulls);
    spdlog::info("null {}: flying it to the guidance's 0", kAxisWords[a.index]);
  }
  auto_best_.fill(1e30);
  auto_stalled_s_.fill(0.0);
  auto_in_bay_ = InTheBay(ComputeGuidance(geometry_, CommandedArmState(), FlownFrame()));
}

void HandControllers::TakeAxis(int i) {
  status_.automatic &= ~(1u << i);
  if (i >= kRhcRoll) status_.automatic &= ~kAutoSquareUp;
  if (status_.automatic & (kAutoUnwind | kAutoStow))
    spdlog::info("{}: stopped by a hand-controller key, where it is",
                 status_.automatic & kAutoStow ? "stow" : "unwind");
  status_.automatic &= ~(kAutoUnwind | kAutoStow);
}

ArmState HandControllers::CommandedArmState() const {
  JointAngles q{};
  for (int i = 0; i < kNumJoints; ++i) q[i] = target_.value[i];
  ArmState s;
  s.mode = dcp_mode_;
  s.X_RS2 = ForwardPose(config_.arm, q, target_.value[kShoulderHeight]);
  if (X_S2P_) {
    s.X_RP = s.X_RS2 * *X_S2P_;
    s.bay_clearance_ft = PayloadLowestZ(geometry_, s.X_RP);  // as commanded, for the way out
  } else {
    s.mode = wire::ModeNumber(wire::DcpMode::kAcquisition);
    s.X_RP = X_RP_;
  }
  return s;
}

CommandFrame HandControllers::FlownFrame() const {
  return status_.frame == CommandFrame::kPayload && !X_S2P_ ? CommandFrame::kEndEffector
                                                            : status_.frame;
}

void HandControllers::AutomaticRates(std::array<double, kNumHandAxes>* rate, double dt_s) {
  std::uint32_t& a = status_.automatic;
  if ((a & ~(kAutoUnwind | kAutoStow)) == 0) return;
  const Guidance g = ComputeGuidance(geometry_, CommandedArmState(), FlownFrame());
  if (auto_in_bay_ && !InTheBay(g)) {
    // Nulls begun in the bay flew the way out's 0: out, they are there
    // (the port's 0 is another press).
    a &= ~0x3fu;
    auto_in_bay_ = false;
    spdlog::info("null: out of the bay ({:.0f} ft clear): there", kLeaveBayMarginFt);
  }
  // Each automatic motion's error (index 6: the square-up's whole angle);
  // one that has arrived ends, one without headway for kBlockedS is given up.
  for (int k = 0; k <= kNumHandAxes; ++k) {
    const std::uint32_t bit = k < kNumHandAxes ? 1u << k : kAutoSquareUp;
    if (!(a & bit)) continue;
    if (k == kNumHandAxes && InTheBay(g)) {
      a &= ~bit;
      counters_.Add(Counter::kIncrementsBlocked);
      spdlog::warn("square up: the payload is still in the bay; lift it out first");
      continue;
    }
    const double e = k < kNumHandAxes ? AxisError(g, k) : g.angle_deg;
    const bool linear = k < 3;
    const std::string what = k < kNumHandAxes ? std::string("null ") + kAxisWords[k] : "square up";
    if (std::abs(e) <= (linear ? kNullTolFt : kNullTolDeg)) {
      a &= ~bit;
      spdlog::info("{}: there ({:.3f} {})", what, std::abs(e), linear ? "ft" : "deg");
      continue;
    }
    auto_stalled_s_[k] = std::abs(e) < auto_best_[k] - 1e-4 ? 0.0 : auto_stalled_s_[k] + dt_s;
    auto_best_[k] = std::min(auto_best_[k], std::abs(e));
    if (auto_stalled_s_[k] > kBlockedS) {
      a &= ~bit;
      counters_.Add(Counter::kIncrementsBlocked);
      spdlog::warn(
          "{}: no headway for {:.1f} s (a joint at its limit or its rate, the end of the reach, "
          "or a contact): stopped {:.3f} {} short",
          what, kBlockedS, std::abs(e), linear ? "ft" : "deg");
      continue;
    }
    if (k < kNumHandAxes) {
      const double full = FullRate(k);
      (*rate)[k] += std::clamp(e / kNullTimeS, -full, full);
    } else {
      const double w = std::min(FullRate(kRhcRoll), g.angle_deg / kNullTimeS);
      for (int i = 0; i < 3; ++i) (*rate)[kRhcRoll + i] += g.rotation_deg[i] / g.angle_deg * w;
    }
  }
}

void HandControllers::FlyJoints(std::uint32_t bit, double dt_s) {
  const bool stow = bit == kAutoStow;
  const char* what = stow ? "stow" : "unwind";
  JointAngles q{}, goal{}, rate{};
  for (int i = 0; i < kNumJoints; ++i) {
    q[i] = goal[i] = target_.value[i];
    rate[i] = b_.max_rate[i];
    if (stow) goal[i] = config_.inputs[i].initial;  // where the session started it
  }
  if (!stow)
    for (int i = 3; i < 6; ++i) goal[i] = 0.5 * (limits_.min_deg[i] + limits_.max_deg[i]);
  const bool there = StepJointsToward(&q, goal, rate, dt_s);
  // No headway (held by a contact: the hand controllers carry on from the
  // pose the DCP holds) for kBlockedS: given up, and said so.
  double left = 0.0;
  for (int i = 0; i < kNumJoints; ++i) left += std::abs(goal[i] - q[i]);
  auto_stalled_s_[kNumHandAxes] =
      left < auto_best_[kNumHandAxes] - 1e-3 ? 0.0 : auto_stalled_s_[kNumHandAxes] + dt_s;
  auto_best_[kNumHandAxes] = std::min(auto_best_[kNumHandAxes], left);
  if (!there && auto_stalled_s_[kNumHandAxes] > kBlockedS) {
    status_.automatic &= ~bit;
    counters_.Add(Counter::kIncrementsBlocked);
    spdlog::warn("{}: no headway for {:.1f} s (a contact holds the arm?): stopped", what,
                 kBlockedS);
    return;
  }
  for (int i = 0; i < kNumJoints; ++i) target_.value[i] = q[i];
  X_ref_.reset();
  status_.achieved = {};
  status_.singular = false;
  status_.rate_limited = false;
  if (there) {
    status_.automatic &= ~bit;
    if (stow)
      spdlog::info("stow: there (joints {:+.1f} {:+.1f} {:+.1f} {:+.1f} {:+.1f} {:+.1f} deg)", q[0],
                   q[1], q[2], q[3], q[4], q[5]);
    else
      spdlog::info("unwind: there (wrist pitch {:+.1f}, yaw {:+.1f}, roll {:+.1f} deg)", q[3], q[4],
                   q[5]);
  }
  ReportLimits(0);
}

void HandControllers::ReportNearLimits() {
  status_.near_limit = 0;
  for (int i = 3; i < 6; ++i) {  // the wrist's joints (docs/operator.md "Joint limits")
    const double q = target_.value[i];
    const bool near =
        q < limits_.min_deg[i] + kNearLimitDeg || q > limits_.max_deg[i] - kNearLimitDeg;
    const std::uint32_t bit = 1u << i;
    if (near) status_.near_limit |= bit;
    if (near && !(near_reported_ & bit)) {
      counters_.Add(Counter::kJointNearLimit);
      spdlog::warn(
          "{} at {:+.1f} deg, within {:.0f} deg of its limit (travel {:+.1f} .. {:+.1f}): "
          "the unwind key flies the wrist back to the middle of its travel",
          kAnalogInputNames[i], q, kNearLimitDeg, limits_.min_deg[i], limits_.max_deg[i]);
    }
    // Reported again only after it has been well clear (2 deg of hysteresis).
    const bool clear =
        q > limits_.min_deg[i] + kNearLimitDeg + 2 && q < limits_.max_deg[i] - kNearLimitDeg - 2;
    if (near)
      near_reported_ |= bit;
    else if (clear)
      near_reported_ &= ~bit;
  }
}

void HandControllers::SelectCamera(int st) {
  const auto& set = status_.cameras;
  if (std::find(set.begin(), set.end(), st) == set.end()) {
    status_.camera_refused = st;
    counters_.Add(Counter::kCameraRefused);
    spdlog::info("camera {}: not in this session's camera set", st);
    return;
  }
  status_.camera_refused = 0;
  target_.camera_station = st;
}

void HandControllers::StepCamera(int step) {
  const auto& set = status_.cameras;
  const auto at = std::find(set.begin(), set.end(), target_.camera_station);
  const int n = static_cast<int>(set.size());
  const int i = at == set.end() ? 0 : static_cast<int>(at - set.begin());
  SelectCamera(set[static_cast<std::size_t>(((i + step) % n + n) % n)]);
}

void HandControllers::AddPress(const struct Press& p) {
  if (status_.mode == ControlMode::kSingleJoint && p.index != kThcX) {
    counters_.Add(Counter::kSingleJointPressesIgnored);
    return;
  }
  // One increment a press, flown at the scale's rate. A press in the
  // direction the axis is still moving is merged into that motion (it
  // never runs on more than one increment from now); one the other way
  // stops it.
  TakeAxis(p.index);
  pending_best_[p.index] = 1e30;  // a press: its headway counted afresh
  stalled_s_[p.index] = 0.0;
  double& pending = status_.pending[p.index];
  const double inc = Increment(p.index);
  // "From now" is from where the arm is: the reference may be ahead of it
  // by what it has counted and the arm not yet flown (lag_F_).
  if (pending * p.sign > 0)
    pending = p.sign * std::max(std::abs(pending), inc - std::max(0.0, p.sign * lag_F_[p.index]));
  else if (pending * p.sign < 0)
    pending = 0.0;
  else
    pending = p.sign * inc;
}

std::array<double, kNumHandAxes> HandControllers::CommandedRates(const DeviceCommands& cmd,
                                                                 double dt_s) {
  std::array<double, kNumHandAxes> rate{};
  for (int i = 0; i < kNumHandAxes; ++i) {
    const double full = FullRate(i);
    if (cmd.hand[i] == 0.0) hand_suppressed_[i] = false;  // let go since the stop: it acts again
    double r = hand_suppressed_[i] ? 0.0 : std::clamp(cmd.hand[i], -1.0, 1.0) * full;
    if (r != 0.0) TakeAxis(i);
    const double pending = status_.pending[i];
    if (pending != 0.0) r += std::copysign(std::min(full, std::abs(pending) / dt_s), pending);
    rate[i] = std::clamp(r, -full, full);
  }
  if (status_.mode == ControlMode::kSingleJoint) {
    for (int i = 1; i < kNumHandAxes; ++i) rate[i] = 0.0;
  }
  return rate;
}

void HandControllers::FlyManualAugmented(const std::array<double, kNumHandAxes>& rate,
                                         double dt_s) {
  JointAngles q{};
  for (int i = 0; i < kNumJoints; ++i) q[i] = target_.value[i];
  const double h = target_.value[kShoulderHeight];
  const ArmState s = CommandedArmState();
  const Eigen::Matrix3d R_RF = CommandAxes(geometry_, FlownFrame(), s);
  const Eigen::Vector3d por = PointOfResolution(geometry_, s);
  // The motion is flown closed loop on a reference pose that moves exactly
  // as commanded (about the point of resolution), so the rate's first-order
  // steps and the elbow's self-motion do not drift; released, nothing moves.
  // The reference waits while the arm lags it (a joint at its rate, a
  // singular pose): what it moves is what the arm will have moved.
  // (Only while an increment is counted off: what flies by itself aims at
  // the guidance's 0 afresh every frame and needs no count.)
  lag_F_ = {};
  double advance = 1.0;
  const bool counting = std::any_of(status_.pending.begin(), status_.pending.end(),
                                    [](double p) { return p != 0.0; });
  if (X_ref_ && counting) {
    const Eigen::Vector3d lag_R = *X_ref_ * por - s.X_RS2 * por;
    const Eigen::Vector3d turn_R = RotationVector(X_ref_->linear() * s.X_RS2.linear().transpose());
    const Eigen::Vector3d lag_F = R_RF.transpose() * lag_R;
    const Eigen::Vector3d turn_F = R_RF.transpose() * turn_R / kDeg;
    lag_F_ = {lag_F.x(), lag_F.y(), lag_F.z(), turn_F.x(), turn_F.y(), turn_F.z()};
    if (lag_R.norm() > kLagFt || turn_R.norm() > kLagDeg * kDeg) advance = 0.0;
    waited_s_ = advance == 0.0 ? waited_s_ + dt_s : 0.0;
    if (waited_s_ > kRebaseS) {
      // The arm cannot reach the reference (it moves, but not that way):
      // start the reference again from where the arm is, and give the
      // presses back what it had counted beyond the arm.
      for (int i = 0; i < kNumHandAxes; ++i) {
        double& p = status_.pending[i];
        const double back = i < 3 ? lag_F[i] : turn_F[i - 3];
        if (p * back > 0) p += back;
      }
      X_ref_ = s.X_RS2;
      lag_F_ = {};
      waited_s_ = 0.0;
      advance = 1.0;
    }
  }
  const Eigen::Vector3d v_R =
      advance * (R_RF * Eigen::Vector3d(rate[kThcX], rate[kThcY], rate[kThcZ]));
  const Eigen::Vector3d w_R =
      advance * (R_RF * Eigen::Vector3d(rate[kRhcRoll], rate[kRhcPitch], rate[kRhcYaw]) * kDeg);
  const bool commanded = std::any_of(rate.begin(), rate.end(), [](double r) { return r != 0.0; });
  if (!commanded) {
    X_ref_.reset();
  } else {
    if (!X_ref_) X_ref_ = s.X_RS2;
    const Eigen::Vector3d Q_ref = *X_ref_ * por + v_R * dt_s;
    X_ref_->linear() =
        Eigen::AngleAxisd(w_R.norm() * dt_s,
                          w_R.norm() > 0 ? w_R.normalized() : Eigen::Vector3d::UnitX())
            .toRotationMatrix() *
        X_ref_->linear();
    X_ref_->translation() = Q_ref - X_ref_->linear() * por;
  }
  Eigen::Vector3d v_fly = v_R, w_fly = w_R;
  if (X_ref_) {
    // Where the reference will be after this frame, less where the arm is.
    constexpr double kCatchUpS = 0.2;
    const Eigen::Vector3d e_v = *X_ref_ * por - s.X_RS2 * por - v_R * dt_s;
    const Eigen::Vector3d e_w =
        RotationVector(X_ref_->linear() * s.X_RS2.linear().transpose()) - w_R * dt_s;
    if (e_v.norm() > 1.5 || e_w.norm() > 10.0 * kDeg) {
      X_ref_ = s.X_RS2;  // the arm cannot follow (a limit, a singular pose): start again from where
                         // it is
    } else {
      v_fly += e_v / kCatchUpS;
      w_fly += e_w / kCatchUpS;
    }
  }
  const RateResult r = ResolveRate(config_.arm, limits_, q, h, por, v_fly, w_fly, dt_s);
  for (int i = 0; i < kNumJoints; ++i) target_.value[i] = r.q_deg[i];
  const Eigen::Vector3d v_done = R_RF.transpose() * r.achieved.head<3>();
  const Eigen::Vector3d w_done = R_RF.transpose() * r.achieved.tail<3>() / kDeg;
  status_.achieved = {v_done.x(), v_done.y(), v_done.z(), w_done.x(), w_done.y(), w_done.z()};
  // The increments are taken off as the reference advances.
  std::array<double, kNumHandAxes> moved{};
  for (int i = 0; i < kNumHandAxes; ++i) moved[i] = advance * rate[i];
  const std::array<double, kNumHandAxes> before = status_.pending;
  ConsumePending(moved, dt_s);
  if (counting && X_ref_) FinishPresses(before, ForwardPose(config_.arm, r.q_deg, h), por, R_RF);
  status_.singular = r.singular;
  status_.rate_limited = r.rate_limited || advance == 0.0;
  status_.sigma_min_ft = r.sigma_min_ft;
  ReportLimits(r.at_limit);
}

// The reference has flown the presses' whole distance: what the arm still
// lags it by along the axes pressed is given back to them, from where the
// arm is, so a press ends where it was asked to even where the arm could
// not keep up (the straight arm).
void HandControllers::FinishPresses(const std::array<double, kNumHandAxes>& before,
                                    const Eigen::Isometry3d& X_RS2_next, const Eigen::Vector3d& por,
                                    const Eigen::Matrix3d& R_RF) {
  if (std::any_of(status_.pending.begin(), status_.pending.end(),
                  [](double p) { return p != 0.0; }))
    return;
  const Eigen::Vector3d lag_F = R_RF.transpose() * (*X_ref_ * por - X_RS2_next * por);
  const Eigen::Vector3d turn_F =
      R_RF.transpose() * RotationVector(X_ref_->linear() * X_RS2_next.linear().transpose()) / kDeg;
  bool again = false;
  for (int i = 0; i < kNumHandAxes; ++i) {
    const double back = i < 3 ? lag_F[i] : turn_F[i - 3];
    if (before[i] * back > 0 && std::abs(back) > (i < 3 ? kNullTolFt : kNullTolDeg)) {
      status_.pending[i] = back;
      again = true;
    }
  }
  if (again) X_ref_ = X_RS2_next;
}

void HandControllers::ConsumePending(const std::array<double, kNumHandAxes>& achieved,
                                     double dt_s) {
  // An increment is done when the motion flown has moved it (not when it
  // was asked for): near a singular pose the first of it may go slowly. One
  // that makes no headway for kBlockedS (a joint at its limit, the arm at
  // the end of its reach) is given up, and said so.
  for (int i = 0; i < kNumHandAxes; ++i) {
    double& pending = status_.pending[i];
    if (pending == 0.0) {
      stalled_s_[i] = 0.0;
      pending_best_[i] = 1e30;
      continue;
    }
    const double along = std::copysign(1.0, pending) * achieved[i];  // > 0: toward completing it
    if (along > 0) pending -= std::copysign(std::min(std::abs(pending), along * dt_s), pending);
    if (std::abs(pending) < 1e-3 * Increment(i)) pending = 0.0;  // done, to a thousandth
    // No headway: what is left of it has not shrunk (by 1e-4) for kBlockedS.
    if (std::abs(pending) < pending_best_[i] - 1e-4) {
      pending_best_[i] = std::abs(pending);
      stalled_s_[i] = 0.0;
    } else {
      stalled_s_[i] += dt_s;
    }
    if (stalled_s_[i] > kBlockedS) {
      pending = 0.0;
      stalled_s_[i] = 0.0;
      counters_.Add(Counter::kIncrementsBlocked);
      spdlog::warn(
          "{}: the arm cannot move that way (at a joint limit or the end of its reach): motion "
          "stopped",
          kHandAxisNames[i]);
    }
  }
}

void HandControllers::FlySingleJoint(double rate_deg_s, double dt_s) {
  const int j = status_.joint;
  const double rate = std::clamp(rate_deg_s, -b_.max_rate[j], b_.max_rate[j]);
  double q = target_.value[j] + rate * dt_s;
  std::uint32_t at_limit = 0;
  if (rate > 0 && q > limits_.max_deg[j]) {
    q = std::max(target_.value[j], limits_.max_deg[j]);
    at_limit = 1u << j;
  } else if (rate < 0 && q < limits_.min_deg[j]) {
    q = std::min(target_.value[j], limits_.min_deg[j]);
    at_limit = 1u << j;
  }
  status_.rate_limited = std::abs(rate) < std::abs(rate_deg_s);
  status_.achieved = {(q - target_.value[j]) / dt_s, 0, 0, 0, 0, 0};
  ConsumePending(status_.achieved, dt_s);
  target_.value[j] = q;
  status_.singular = false;
  ReportLimits(at_limit);
}

void HandControllers::ReportLimits(std::uint32_t at_limit) {
  status_.at_limit = at_limit;
  for (int i = 0; i < kNumJoints; ++i) {
    const std::uint32_t bit = 1u << i;
    const double q = target_.value[i];
    const bool on_limit = q <= limits_.min_deg[i] + 1e-6 || q >= limits_.max_deg[i] - 1e-6;
    if ((at_limit & bit) && !(limit_reported_ & bit)) {
      counters_.Add(JointLimitCounter(i));
      spdlog::warn("joint limit: {} stopped at {:+.1f} deg (its travel {:+.1f} .. {:+.1f})",
                   kAnalogInputNames[i], q, limits_.min_deg[i], limits_.max_deg[i]);
      limit_reported_ |= bit;
    } else if (!on_limit) {
      limit_reported_ &= ~bit;
    }
  }
}

void HandControllers::DirectInputs(const DeviceCommands& cmd, double dt_s) {
  const InputCalibrations& cal = config_.inputs;
  for (const struct Press& p : cmd.input_presses) {
    // As the hand controllers' increments: one step ahead of the output at
    // most; a press the other way stops it.
    double& t = target_.value[p.index];
    const double o = out_.value[p.index], moving = t - o;
    if (moving * p.sign > 1e-12)
      t = o + p.sign * std::max(std::abs(moving), b_.key_step[p.index]);
    else if (moving * p.sign < -1e-12)
      t = o;
    else
      t = o + p.sign * b_.key_step[p.index];
    // A press asks for a step, not a place: it moves to the end of the
    // range at most, which is no command out of range (nothing clamped).
    t = std::clamp(t, cal[p.index].min, cal[p.index].max);
  }
  for (int i = kFinger; i < kNumAnalogInputs; ++i) {
    const double lim = b_.max_rate[i] * dt_s;
    if (cmd.input_rate[i] == 0.0) input_suppressed_[i] = false;
    const double rate = input_suppressed_[i] ? 0.0 : std::clamp(cmd.input_rate[i], -1.0, 1.0);
    double t = target_.value[i] + rate * lim;
    // Clamping to the calibrated range, counted and reported once per
    // excursion (a lever held against its stop is one excursion).
    const double c = std::clamp(t, cal[i].min, cal[i].max);
    if (c != t && !clamping_[i]) {
      counters_.Add(ClampedCounter(i));
      const std::string unit = cal[i].unit == "1" ? std::string() : " " + cal[i].unit;
      spdlog::warn("{} command held against the end of its range [{}, {}]{}: clamped",
                   kAnalogInputNames[i], cal[i].min, cal[i].max, unit);
    }
    clamping_[i] = c != t;
    target_.value[i] = c;
    out_.value[i] += std::clamp(target_.value[i] - out_.value[i], -lim, lim);
  }
}

wire::OperatorInputs HandControllers::Apply(const DeviceCommands& cmd, double dt_s,
                                            const dcp_telemetry_t* tm) {
  out_.reset = false;
  freeze_requested_ = false;
  step_requests_ = 0;
  frozen_noted_ = false;
  key_actions_ += cmd.key_actions;
  if (tm) {
    if (tm->mode == wire::DcpMode::kAcquisition && dcp_mode_ != wire::DcpMode::kAcquisition &&
        status_.frame == CommandFrame::kPayload) {
      status_.frame = CommandFrame::kEndEffector;  // reset: no payload held any more
      Announce("command frame");
    }
    dcp_mode_ = tm->mode;
    X_RP_ = TelemetryPose(tm->p_RoPo_R_ft, tm->R_RP);
    if (tm->mode >= wire::DcpMode::kExtraction)
      X_S2P_ = TelemetryPose(tm->p_RoA_R_ft, tm->R_RS2).inverse() * X_RP_;
    else
      X_S2P_.reset();
    // The DCP holds the arm (the command collides): carry on from the pose
    // the slave holds, so the next command away from the contact relieves
    // it. Docked, the port holds the payload and the arm until the finger
    // opens: nothing the hand controllers do moves it meanwhile.
    status_.held_at_port = tm->docked && !tm->released;
    if ((tm->held && tm->slave_collisions == 0) || status_.held_at_port) FollowHeldArm(*tm);
    if (tm->held && !status_.held_at_port) CutPressesShort();
  }
  HandleEvents(cmd, tm);
  if (status_.held_at_port) {
    // Held at the port: the arm's motions are not flown (nor kept for
    // later); the finger and the other inputs are.
    status_.pending = {};
    status_.rate = {};
    status_.automatic = 0;
  } else {
    for (const struct Press& p : cmd.hand_presses) AddPress(p);
    auto rate = CommandedRates(cmd, dt_s);
    if (status_.mode == ControlMode::kManualAugmented) AutomaticRates(&rate, dt_s);
    status_.rate = rate;
    if (status_.automatic & (kAutoUnwind | kAutoStow))
      FlyJoints(status_.automatic & (kAutoUnwind | kAutoStow), dt_s);
    else if (status_.mode == ControlMode::kManualAugmented)
      FlyManualAugmented(rate, dt_s);
    else
      FlySingleJoint(rate[kThcX], dt_s);
  }
  ReportNearLimits();
  DirectInputs(cmd, dt_s);
  for (int i = 0; i < kNumJoints; ++i) out_.value[i] = target_.value[i];
  out_.camera_station = target_.camera_station;
  out_.overlay = target_.overlay;
  out_.crosshairs = target_.crosshairs;
  return out_;
}

}  // namespace rms::operator_station
