#include "rms/wire/frame_numbers.h"

#include <algorithm>
#include <limits>

namespace rms::wire {

std::int64_t FrameClock::Limit(std::int64_t now_us) const {
  const double s = std::max(0.0, static_cast<double>(now_us - epoch_us) * 1e-6) + margin_s;
  return static_cast<std::int64_t>(s * max_rate_hz);
}

SequenceTracker::Verdict SequenceTracker::Refuse(std::int64_t frame, Verdict why) {
  // A run of refusals each after the one before is a sender whose numbering
  // moved: after kResyncAfter of them it is followed again (never beyond the
  // session clock, which is checked before this).
  refused_run_ = (refused_run_ > 0 && frame > refused_last_) ? refused_run_ + 1 : 1;
  refused_last_ = frame;
  if (refused_run_ >= kResyncAfter) {
    refused_run_ = 0;
    ++resyncs_;
    ++received_;
    previous_ = last_;
    last_ = frame;
    return Verdict::kResync;
  }
  if (why == Verdict::kStale)
    ++stale_;
  else
    ++far_ahead_;
  return why;
}

SequenceTracker::Verdict SequenceTracker::Accept(std::int64_t frame, std::int64_t now_us) {
  if (clock_.active() && now_us > 0 && frame > clock_.Limit(now_us)) {
    ++far_ahead_;
    refused_run_ = 0;
    return Verdict::kFarAhead;
  }
  if (!started_) {
    started_ = true;
    last_ = frame;
    ++received_;
    return Verdict::kFirst;
  }
  if (frame == last_) {
    ++duplicates_;
    return Verdict::kDuplicate;
  }
  if (frame < last_) return Refuse(frame, Verdict::kStale);
  if (!clock_.active() && frame - last_ > kMaxJump) return Refuse(frame, Verdict::kFarAhead);
  refused_run_ = 0;
  ++received_;
  const std::int64_t gap = frame - last_ - 1;
  previous_ = last_;
  last_ = frame;
  if (gap == 0) return Verdict::kNext;
  missing_ += gap;
  return Verdict::kGap;
}

}  // namespace rms::wire
