#pragma once
// The operator station's terminal without a network (docs/studies.md
// "Designs judged by flying them"): the hand controllers with a terminal's
// keyboard and the bindings, the real Dynamic Collision Program in closed
// loop (its telemetry read one frame later, as the station reads it over
// LCM before it sends the next block), and the status screen rendered as
// the station renders it. Session time passes only while the one at the
// terminal waits, frame by frame; nothing runs in real time. The scripted
// operator flies it as a virtual subject.
#include <cstdint>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "rms/base/config.h"
#include "rms/dcp_model/dynamic_collision_program.h"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/operator_station/bindings.h"
#include "rms/operator_station/guidance.h"
#include "rms/operator_station/hand_controllers.h"
#include "rms/sim/closed_loop.h"
#include "rms/sim/scripted_operator.h"

namespace rms::sim {

// Thrown by OfflineStation::Wait once the flight's session time is spent.
struct FlightTimeUp : std::runtime_error {
  FlightTimeUp() : std::runtime_error("the flight's session time is spent") {}
};

class OfflineStation : public OperatorTerminal {
 public:
  // max_s: the session time Wait may reach before it throws FlightTimeUp.
  // width x height: the terminal's size (the status screen follows it).
  // window_keys: the keys are the live window's (held until released,
  // RMS_WINDOW_KEYS' device), not a terminal's.
  OfflineStation(const LabConfig& config, const operator_station::Bindings& bindings, double max_s,
                 int width = 132, int height = 50, bool window_keys = false);
  std::string Capture() override;
  // Keys by tmux's names (one character, "Space", "Enter"); an unknown name
  // throws rms::InputError. Each is read by the station's next frame.
  void Send(const std::vector<std::string>& keys) override;
  void Wait(double s) override;
  bool HoldsKeys() const override { return window_ != nullptr; }
  void Release(const std::vector<std::string>& keys) override;

  // What the DCP's telemetry said, frame by frame (docked, times, margins,
  // collisions): the truth the screen showed.
  const ClosedLoopResult& result() const { return result_; }
  long key_actions() const { return hands_.key_actions(); }
  double session_s() const { return frames_ / rate_hz_; }

 private:
  void StepFrame();

  const LabConfig& config_;
  const operator_station::Bindings bindings_;  // before hands_, which holds a reference
  operator_station::HandControllers hands_;
  operator_station::GuidanceGeometry geometry_;
  dcp_model::DynamicCollisionProgram program_;
  double rate_hz_, max_s_;
  int width_, height_;
  std::vector<int> pending_keys_;  // typed, for the keyboard's next poll
  // The window's keyboard, when the keys are a window's: held keys and
  // those that went down since the last message.
  operator_station::WindowKeyboardDevice* window_ = nullptr;
  std::set<int> window_held_;
  std::vector<int> window_pressed_;
  std::int64_t window_sequence_ = 0;
  std::size_t next_key_ = 0;
  std::int64_t frames_ = 0;
  double waited_s_ = 0.0;  // the session time the waits asked for
  wire::OperatorInputs inputs_;
  std::optional<dcp_telemetry_t> telemetry_;  // the newest, as the station holds it
  ClosedLoopResult result_;
  bool colliding_ = false;
};

// The scripted operator flying one design at an offline station from the
// start, at most max_s of session time: the DCP's verdicts (result) and the
// operator's own report (keys, transcript). With again_after_reset, once
// docked it resets and flies a second attempt from where the arm docked;
// the report is that attempt's (the result and key_actions the session's).
struct ScriptedFlight {
  ClosedLoopResult result;
  FlightReport report;
  long key_actions = 0;
};
ScriptedFlight FlyScriptedSubject(const LabConfig& config,
                                  const operator_station::Bindings& bindings,
                                  const ScriptedOperatorOptions& options, double max_s,
                                  bool window_keys = false, bool again_after_reset = false);

}  // namespace rms::sim
