#pragma once
// The autopilot (docs/operator.md, "The autopilot"): flies the whole task
// from the initial state -- acquire the payload, extract it from the cargo
// bay, manoeuvre it and dock it to the CAE -- publishing the same input
// block an operator would. It closes the loop on the DCP's telemetry
// (RMS_DCP_TELEMETRY): it plans from the payload's pose and the arm's state
// as the DCP reports them, moves on only when the slave arm has followed its
// command, retries what the telemetry says failed, and relieves collisions
// the way an operator must (back to the pose the slave holds, then away).
//
// Motions: joint moves (every joint at most joint_rate_deg_s, all arriving
// together) for the long approach; straight-line moves of System Two
// (translation at a speed, rotation by slerp at a rate) solved by inverse
// kinematics every frame for the descent, the lift, the transfer and the
// docking approach, slowed down wherever a joint would exceed its rate.
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rms/base/camera_view.h"
#include "rms/base/config.h"
#include "rms/base/counters.h"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/mission/mission_geometry.h"
#include "rms/operator_station/arm_motion.h"
#include "rms/operator_station/follow_watch.h"
#include "rms/scene_model/scene_model.h"
#include "rms/wire/input_block.h"

namespace rms::operator_station {

struct AutopilotOptions {
  double joint_rate_deg_s = 8.0;     // the master arm's joints, at most
  double finger_rate_per_s = 0.5;    // finger lever travel a second
  double hover_ft = 6.0;             // the approach ends this far above the grasp, along -X2
  double descend_speed_ft_s = 0.75;  // the descent onto the bar
  double lift_speed_ft_s = 1.5;      // extraction, straight up
  double lift_margin_ft = 3.0;       // climb on this far after leaving the bay (Mode 3)
  double transfer_speed_ft_s = 2.0;  // to the pre-dock pose
  double turn_rate_deg_s = 8.0;      // System Two's rotation, at most
  double predock_ft = 3.0;  // the pre-dock pose: this far below the dock along the port's axis
  double dock_speed_ft_s = 0.25;  // the final approach
  int max_collisions = 8;         // collisions relieved before giving up
  int max_retries = 4;            // grasp or docking corrections before giving up
  bool plan_clear_paths = true;   // check planned paths against the scene's solids (off: fly
                                  // straight and relieve collisions as they come)
  double clearance_ft = 0.5;      // planned paths keep this far from solids
  double timeout_s = 600.0;       // of session time
  bool cameras = true;            // switch camera stations as the phases go (the demo's tour)
};

enum class AutopilotPhase {
  kWaitTelemetry,  // nothing heard from the DCP yet
  kReset,          // the DCP is not in its initial state: press reset
  kOpenFinger,
  kApproach,  // joint move to the hover pose above the bar
  kDescend,   // straight down onto the bar
  kClose,     // close the finger until the DCP says acquired (Mode 2)
  kLift,      // straight up out of the bay (Mode 3), then the margin
  kTransfer,  // to the pre-dock pose under the port
  kDock,      // along the port's axis until the DCP says docked
  kDocked,    // hold
  kRelieve,   // backing away from a collision, then back to the phase it interrupted
  kResync,    // after a restored checkpoint: pick up the task where the telemetry says it is
  kFailed,
};
const char* AutopilotPhaseName(AutopilotPhase p);

class Autopilot {
 public:
  explicit Autopilot(const LabConfig& config, AutopilotOptions options = {});

  // One frame: the inputs to publish, given the newest telemetry (nullptr
  // while there is none). Session time advances 1 / frame rate a call.
  wire::OperatorInputs Step(const dcp_telemetry_t* telemetry);

  // A checkpoint was restored (docs/sessions.md): command these inputs and,
  // at the next telemetry, carry on with the phase the DCP's state calls for.
  void Resync(const wire::OperatorInputs& restored);

  AutopilotPhase phase() const { return phase_; }
  bool docked() const { return phase_ == AutopilotPhase::kDocked; }
  bool failed() const { return phase_ == AutopilotPhase::kFailed; }
  const std::string& failure() const { return failure_; }
  double time_s() const { return t_s_; }
  double docked_at_s() const { return docked_at_s_; }
  // "autopilot.collisions_relieved", "autopilot.grasp_retries",
  // "autopilot.dock_corrections", "autopilot.via_points", ...
  const Counters& counters() const { return counters_; }

 private:
  // A plan is a queue of segments: a joint move (every joint at most its
  // rate, all arriving together) or a straight line of System Two.
  struct Segment {
    bool joints = false;
    std::array<double, 6> q{};                             // joints: the target
    Eigen::Isometry3d X1 = Eigen::Isometry3d::Identity();  // line: the end pose
    double speed_ft_s = 1.0;                               // line: translation speed
    // Filled when the segment starts.
    bool started = false;
    Eigen::Isometry3d X0 = Eigen::Isometry3d::Identity();
    double duration_s = 0.0, s = 0.0;
  };
  enum class PlanState { kMoving, kDone, kUnreachable };
  void PlanLine(const Eigen::Isometry3d& X1, double speed_ft_s);
  void PlanJoints(const std::array<double, 6>& q);
  // Advances the plan one frame; kDone once the command has reached the end of
  // the last segment (the slave may still be a frame behind: see Settled).
  PlanState StepPlan();
  // Moves the command toward q by at most the joint rate; true when there.
  bool StepJoints(const std::array<double, 6>& q);
  // The telemetry answers the current command and the slave follows it.
  bool Settled(const dcp_telemetry_t& tm) const;
  Eigen::Isometry3d CommandedPose() const;
  std::array<double, 6> CommandedAngles() const;
  std::optional<std::array<double, 6>> Solve(const Eigen::Isometry3d& X_RS2) const;
  // Is the straight joint path (or the line of System Two) clear of the
  // scene's solids by the planning margin? "" when clear, else what hits.
  std::string JointPathHits(const std::array<double, 6>& q0, const std::array<double, 6>& q1,
                            const dcp_telemetry_t& tm, mission::PayloadState payload) const;
  std::string LinePathHits(const Eigen::Isometry3d& X0, const Eigen::Isometry3d& X1,
                           const dcp_telemetry_t& tm, mission::PayloadState payload) const;
  void Enter(AutopilotPhase p);
  // One frame of each phase (docs/operator.md "The autopilot").
  void StepWaitTelemetry(const dcp_telemetry_t& tm);
  void StepReset(const dcp_telemetry_t& tm);
  void StepOpenFinger(const dcp_telemetry_t& tm);
  void StepApproach(const dcp_telemetry_t& tm);
  void StepDescend(const dcp_telemetry_t& tm);
  void StepClose(const dcp_telemetry_t& tm);
  void StepLift(const dcp_telemetry_t& tm);
  void StepTransfer(const dcp_telemetry_t& tm);
  void StepDock(const dcp_telemetry_t& tm);
  void StepDocked(const dcp_telemetry_t& tm);
  void StepRelieve(const dcp_telemetry_t& tm);
  void StepResync(const dcp_telemetry_t& tm);
  void Fail(const std::string& why);
  void Relieve(const dcp_telemetry_t& tm);
  void Camera(CameraView view, double zoom = 0.0);
  void PlanApproach(const dcp_telemetry_t& tm);
  void PlanTransfer(const dcp_telemetry_t& tm);
  void StartPhase(AutopilotPhase p, const dcp_telemetry_t& tm);

  const LabConfig& config_;
  AutopilotOptions opt_;
  JointLimits limits_;
  scene_model::SceneModel model_;
  double dt_s_;
  // A joint or the finger not following (a failure, docs/operator.md "The
  // autopilot"): the autopilot says so and holds its command until it follows.
  FollowWatch follow_;
  CameraStations stations_;       // each view's camera station, by its mount (0: none)
  double holding_since_s_ = 0.0;  // when it last said it holds for a failure
  // The telemetry's master command is where the slave arm is (every joint
  // within FollowWatch's recovery tolerance, the same shoulder height).
  bool CommandedWhereItIs(const dcp_telemetry_t& tm) const;
  double t_s_ = 0.0, phase_t0_s_ = 0.0;
  AutopilotPhase phase_ = AutopilotPhase::kWaitTelemetry;
  std::string failure_;
  Counters counters_;
  wire::OperatorInputs cmd_;
  std::vector<Segment> plan_;
  AutopilotPhase resume_ = AutopilotPhase::kApproach;  // after a relief
  // Closed-loop state.
  Eigen::Isometry3d X_PS2_grasp_ = Eigen::Isometry3d::Identity();  // System Two at the grasp, in P
  Eigen::Isometry3d X_S2P_ =
      Eigen::Isometry3d::Identity();  // the payload in System Two, as acquired
  Eigen::Isometry3d X_RP_dock_ = Eigen::Isometry3d::Identity();  // the payload docked
  double margin_ft_ = 0.5;  // the approach's planning margin (0 when it starts closer)
  double mode3_height_ft_ = 0.0;
  bool seen_mode3_ = false;
  int collisions_ = 0, retries_ = 0;
  int finger_full_frames_ = 0;
  int docked_frames_ = 0;
  double docked_at_s_ = -1.0;
  int reset_frames_ = 0;
  std::int64_t relieved_at_frame_ = -1000;  // the DCP frame a relief answered
};

}  // namespace rms::operator_station
