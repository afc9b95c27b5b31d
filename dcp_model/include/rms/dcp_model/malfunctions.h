#pragma once
// The malfunctions the DCP honours (docs/sessions.md "Malfunctions"): failed
// joints, the finger jammed, camera stations lost, the operator's inputs
// delayed. Injected and repaired between frames (RMS_CONTROL MALFUNCTION and
// REPAIR), part of the DCP's state (its checkpoint), so a re-simulation
// reproduces them from the logged RMS_DCP_STATE.
//
// Each acts on what the slave arm is commanded, never on the operator's
// command (the telemetry's master angles stay the operator's):
//  joint stuck   the joint's command is where the slave's joint was when it failed
//  joint drift   the joint's command is the slave's joint plus RATE / frame rate, each frame
//  joint slow    the joint moves toward its command at most RATE / frame rate a frame
//  finger jammed open    the finger lever at most where the slave's was when it jammed
//  finger jammed closed  the finger lever at least where it was
//  camera lost   the control word's NO VIDEO bit when the operator selects that station
//  inputs delayed  each input block is answered ROUND(MS x frame rate / 1000) frames
//                  late (at least one); when the delay starts, the last block
//                  answered is held until the first delayed one is due
// The collision test then applies to the command as it always does.
#include <array>
#include <cstdint>
#include <deque>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rms/wire/input_block.h"
#include "rms/wire/malfunction.h"

namespace rms::dcp_model {

class Malfunctions {
 public:
  // frame_rate_hz: the session's; joint_min/max_deg: each joint's travel
  // (config [arm] joint limits within [inputs.*]), which a drifting joint
  // stays within.
  Malfunctions(double frame_rate_hz, const std::array<double, kNumJoints>& joint_min_deg,
               const std::array<double, kNumJoints>& joint_max_deg);

  // A malfunction from now on (one per joint, one for the finger: a new one
  // replaces the old), anchored at the slave's joint angles and finger lever
  // now.
  void Inject(const wire::Malfunction& m, const std::array<double, kNumJoints>& slave_angles_deg,
              double slave_finger);
  void Repair(const wire::Repair& r);

  // The inputs the frame answers: `in` itself, or the one due from the
  // delay line.
  const wire::OperatorInputs& Delay(const wire::OperatorInputs& in);
  // The command the failed joints and the finger let through, from the
  // slave's pose (*angles_deg and *finger: the command, changed in place).
  void Apply(const std::array<double, kNumJoints>& slave_angles_deg,
             std::array<double, kNumJoints>* angles_deg, double* finger);
  bool CameraLost(int station) const { return (cameras_lost_ >> (station - 1)) & 1u; }

  // Whether any is in force (what active() lists), without building the list.
  bool any() const;
  // What is in force, in the order of kMalfunctionKinds and targets.
  std::vector<wire::Malfunction> active() const;
  int delay_frames() const { return delay_frames_; }

  // The state, for the checkpoint: the malfunctions in force (their text),
  // each joint's and the finger's anchor, the delay line (doubles exact).
  // FromJson throws rms::InputError naming what is wrong and changes nothing;
  // a checkpoint without the key has none.
  nlohmann::ordered_json ToJson() const;
  void FromJson(const nlohmann::json& j);

 private:
  struct JointFault {
    wire::MalfunctionKind kind;
    double value;
    double anchor_deg;  // stuck: the angle it stays at
  };
  struct FingerFault {
    bool open;            // jammed open (cannot close) or closed (cannot open)
    double anchor_lever;  // where it jammed
  };
  double frame_rate_hz_;
  std::array<double, kNumJoints> joint_min_deg_, joint_max_deg_;
  std::array<std::optional<JointFault>, kNumJoints> joints_{};
  std::optional<FingerFault> finger_;
  std::uint32_t cameras_lost_ = 0;  // bit k-1: station k
  double delay_ms_ = 0.0;
  int delay_frames_ = 0;
  std::deque<wire::OperatorInputs> line_;  // the delay line: the oldest is answered next
  wire::OperatorInputs last_{};            // the last block answered
  bool have_last_ = false;
};

}  // namespace rms::dcp_model
