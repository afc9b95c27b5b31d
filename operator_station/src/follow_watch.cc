#include "rms/operator_station/follow_watch.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "rms/wire/dcp_mode.h"
#include "rms/wire/malfunction.h"

namespace rms::operator_station {

FollowWatch::FollowWatch(double frame_rate_hz)
    : fail_frames_(std::max(1, static_cast<int>(std::lround(kFailSeconds * frame_rate_hz)))) {}

void FollowWatch::Forget() {
  off_frames_.fill(0);
  failing_ = 0;
}

namespace {

std::string FailingText(int part, const dcp_telemetry_t& t) {
  if (part == FollowWatch::kArm) {
    return "the arm is HELD by a collision though commanded where it is: something moves it on "
           "its own";
  }
  if (part == FollowWatch::kFinger) {
    return fmt::format("the finger is NOT FOLLOWING its command: commanded {:.2f}, at {:.2f}",
                       t.master_finger, t.slave_finger);
  }
  return fmt::format(
      "joint {} ({}) is NOT FOLLOWING its command: commanded {:.1f} deg, at {:.1f} deg", part + 1,
      wire::JointName(part + 1), t.master_angles_deg[part], t.slave_angles_deg[part]);
}

std::string RecoveredText(int part) {
  if (part == FollowWatch::kArm) return "the arm is no longer held";
  if (part == FollowWatch::kFinger) return "the finger follows its command again";
  return fmt::format("joint {} ({}) follows its command again", part + 1,
                     wire::JointName(part + 1));
}

}  // namespace

std::vector<FollowWatch::Change> FollowWatch::Observe(const dcp_telemetry_t& t, bool commanding) {
  std::vector<Change> changes;
  // Held by a collision, or captured at the dock: the arm is meant to stay.
  const bool captured = t.docked && !t.released;
  const bool arm_judged = !t.held && !captured;
  bool at_command = true;  // every joint where it is commanded
  for (int i = 0; i < kNumJoints; ++i) {
    at_command = at_command &&
                 std::abs(t.master_angles_deg[i] - t.slave_angles_deg[i]) <= kRecoverToleranceDeg;
  }
  for (int p = 0; p <= kArm; ++p) {
    const bool was = (failing_ >> p) & 1u;
    bool off = false, back = false;
    if (p == kArm) {
      off = t.held && at_command && !captured && !commanding;
      back = !t.held;
    } else if (p < kFinger) {
      const double d = std::abs(t.master_angles_deg[p] - t.slave_angles_deg[p]);
      off = arm_judged && d > kJointToleranceDeg;
      back = arm_judged && d <= kRecoverToleranceDeg;
    } else {
      const double d = t.master_finger - t.slave_finger;  // > 0: commanded more closed
      const bool free_to_close =
          t.mode == wire::DcpMode::kAcquisition && !t.finger_held && t.collisions == 0;
      off = !t.held && (d < -kFingerTolerance || (free_to_close && d > kFingerTolerance));
      back = !off;
    }
    off_frames_[p] = off ? off_frames_[p] + 1 : 0;
    if (!was && off_frames_[p] >= fail_frames_) {
      failing_ |= 1u << p;
      changes.push_back({p, true, FailingText(p, t)});
    } else if (was && back) {
      failing_ &= ~(1u << p);
      changes.push_back({p, false, RecoveredText(p)});
    }
  }
  return changes;
}

}  // namespace rms::operator_station
