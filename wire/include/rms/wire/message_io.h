#pragma once
// Safe encode / decode of LCM messages. Every message a process receives goes
// through SafeDecode: a malformed message is classified (wrong type,
// truncated, trailing bytes, impossible count) and never throws or crashes.
// lcm-gen 1.3.1's decoders resize arrays from the message's own count fields
// and can throw on hostile input; SafeDecode catches that.
#include <array>
#include <cstdint>
#include <cstring>
#include <exception>
#include <string>
#include <string_view>
#include <vector>

#include "rms/base/counters.h"
#include "rms/control_answer_t.hpp"
#include "rms/lcm_limits.h"
#include "rms/session_control_t.hpp"

namespace rms::wire {

enum class DecodeError {
  kNone = 0,
  kTooLarge,       // larger than any valid message of the type
  kWrongType,      // fingerprint is not the expected type's
  kTruncated,      // ended before the message did
  kTrailingBytes,  // bytes left after the message
  kBadCount,       // an array or string length that cannot be valid
};

// Counter-friendly names, kTooLarge first: "too_large", "wrong_type", ...
inline constexpr int kNumDecodeErrors = 5;
inline constexpr std::array<std::string_view, kNumDecodeErrors> kDecodeErrorNames = {
    "too_large", "wrong_type", "truncated", "trailing_bytes", "bad_count"};
const char* DecodeErrorName(DecodeError e);
// The counter a message dropped for `e` goes to (e != kNone): dropped.E on a
// process's input channel, and the families of the operator station's
// telemetry and window keys and the renderer's operator state.
constexpr Counter DroppedCounter(DecodeError e) {
  return CounterAt(Counter::kDroppedTooLarge, static_cast<int>(e) - 1);
}
constexpr Counter DroppedTelemetryCounter(DecodeError e) {
  return CounterAt(Counter::kDroppedTelemetryTooLarge, static_cast<int>(e) - 1);
}
constexpr Counter DroppedWindowKeysCounter(DecodeError e) {
  return CounterAt(Counter::kDroppedWindowKeysTooLarge, static_cast<int>(e) - 1);
}
constexpr Counter DroppedOperatorStateCounter(DecodeError e) {
  return CounterAt(Counter::kDroppedOperatorStateTooLarge, static_cast<int>(e) - 1);
}
static_assert(FamilyFollows(Counter::kDroppedTooLarge, "dropped.", kDecodeErrorNames.data(),
                            kNumDecodeErrors));
static_assert(FamilyFollows(Counter::kDroppedTelemetryTooLarge, "dropped.telemetry_",
                            kDecodeErrorNames.data(), kNumDecodeErrors));
static_assert(FamilyFollows(Counter::kDroppedWindowKeysTooLarge, "dropped.window_keys_",
                            kDecodeErrorNames.data(), kNumDecodeErrors));
static_assert(FamilyFollows(Counter::kDroppedOperatorStateTooLarge, "dropped.operator_state_",
                            kDecodeErrorNames.data(), kNumDecodeErrors));

// Reads the 8-byte big-endian fingerprint at the start of an LCM message.
inline bool ReadFingerprint(const void* data, int size, std::int64_t* out) {
  if (size < 8) return false;
  const auto* b = static_cast<const std::uint8_t*>(data);
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | b[i];
  *out = static_cast<std::int64_t>(v);
  return true;
}

// sender_t on the wire: right after the fingerprint (every rmslab message
// has it first), session_id (8 bytes), process (1), pid (4), big-endian.
inline constexpr int kSenderBytes = 13;
// RMS_OPERATOR_INPUT, RMS_DCP_FRAME and RMS_DCP_TELEMETRY go on with their
// frame number, then their send time (int64 each, big-endian): where they
// start in the raw message (docs/protocol.md "Senders").
inline constexpr int kFrameAt = 8 + kSenderBytes;
inline constexpr int kSendTimeAt = kFrameAt + 8;
// RMS_DCP_FRAME's input_frame, after its send time.
inline constexpr int kDcpFrameInputFrameAt = kSendTimeAt + 8;
// The big-endian int64 at byte `at` of a raw message; false when it is too
// short to hold it.
bool ReadInt64At(const void* data, int size, int at, std::int64_t* value);
// Such a raw message's frame number (at kFrameAt).
inline bool ReadFrameNumber(const void* data, int size, std::int64_t* frame) {
  return ReadInt64At(data, size, kFrameAt, frame);
}

// True for the fingerprint of one of rmslab's own message types.
bool IsRmslabFingerprint(std::int64_t fingerprint);
// The sender's session id / process and pid of a raw rmslab message; false
// when it is too short to hold them.
bool ReadSessionId(const void* data, int size, std::int64_t* session_id);
bool ReadSenderProcess(const void* data, int size, std::int8_t* process, std::int32_t* pid);
// "0x" and 16 hex digits, as the manifest and the logs write a session id.
std::string FormatSessionId(std::int64_t session_id);
// "dynamics_proc", ... for sender_t::PROCESS_*; "unknown" otherwise.
// "freeze", "run", "step", "checkpoint", "restore", "reset" for
// session_control_t's commands; "?" otherwise (the one table of their names).
const char* ControlCommandName(std::int8_t command);
const char* ProcessCodeName(std::int8_t process);
// sender_t::PROCESS_* for a process name ("operator_station", ...); PROCESS_TOOL otherwise.
std::int8_t ProcessCode(std::string_view name);

// The answer to `command` (docs/protocol.md "RMS_CONTROL_ANSWER"): its id
// (the command's sender and sequence), the outcome (control_answer_t::DONE
// or REFUSED), the frame from which it holds and the text, cut to
// control_answer_t::MAX_TEXT_BYTES on a UTF-8 character's boundary. The
// answerer stamps its own sender as it publishes.
control_answer_t MakeControlAnswer(const session_control_t& command, std::int8_t outcome,
                                   std::int64_t frame, std::string text);

// Decodes a raw message of type Msg. Its size limit and the bounds of its
// counts and strings come from the type (lcmtypes/*.lcm's MAX_* constants,
// rms/lcm_limits.h): a larger message is kTooLarge before any decoding, a
// count or string beyond its bound kBadCount after.
template <class Msg>
DecodeError SafeDecode(const void* data, int size, Msg* msg) {
  if (size > lcm_limits::kMaxEncodedSize<Msg>) return DecodeError::kTooLarge;
  std::int64_t fp = 0;
  if (!ReadFingerprint(data, size, &fp)) return DecodeError::kTruncated;
  if (fp != Msg::getHash()) return DecodeError::kWrongType;
  int n = -1;
  try {
    n = msg->decode(data, 0, size);
  } catch (const std::exception&) {  // length_error / bad_alloc from a hostile count
    return DecodeError::kBadCount;
  }
  if (n < 0) return DecodeError::kTruncated;
  if (n != size) return DecodeError::kTrailingBytes;
  if (!lcm_limits::Bounds<Msg>::Within(*msg)) return DecodeError::kBadCount;
  return DecodeError::kNone;
}

// What SafeDecode says of a raw message of a fixed-size type
// (lcm_limits::Bounds<Msg>::kFixedSize: no string, no variable-length array,
// so no count to bound), told from its size and fingerprint alone: a reader
// that keeps or compares the bytes need not decode them.
template <class Msg>
DecodeError CheckEncoded(const void* data, int size) {
  static_assert(lcm_limits::Bounds<Msg>::kFixedSize, "a type with counts must be decoded");
  if (size > lcm_limits::kMaxEncodedSize<Msg>) return DecodeError::kTooLarge;
  std::int64_t fp = 0;
  if (!ReadFingerprint(data, size, &fp)) return DecodeError::kTruncated;
  if (fp != Msg::getHash()) return DecodeError::kWrongType;
  if (size < lcm_limits::kMaxEncodedSize<Msg>) return DecodeError::kTruncated;
  return DecodeError::kNone;
}

template <class Msg>
std::vector<std::uint8_t> EncodeMessage(const Msg& msg) {
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(msg.getEncodedSize()));
  const int n = msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
  if (n < 0) buf.clear();
  return buf;
}

}  // namespace rms::wire
