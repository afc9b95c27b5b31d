#pragma once
// Frame numbers on the wire (docs/protocol.md "Frame numbers"): what a
// session's clock allows, and each incoming stream's bookkeeping of gaps,
// duplicates, stale and impossible frames.
#include <cstdint>

namespace rms::wire {

// What no real sender produces (docs/protocol.md "Frame numbers", its
// dropped counters bad_frame, bad_time): a frame number of 2^48 or more (at
// 1 kHz, 8,900 years of frames) or a send time outside [0, 2^62) us. Every
// receiver drops such a message before any arithmetic on it.
inline constexpr std::int64_t kMaxFrameNumber = std::int64_t{1} << 48;
inline constexpr std::int64_t kMaxSendTimeUs = std::int64_t{1} << 62;

// The frame numbers a session's clock allows (docs/protocol.md "Frame
// numbers"): every sender numbers its frames from the session's epoch, so by
// now_us none can have gone past (now_us - epoch_us) x max_rate_hz, plus a
// margin. epoch_us 0: no session clock (a process started by hand).
struct FrameClock {
  std::int64_t epoch_us = 0;
  double max_rate_hz = 0;
  double margin_s = 10.0;
  bool active() const { return epoch_us > 0 && max_rate_hz > 0; }
  std::int64_t Limit(std::int64_t now_us) const;
};

// Frame-number bookkeeping for one incoming stream: detects lost frames
// (gaps), duplicates and stale (out-of-order) frames, and refuses frame
// numbers that cannot be real: beyond the session clock (FrameClock), or --
// with no clock -- more than kMaxJump ahead of the last. A sender whose
// numbering really moved (restarted without the session's epoch; or the
// last accepted frame was a forgery far ahead) is followed again after
// kResyncAfter refusals in a row, each after the one before: kResync.
// docs/protocol.md "Frame numbers".
class SequenceTracker {
 public:
  enum class Verdict { kFirst, kNext, kGap, kDuplicate, kStale, kFarAhead, kResync };
  static constexpr int kResyncAfter = 30;
  static constexpr std::int64_t kMaxJump = std::int64_t{1} << 20;  // 9.7 h at 30 Hz

  void SetClock(const FrameClock& clock) { clock_ = clock; }
  // now_us: when it arrived (wall clock); only the clock check uses it.
  Verdict Accept(std::int64_t frame, std::int64_t now_us = 0);
  std::int64_t received() const { return received_; }
  std::int64_t missing() const { return missing_; }  // frames never seen (sum of gaps)
  std::int64_t duplicates() const { return duplicates_; }
  std::int64_t stale() const { return stale_; }
  std::int64_t far_ahead() const { return far_ahead_; }
  std::int64_t resyncs() const { return resyncs_; }
  std::int64_t last() const { return last_; }
  std::int64_t previous() const { return previous_; }  // the last frame before the latest
  bool started() const { return started_; }

 private:
  Verdict Refuse(std::int64_t frame, Verdict why);
  FrameClock clock_;
  bool started_ = false;
  std::int64_t last_ = -1, previous_ = -1;
  std::int64_t received_ = 0, missing_ = 0, duplicates_ = 0, stale_ = 0, far_ahead_ = 0,
               resyncs_ = 0;
  int refused_run_ = 0;  // refusals in a row, each after the one before
  std::int64_t refused_last_ = -1;
};

}  // namespace rms::wire
