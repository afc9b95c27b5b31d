#pragma once
// The receive path every subscriber shares: safe decode, the block's own
// checks, frame-number bookkeeping, and a counter for whatever is dropped
// ("dropped.REASON", docs/protocol.md "Malformed messages"). Nothing throws out.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <spdlog/spdlog.h>
#include <string>
#include <type_traits>
#include <utility>

#include "rms/base/check.h"
#include "rms/base/counters.h"
#include "rms/wire/frame_numbers.h"
#include "rms/wire/message_io.h"

namespace rms::wire {

// Thrown by a block's checks to drop a message under a counter of its own
// (plain InputError drops it as dropped.bad_word).
class MalformedError : public InputError {
 public:
  MalformedError(Counter counter, const std::string& what) : InputError(what), counter_(counter) {}
  Counter counter() const { return counter_; }

 private:
  Counter counter_;
};

// Frames that waited too long to be worth acting on (docs/protocol.md "Late
// frames"): a process that was stopped (SIGSTOP, a stall, a swapped-out
// host) wakes to a queue of old frames; executing them in a burst would
// overrun every receiver after it. A frame is too late when its age (now
// minus its sender's send time) exceeds the link's own delay -- the least
// age seen over the last 10 s, so clocks that differ between hosts cancel
// out -- by more than the limit: three frame periods, at least 100 ms.
// Default-constructed: off (re-simulation, tests).
class LateFrameFilter {
 public:
  LateFrameFilter() = default;
  explicit LateFrameFilter(double frame_rate_hz)
      : limit_us_(std::max<std::int64_t>(100000, static_cast<std::int64_t>(3e6 / frame_rate_hz))) {}
  bool enabled() const { return limit_us_ > 0; }
  std::int64_t limit_us() const { return limit_us_; }
  bool TooLate(std::int64_t send_time_us, std::int64_t now_us) {
    if (!enabled()) return false;
    const std::int64_t age = now_us - send_time_us;
    if (now_us - bucket_start_us_ >= kBucketUs) {  // the window slides by half
      min_prev_ = min_cur_;
      min_cur_ = kNone;
      bucket_start_us_ = now_us;
    }
    min_cur_ = std::min(min_cur_, age);
    return age - std::min(min_cur_, min_prev_) > limit_us_;
  }

 private:
  static constexpr std::int64_t kBucketUs = 5000000,
                                kNone = std::numeric_limits<std::int64_t>::max();
  std::int64_t limit_us_ = 0;
  std::int64_t bucket_start_us_ = 0, min_cur_ = kNone, min_prev_ = kNone;
};

// Decodes one raw message of type Msg (SafeDecode: the type's bounds), applies
// `unpack` (Msg -> the block's content; throws InputError to refuse it),
// the frame-number checks and -- given a filter -- the lateness check
// (now_us: the wall clock as it is handled). Returns the message and its
// content, or nothing when the message was dropped (and counted). Counts
// "received" always.
template <class Msg, class Unpack>
auto ReceiveFrame(const void* data, int size, SequenceTracker* seq, Counters* counters,
                  Unpack&& unpack, std::int64_t now_us = 0, LateFrameFilter* late = nullptr)
    -> std::optional<std::pair<Msg, std::invoke_result_t<Unpack, const Msg&>>> {
  using Content = std::invoke_result_t<Unpack, const Msg&>;
  counters->Add(Counter::kReceived);
  Msg msg;
  const DecodeError err = SafeDecode(data, size, &msg);
  if (err != DecodeError::kNone) {
    counters->Add(DroppedCounter(err));
    return std::nullopt;
  }
  // Frame numbers and send times a real sender cannot produce (negative, or
  // beyond kMaxFrameNumber, times outside [0, kMaxSendTimeUs)): dropped
  // before any arithmetic on them.
  if (msg.frame < 0 || msg.frame >= kMaxFrameNumber) {
    counters->Add(Counter::kDroppedBadFrame);
    return std::nullopt;
  }
  bool times_ok = msg.send_time_us >= 0 && msg.send_time_us < kMaxSendTimeUs;
  if constexpr (requires { msg.input_send_time_us; }) {
    times_ok = times_ok && msg.input_send_time_us >= 0 && msg.input_send_time_us < kMaxSendTimeUs;
  }
  if (!times_ok) {
    counters->Add(Counter::kDroppedBadTime);
    return std::nullopt;
  }
  std::optional<Content> content;
  try {
    content.emplace(unpack(msg));
  } catch (const MalformedError& e) {
    counters->Add(e.counter());
    spdlog::debug("frame {} dropped: {}", msg.frame, e.what());
    return std::nullopt;
  } catch (const InputError& e) {
    counters->Add(Counter::kDroppedBadWord);
    spdlog::debug("frame {} dropped: {}", msg.frame, e.what());
    return std::nullopt;
  }
  const std::int64_t before = seq->last();
  switch (seq->Accept(msg.frame, now_us)) {
    case SequenceTracker::Verdict::kDuplicate:
      counters->Add(Counter::kDroppedDuplicate);
      return std::nullopt;
    case SequenceTracker::Verdict::kStale:
      counters->Add(Counter::kDroppedStale);
      return std::nullopt;
    case SequenceTracker::Verdict::kFarAhead:
      // A frame number no sender of this session can have reached: refused.
      if (counters->Get(Counter::kDroppedFarAhead) == 0) {
        spdlog::warn("frame {} refused: beyond what the session's clock allows (dropped.far_ahead)",
                     msg.frame);
      }
      counters->Add(Counter::kDroppedFarAhead);
      return std::nullopt;
    case SequenceTracker::Verdict::kResync:
      counters->Add(Counter::kResyncs);
      spdlog::warn(
          "frame numbers resynchronised: {} refused in a row, now following frame {} (the last "
          "accepted "
          "was {}; a sender restarted, or that frame was not real)",
          SequenceTracker::kResyncAfter, msg.frame, before);
      break;
    case SequenceTracker::Verdict::kGap: {
      // Frames lost on the way (or while the sender was down): counted by
      // the caller from seq->missing(); a gap of several frames is said.
      counters->Add(Counter::kGaps);
      if (const std::int64_t n = msg.frame - seq->previous() - 1; n >= 3) {
        spdlog::warn("gap: {} frames missing before frame {} (a lossy link or a restarted sender)",
                     n, msg.frame);
      }
      break;
    }
    default:
      break;
  }
  if (late && late->TooLate(msg.send_time_us, now_us)) {
    // In the sequence (not counted missing), but not acted on.
    counters->Add(Counter::kDroppedLate);
    if (counters->Get(Counter::kDroppedLate) == 1 ||
        counters->Get(Counter::kDroppedLate) % 1000 == 0) {
      spdlog::warn(
          "frame {} dropped: {} ms old, later than {} ms beyond the link's delay (dropped.late: {} "
          "so far; "
          "a stall, or a process that was stopped)",
          msg.frame, (now_us - msg.send_time_us) / 1000, late->limit_us() / 1000,
          counters->Get(Counter::kDroppedLate));
    }
    return std::nullopt;
  }
  return std::make_pair(std::move(msg), std::move(*content));
}

}  // namespace rms::wire
