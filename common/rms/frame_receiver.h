#pragma once
// The receive path every subscriber shares: safe decode, the block's own
// checks, frame-number bookkeeping, and a counter for whatever is dropped
// ("dropped.REASON", docs/protocol.md "Malformed messages"). Nothing throws out.
#include <optional>
#include <string>
#include <type_traits>
#include <utility>

#include <spdlog/spdlog.h>

#include "rms/check.h"
#include "rms/counters.h"
#include "rms/message_io.h"

namespace rms {

// Thrown by a block's checks to drop a message under a reason of its own
// (plain InputError drops it as "bad_word").
class MalformedError : public InputError {
 public:
  MalformedError(std::string reason, const std::string& what)
      : InputError(what), reason_(std::move(reason)) {}
  const std::string& reason() const { return reason_; }

 private:
  std::string reason_;
};

// Decodes one raw message of type Msg (at most max_size bytes), applies
// `unpack` (Msg -> the block's content; throws InputError to refuse it) and
// the frame-number checks. Returns the message and its content, or nothing
// when the message was dropped (and counted). Counts "received" always.
template <class Msg, class Unpack>
auto ReceiveFrame(const void* data, int size, int max_size, SequenceTracker* seq,
                  Counters* counters, Unpack&& unpack)
    -> std::optional<std::pair<Msg, std::invoke_result_t<Unpack, const Msg&>>> {
  using Content = std::invoke_result_t<Unpack, const Msg&>;
  counters->Add("received");
  Msg msg;
  const DecodeError err = SafeDecode(data, size, max_size, &msg);
  if (err != DecodeError::kNone) {
    counters->Add(std::string("dropped.") + DecodeErrorName(err));
    return std::nullopt;
  }
  // Frame numbers and send times a real sender cannot produce (negative, or
  // beyond 2^48 frames, times outside [0, 2^62) us): dropped before any arithmetic on them.
  constexpr std::int64_t kMaxFrame = std::int64_t{1} << 48, kMaxTimeUs = std::int64_t{1} << 62;
  if (msg.frame < 0 || msg.frame >= kMaxFrame) {
    counters->Add("dropped.bad_frame");
    return std::nullopt;
  }
  bool times_ok = msg.send_time_us >= 0 && msg.send_time_us < kMaxTimeUs;
  if constexpr (requires { msg.input_send_time_us; }) {
    times_ok = times_ok && msg.input_send_time_us >= 0 && msg.input_send_time_us < kMaxTimeUs;
  }
  if (!times_ok) {
    counters->Add("dropped.bad_time");
    return std::nullopt;
  }
  std::optional<Content> content;
  try {
    content.emplace(unpack(msg));
  } catch (const MalformedError& e) {
    counters->Add("dropped." + e.reason());
    spdlog::debug("frame {} dropped: {}", msg.frame, e.what());
    return std::nullopt;
  } catch (const InputError& e) {
    counters->Add("dropped.bad_word");
    spdlog::debug("frame {} dropped: {}", msg.frame, e.what());
    return std::nullopt;
  }
  switch (seq->Accept(msg.frame)) {
    case SequenceTracker::Verdict::kDuplicate: counters->Add("dropped.duplicate"); return std::nullopt;
    case SequenceTracker::Verdict::kStale: counters->Add("dropped.stale"); return std::nullopt;
    case SequenceTracker::Verdict::kGap: {
      // Frames lost on the way (or while the sender was down): counted by
      // the caller from seq->missing(); a gap of several frames is said.
      counters->Add("gaps");
      if (const std::int64_t n = msg.frame - seq->previous() - 1; n >= 3) {
        spdlog::warn("gap: {} frames missing before frame {} (a lossy link or a restarted sender)", n, msg.frame);
      }
      break;
    }
    default: break;
  }
  return std::make_pair(std::move(msg), std::move(*content));
}

}  // namespace rms
