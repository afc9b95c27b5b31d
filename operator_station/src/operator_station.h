#pragma once
// operator_station: publishes the operator's input block (Table I) on
// RMS_OPERATOR_INPUT at the frame rate, from one source: a timeline file, the
// operator's hand controllers (keyboard, gamepad, 3D mouse), or the
// autopilot. It listens to the DCP's telemetry (the status screen, the
// autopilot) and to the processes' status reports (the screen's rates and
// latency). docs/operator.md.
#include <cstdint>
#include <string>

#include "rms/config.h"
#include "rms/counters.h"
#include "rms/input_block.h"
#include "rms/lcm_interface.h"
#include "rms/operator_input_t.hpp"

namespace rms::op {

struct OperatorOptions {
  std::string timeline_path;  // --timeline FILE
  bool keyboard = false;      // --keyboard: by hand, the terminal's keyboard required (plus any other device)
  bool manual = false;        // --manual: by hand with whatever devices are found
  bool autopilot = false;     // --autopilot
  bool autopilot_straight = false;  // --autopilot-straight: no path planning, relieve collisions as they come
  std::string bindings_path;  // --bindings (default config/bindings.toml)
  bool gamepad = true;        // --no-gamepad: don't look for one
  bool spacemouse = true;     // --no-spacemouse: don't look for one
  int status = -1;            // --status / --no-status (-1: on when by hand and stdout is a terminal)
  double rate_hz = 0.0;       // --rate (0: config session.frame_rate_hz)
  bool hold = false;          // --hold: keep publishing after the timeline's end / docking
  double speed = 1.0;         // --speed: timeline seconds per wall-clock second (frames stay at the rate)
  std::int64_t max_frames = -1;  // --frames N: stop after N frames (-1: no limit)
  std::string restore_path;   // --restore CHECKPOINT: start from its operator inputs (by hand, autopilot)
};

// Builds the numbered, time-stamped input blocks.
class InputBlockBuilder {
 public:
  explicit InputBlockBuilder(const InputCalibrations& cal) : cal_(cal) {}
  operator_input_t Build(const OperatorInputs& in, std::int64_t send_time_us, Counters* counters);
  std::int64_t next_frame() const { return next_frame_; }
  void set_next_frame(std::int64_t f) { next_frame_ = f; }

 private:
  const InputCalibrations& cal_;
  std::int64_t next_frame_ = 0;
};

// Exit codes: 0 done (the timeline's end, docked, 'quit'); 2 a bad option or
// file; 3 the autopilot failed; 130 stopped by SIGINT / SIGTERM.
inline constexpr int kExitAutopilotFailed = 3;
inline constexpr int kExitInterrupted = 130;

int RunOperatorStation(const OperatorOptions& options, const LabConfig& config, LcmInterface& lcm,
                       const std::string& stats_path, const std::string& ready_path);

}  // namespace rms::op
