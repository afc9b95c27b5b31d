#include "rms/operator_station/follow_watch.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "rms/wire/malfunction.h"

namespace rms::operator_station {

FollowWatch::FollowWatch(double frame_rate_hz)
    : fail_frames_(std::max(1, static_cast<int>(std::lround(kFailSeconds * frame_rate_hz)))) {}

void FollowWatch::Forget() {
  off_frames_.fill(0);
  failing_ = 0;
}

std::vector<FollowWatch::Change> FollowWatch::Observe(const dcp_telemetry_t& t) {
  std::vector<Change> changes;
  // Held by a collision, or captured at the dock: the arm is meant to stay.
  const bool arm_judged = !t.held && !(t.docked && !t.released);
  for (int p = 0; p <= kFinger; ++p) {
    const bool was = (failing_ >> p) & 1u;
    bool off = false, back = false;
    if (p < kFinger) {
      const double d = std::abs(t.master_angles_deg[p] - t.slave_angles_deg[p]);
      off = arm_judged && d > kJointToleranceDeg;
      back = arm_judged && d <= kRecoverToleranceDeg;
    } else {
      const double d = t.master_finger - t.slave_finger;  // > 0: commanded more closed
      const bool free_to_close = t.mode == 1 && !t.finger_held && t.collisions == 0;
      off = !t.held && (d < -kFingerTolerance || (free_to_close && d > kFingerTolerance));
      back = !off;
    }
    off_frames_[p] = off ? off_frames_[p] + 1 : 0;
    if (!was && off_frames_[p] >= fail_frames_) {
      failing_ |= 1u << p;
      Change c{p, true, ""};
      c.text = p < kFinger ? fmt::format(
                                 "joint {} ({}) is NOT FOLLOWING its command: commanded {:.1f} "
                                 "deg, at {:.1f} deg",
                                 p + 1, wire::JointName(p + 1), t.master_angles_deg[p],
                                 t.slave_angles_deg[p])
                           : fmt::format(
                                 "the finger is NOT FOLLOWING its command: commanded {:.2f}, at "
                                 "{:.2f}",
                                 t.master_finger, t.slave_finger);
      changes.push_back(c);
    } else if (was && back) {
      failing_ &= ~(1u << p);
      Change c{p, false, ""};
      c.text = p < kFinger ? fmt::format("joint {} ({}) follows its command again", p + 1,
                                         wire::JointName(p + 1))
                           : std::string("the finger follows its command again");
      changes.push_back(c);
    }
  }
  return changes;
}

}  // namespace rms::operator_station
