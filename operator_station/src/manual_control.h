#pragma once
// Flying by hand (docs/operator.md "Devices" and "Conditioning"): the
// devices' commands, conditioned as the hand controllers' electronics did --
// deadband (at the device), a rate limit on every input, clamping to each
// input's calibrated range with a report -- and combined into the operator
// input block's values.
//
// Each input has a target (where the operator's keys, sticks and buttons
// put it) and an output (what is published), which follows the target at no
// more than the input's max_rate. A target beyond its calibrated range is
// clamped, counted ("clamped.NAME") and reported once per excursion. The 3D
// mouse moves System Two (resolved rate): its velocity is turned into the
// six arm targets by inverse kinematics each frame.
#include <memory>
#include <string>
#include <vector>

#include "bindings.h"
#include "devices.h"
#include "rms/config.h"
#include "rms/counters.h"
#include "rms/input_block.h"

namespace rms::op {

class ManualControl {
 public:
  ManualControl(const LabConfig& config, const Bindings& bindings);
  void AddDevice(std::unique_ptr<InputDevice> device);
  const std::vector<std::unique_ptr<InputDevice>>& devices() const { return devices_; }

  // One frame of dt seconds: polls every device and returns the inputs.
  OperatorInputs Step(double dt_s);
  // Applies one frame's commands (Step does this after polling; tests too).
  OperatorInputs Apply(const DeviceCommands& cmd, double dt_s);

  bool quit() const { return quit_; }
  // Freeze / step asked for this frame (the station sends them on RMS_CONTROL).
  bool freeze_requested() const { return freeze_requested_; }
  bool step_requested() const { return step_requested_; }
  // Only the session's keys (freeze, step, quit) while frozen: everything
  // else is read and dropped, counted ("frozen.inputs_ignored").
  void PollFrozen();
  // Carry on from these inputs (a restored checkpoint): targets and outputs.
  void SetInputs(const OperatorInputs& in);
  const OperatorInputs& target() const { return target_; }
  // "clamped.NAME", "resolved_rate.unreachable", "device.disconnected".
  const Counters& counters() const { return counters_; }

 private:
  const LabConfig& config_;
  const Bindings& b_;
  std::vector<std::unique_ptr<InputDevice>> devices_;
  std::vector<bool> reported_gone_;
  OperatorInputs target_, out_;
  std::array<bool, kNumAnalogInputs> clamping_{};
  Counters counters_;
  bool quit_ = false;
  bool freeze_requested_ = false, step_requested_ = false;
};

}  // namespace rms::op
