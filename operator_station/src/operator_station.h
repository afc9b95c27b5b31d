#pragma once
// operator_station: publishes the operator's input block (Table I) on
// RMS_OPERATOR_INPUT at the frame rate, from a timeline file or the keyboard.
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
  bool keyboard = false;      // --keyboard
  double rate_hz = 0.0;       // --rate (0: config session.frame_rate_hz)
  bool hold = false;          // --hold: keep publishing the timeline's last inputs until stopped
  double speed = 1.0;         // --speed: timeline seconds per wall-clock second (frames stay at the rate)
  std::int64_t max_frames = -1;  // --frames N: stop after N frames (-1: no limit)
};

// Builds the numbered, time-stamped input blocks.
class InputBlockBuilder {
 public:
  explicit InputBlockBuilder(const InputCalibrations& cal) : cal_(cal) {}
  operator_input_t Build(const OperatorInputs& in, std::int64_t send_time_us, Counters* counters);
  std::int64_t next_frame() const { return next_frame_; }

 private:
  const InputCalibrations& cal_;
  std::int64_t next_frame_ = 0;
};

// Exit code when SIGINT / SIGTERM stopped the station (before a timeline's end).
inline constexpr int kExitInterrupted = 130;

// The station's main loop: runs until the timeline ends (unless hold), the
// frame limit, 'x' on the keyboard, or SIGINT / SIGTERM. Returns the exit
// code: 0, or kExitInterrupted when stopped by a signal.
int RunOperatorStation(const OperatorOptions& options, const LabConfig& config, LcmInterface& lcm,
                       const std::string& stats_path, const std::string& ready_path);

}  // namespace rms::op
