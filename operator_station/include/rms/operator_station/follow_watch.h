#pragma once
// A failure as the operator sees it (docs/operator.md "A joint that does not
// follow"): the DCP's telemetry shows a joint, or the finger, not where it is
// commanded, for longer than a collision hold or the finger on the bar can
// explain. That is how a stuck, drifting or slowed joint or a jammed finger
// (docs/sessions.md "Malfunctions") shows: the watch reads only the
// telemetry, never the malfunctions injected.
//
// A joint fails to follow when its slave angle stays more than
// kJointToleranceDeg from the master's for kFailSeconds while the arm is
// neither held by a collision nor captured at the dock; it follows again once
// within kRecoverToleranceDeg. The finger: the slave's lever more closed than
// commanded (it does not open), or in Mode 1, free of the bar, less closed (it
// does not close), by kFingerTolerance. The arm: held by a collision for
// kFailSeconds though every joint is commanded where it is (a drifting joint
// pushing into a collision); it follows again once no longer held.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "rms/dcp_telemetry_t.hpp"

namespace rms::operator_station {

class FollowWatch {
 public:
  static constexpr double kJointToleranceDeg = 0.5;
  static constexpr double kRecoverToleranceDeg = 0.05;
  static constexpr double kFingerTolerance = 0.02;
  static constexpr double kFailSeconds = 0.5;
  static constexpr int kFinger = 6;  // part index of the finger; joints 0..5
  // Part index of "the arm": held by a collision though commanded where it
  // is -- something moves it that the command does not (a drifting joint).
  static constexpr int kArm = 7;

  explicit FollowWatch(double frame_rate_hz);

  // What changed with this telemetry: each part that stopped or began
  // following again, as a sentence for the operator's events.
  struct Change {
    int part = 0;  // 0..5 joint (shoulder yaw .. wrist roll), kFinger, kArm
    bool failing = false;
    std::string text;
  };
  // commanding: the operator's hand controllers command a motion now (a
  // held arm is then the operator's own collision, not "something moving
  // it on its own").
  std::vector<Change> Observe(const dcp_telemetry_t& t, bool commanding = false);
  // Bit p: part p does not follow.
  std::uint32_t failing() const { return failing_; }
  // After a reset or a restore: nothing carried over.
  void Forget();

 private:
  int fail_frames_;
  std::array<int, 8> off_frames_{};  // consecutive frames off its command
  std::uint32_t failing_ = 0;
};

}  // namespace rms::operator_station
