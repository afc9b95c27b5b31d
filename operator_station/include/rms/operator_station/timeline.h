#pragma once
// Scripted operator inputs: the timeline file format of docs/timeline.md.
//
//   # comment
//   <time_s> <key>=<value> [<key>=<value> ...] [reset] [end]
//
// Analog keys (the input names of Table I: shoulder_yaw ... camera_zoom) are
// keyframes: a channel is at `value` at `time_s` and moves linearly between
// its keyframes; it starts at its calibration's `initial` at t = 0 unless set
// at t = 0, and holds after its last keyframe. `camera=N` (1-8) and
// `overlay=on|off` step at their time. `reset` presses the reset button for
// one frame. `end` ends the timeline (default: the last line's time).
#include <string>
#include <string_view>
#include <vector>

#include "rms/wire/input_block.h"

namespace rms::operator_station {

class Timeline {
 public:
  // Throws rms::InputError "SOURCE:LINE: reason" on the first problem.
  // Values outside a channel's [min, max] are accepted; they are clamped
  // (and counted) when encoded, and listed in warnings().
  static Timeline Parse(std::string_view text, const std::string& source,
                        const InputCalibrations& cal);
  static Timeline Load(const std::string& path, const InputCalibrations& cal);

  // The inputs at time t (seconds). reset is false here; see ResetIn.
  wire::OperatorInputs Sample(double t) const;
  // True when a reset keyframe lies in (t0, t1] (or [0, t1] when t0 < 0).
  bool ResetIn(double t0, double t1) const;
  double end_time() const { return end_time_; }
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  void AddItem(double t, std::string_view item, const InputCalibrations& cal,
               const std::string& where, bool* end);
  struct Key {
    double t;
    double v;
  };
  std::array<std::vector<Key>, kNumAnalogInputs> analog_;
  std::vector<std::pair<double, int>> camera_;
  std::vector<std::pair<double, bool>> overlay_;
  std::vector<std::pair<double, bool>> crosshairs_;
  std::vector<double> resets_;
  double end_time_ = 0.0;
  wire::OperatorInputs initial_;
  std::vector<std::string> warnings_;
};

}  // namespace rms::operator_station
