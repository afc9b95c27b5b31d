#pragma once
// Flying by hand (docs/operator.md "Control modes", "Devices",
// "Conditioning"): the devices' commands, conditioned as the hand
// controllers' electronics did, turned into the six master-arm angles and
// the other inputs of the input block, each frame.
//
//  - Manual augmented (resolved rate): the translational hand controller
//    (THC) commands the point of resolution's velocity, the rotational one
//    (RHC) the end effector's angular velocity, in the command frame (end
//    effector, orbiter, or payload once held); ResolveRate (arm_motion.h)
//    turns them into the angles.
//  - Single joint: the THC's x drives the selected joint at a rate.
//  - Coarse and vernier rate scales; a terminal's presses are fixed
//    increments flown at the scale's rate, a press that arrives while its
//    axis is still moving merged into that motion (never queued); stop
//    halts everything at once.
//  - The direct inputs (finger, shoulder height, camera pan / tilt / zoom)
//    follow their targets at no more than their max rates; a target beyond
//    its calibrated range is clamped, counted and reported once.
//  - Joints stopped at their limits, reported once per excursion.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rms/base/config.h"
#include "rms/base/counters.h"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/operator_station/arm_motion.h"
#include "rms/operator_station/bindings.h"
#include "rms/operator_station/control_modes.h"
#include "rms/operator_station/devices.h"
#include "rms/operator_station/guidance.h"
#include "rms/wire/input_block.h"

namespace rms::operator_station {

// What flies by itself (HandStatus::automatic; docs/operator.md "Nulling
// an axis, squaring up, unwinding"): bit i (HandAxis) that axis flown to
// its guidance's 0; and these three.
inline constexpr std::uint32_t kAutoSquareUp = 64;  // the whole turn, in one rotation
inline constexpr std::uint32_t kAutoUnwind = 128;   // the wrist to the middle of its travel
inline constexpr std::uint32_t kAutoStow = 256;     // every joint to its start (Mode 1)
// A joint this near a limit of its travel is warned of.
inline constexpr double kNearLimitDeg = 10.0;

// What the hand controllers did this frame (the status screen, the
// operator state message).
struct HandStatus {
  ControlMode mode = ControlMode::kManualAugmented;
  CommandFrame frame = CommandFrame::kEndEffector;
  RateScale scale = RateScale::kCoarse;
  int joint = 0;                                // single joint: which
  std::array<double, kNumHandAxes> rate{};      // commanded: ft/s, deg/s (single joint: [0] deg/s)
  std::array<double, kNumHandAxes> achieved{};  // what the arm did of it this frame
  std::array<double, kNumHandAxes> pending{};   // a terminal's increments still to fly: ft, deg
  std::uint32_t automatic = 0;                  // kAuto* and bit i: axis i nulled
  std::uint32_t at_limit = 0;                   // joints held at a limit
  std::uint32_t near_limit = 0;                 // joints within kNearLimitDeg of a limit
  bool singular = false;
  bool rate_limited = false;  // slower than commanded: a joint at its rate
  bool held_at_port =
      false;  // docked: the CAE holds the payload and the arm until the finger opens
  double sigma_min_ft = 0.0;
  // The bindings' camera set (docs/operator.md "Bindings"), and the last
  // station asked for outside it (0: none since the last selection that
  // was taken), for the status screen.
  std::vector<int> cameras;
  int camera_refused = 0;
};

// The turn in flight (command axes, deg) for the clearance over it
// (docs/operator.md "Clearance in Mode 3"): the rotation increments still
// to go and the nulled rotation axes' guidance; nothing when neither (the
// guidance's whole turn is then the one judged, as for a square-up).
std::optional<Eigen::Vector3d> TurnInFlight(const HandStatus& h, const Guidance& g);

class HandControllers {
 public:
  HandControllers(const LabConfig& config, const Bindings& bindings);
  void AddDevice(std::unique_ptr<InputDevice> device);
  const std::vector<std::unique_ptr<InputDevice>>& devices() const { return devices_; }

  // One frame of dt seconds: polls every device and returns the inputs.
  // telemetry: the DCP's newest (the mode, the payload held), or null.
  wire::OperatorInputs Step(double dt_s, const dcp_telemetry_t* telemetry);
  // Applies one frame's commands (Step does this after polling; tests too).
  wire::OperatorInputs Apply(const DeviceCommands& cmd, double dt_s,
                             const dcp_telemetry_t* telemetry);

  bool quit() const { return quit_; }
  // Freeze / step asked for this frame (the station sends them on RMS_CONTROL).
  bool freeze_requested() const { return freeze_requested_; }
  // Step presses this frame (each is one frame while frozen).
  int step_requests() const { return step_requests_; }
  // While frozen only freeze, step, stop and quit act: everything else is
  // read and dropped, counted ("frozen.inputs_ignored") and said once.
  void PollFrozen();
  // Carry on from these inputs (a restored checkpoint, a restart): the
  // command, targets and outputs; every motion in progress stops.
  void SetInputs(const wire::OperatorInputs& in);
  const wire::OperatorInputs& target() const { return target_; }
  const HandStatus& status() const { return status_; }
  bool show_guidance() const { return show_guidance_; }
  bool crosshairs() const { return target_.crosshairs; }
  long key_actions() const { return key_actions_; }
  // Each device's presses so far, in the order added, and its description.
  const std::vector<long>& device_actions() const { return device_actions_; }
  std::string device_name(std::size_t i) const { return devices_[i]->Describe(); }
  // "clamped.NAME", "joint_limit.NAME", "control.mode_changes",
  // "control.frame_changes", "control.scale_changes", "device.disconnected", ...
  const Counters& counters() const { return counters_; }

 private:
  void HandleEvents(const DeviceCommands& cmd, const dcp_telemetry_t* telemetry);
  // Selects camera station `st` if the camera set has it; else refuses it
  // (counted, shown on the status screen). step +1 / -1: the set's next or
  // previous station from the one shown.
  void SelectCamera(int st);
  void StepCamera(int step);
  void AddPress(const Press& p);
  std::array<double, kNumHandAxes> CommandedRates(const DeviceCommands& cmd, double dt_s);
  void FlyManualAugmented(const std::array<double, kNumHandAxes>& rate, double dt_s);
  // The arm as commanded now (the angles sent, the payload held as the
  // telemetry last showed it), for guidance flown by itself.
  ArmState CommandedArmState() const;
  // The automatic motions' rates this frame (nulled axes, the square-up),
  // added to `rate`; an automatic motion that has arrived ends, said so.
  void AutomaticRates(std::array<double, kNumHandAxes>* rate, double dt_s);
  void StartAutomatic(const Action& a);
  // The command frame flown: the payload's falls back to the end
  // effector's until a payload is held.
  CommandFrame FlownFrame() const;
  // The unwind (the wrist's joints toward the middle of their travel) or
  // the stow (every joint toward where the session started it): flown in
  // the joints, all arriving together; `bit` is kAutoUnwind or kAutoStow.
  void FlyJoints(std::uint32_t bit, double dt_s);
  // A person takes axis i (a press, a stick, a held key): what flies it by
  // itself stops.
  void TakeAxis(int i);
  void ReportNearLimits();
  void FlySingleJoint(double rate_deg_s, double dt_s);
  // Takes what the motion flown did (ft/s, deg/s, command axes: the
  // reference's advance) off the increments in progress.
  void ConsumePending(const std::array<double, kNumHandAxes>& done, double dt_s);
  void FinishPresses(const std::array<double, kNumHandAxes>& before,
                     const Eigen::Isometry3d& X_RS2_next, const Eigen::Vector3d& por,
                     const Eigen::Matrix3d& R_RF);
  void ReportLimits(std::uint32_t at_limit);
  void DirectInputs(const DeviceCommands& cmd, double dt_s);
  void StopMotion();
  // Stop, and let go of every axis and input `cmd` holds until it is released.
  void StopAndRelease(const DeviceCommands& cmd);
  // The DCP holds the arm (a collision, or docked at the port): carry on
  // from the pose it holds.
  void FollowHeldArm(const dcp_telemetry_t& tm);
  void CutPressesShort();
  void Announce(const char* what);
  double Increment(int axis) const;
  double FullRate(int axis) const;

  const LabConfig& config_;
  const Bindings& b_;
  GuidanceGeometry geometry_;
  JointLimits limits_;
  std::vector<std::unique_ptr<InputDevice>> devices_;
  std::vector<bool> reported_gone_;
  wire::OperatorInputs target_, out_;
  std::array<bool, kNumAnalogInputs> clamping_{};
  std::uint32_t limit_reported_ = 0;
  std::array<double, kNumHandAxes> stalled_s_{};  // how long each increment has made no headway
  std::array<double, kNumHandAxes> pending_best_ = {
      1e30, 1e30, 1e30, 1e30, 1e30, 1e30};  // the least left of each increment so far
  double waited_s_ = 0.0;
  bool auto_in_bay_ = false;  // the nulls in flight began with the payload in the bay
  // The reference ahead of the arm (command axes: ft, deg), this frame.
  std::array<double, kNumHandAxes> lag_F_{};  // how long the reference has waited for the arm
  HandStatus status_;
  // The DCP's state the frames need: the mode and, once held, the payload
  // in System Two (from the telemetry).
  int dcp_mode_ = 1;
  std::optional<Eigen::Isometry3d> X_S2P_;
  Eigen::Isometry3d X_RP_ = Eigen::Isometry3d::Identity();  // the payload, as last shown
  std::uint32_t near_reported_ = 0;
  // Each automatic motion's least error so far and how long it has made no
  // headway (index 6: the square-up).
  std::array<double, kNumHandAxes + 1> auto_best_{};
  std::array<double, kNumHandAxes + 1> auto_stalled_s_{};
  // Manual augmented: the pose the commanded motion has reached, flown to
  // closed loop while a motion is commanded (none while still).
  std::optional<Eigen::Isometry3d> X_ref_;
  Counters counters_;
  long key_actions_ = 0;
  std::vector<long> device_actions_;
  bool quit_ = false;
  bool freeze_requested_ = false;
  int step_requests_ = 0;
  // Stop lets go of what is held: a held key, a stick, a button acts again
  // only once it has been let go (a key up, the stick back to centre).
  std::array<bool, kNumHandAxes> hand_suppressed_{};
  std::array<bool, kNumAnalogInputs> input_suppressed_{};
  bool frozen_noted_ = false;
  bool show_guidance_ = true;
};

}  // namespace rms::operator_station
