#pragma once
// The one reader of a session's LCM log (docs/sessions.md "The session
// log"): the summary, the re-simulation, the export, the report and the
// comparison all read SESSION/lcmlog through it. It gives the session's own
// messages only (SenderCheck: docs/security.md "What the summary trusts"),
// on the channels asked for (the rest are skipped undecoded), each with its
// base channel, the recorder's time and the session time.
#include <atomic>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "rms/base/other_core.h"
#include "rms/session/sender_check.h"
#include "rms/wire/message_io.h"

namespace rms::session {

class RawLogReader;

// One logged message of the session's own.
struct LogMessage {
  std::string_view base;     // channel without the session's suffix ("RMS_DCP_FRAME")
  std::string_view channel;  // as logged
  std::int64_t log_us = 0;   // the recorder's receive time, us since 1970
  double log_time_s = 0;     // the same, s since the log's first event
  // Session time, s: the operator frame of the message (RMS_OPERATOR_INPUT)
  // or the last one logged before it, over the frame rate. It stands still
  // while the session is frozen and reads as flown at any --speed
  // (docs/sessions.md "Session time").
  double session_time_s = 0;
  const void* data = nullptr;
  int size = 0;
};

class SessionLog {
 public:
  // SESSION/lcmlog, SESSION/manifest.json (the session's id and suffix) and
  // the frame rate of SESSION/config.toml. Throws rms::InputError naming what
  // is missing or unreadable.
  explicit SessionLog(const std::string& session_dir);
  // The same with the session's frame rate already known (its config.toml
  // read by the caller): not read again. kNoSessionTime: a reader that
  // needs no session time (every session_time_s is NaN).
  // `log_name`: another log of the session's folder than lcmlog (a running
  // session's wire.lcmlog, the network's record so far).
  SessionLog(const std::string& session_dir, double frame_rate_hz,
             const std::string& log_name = "lcmlog");
  static constexpr double kNoSessionTime = std::numeric_limits<double>::quiet_NaN();

  // Every message of the session's own on `channels` (base names; empty:
  // every channel), in log order. Messages of other sessions and other
  // senders are counted in check() and skipped.
  void Read(std::initializer_list<std::string_view> channels,
            const std::function<void(const LogMessage&)>& visit);

  // How ReadInTwo shares the reading out.
  struct TwoParts {
    OtherCore* other = nullptr;       // the other core; null: all on this thread
    std::function<void()> meanwhile;  // this thread's own work first (may be none)
    double second_share = 0.5;        // the part of the log's bytes the other core reads
  };
  // The same in two parts at once: the log's first part on this thread, once
  // parts.meanwhile has run on it, and its second on parts.other (from the
  // first event at or after the point second_share of the bytes before the
  // end), for a reader that keeps each part on its own and joins them:
  // visit(0, m) on this thread, visit(1, m) on the other. True when the
  // second part stands: this thread's reading reached the event the other
  // began at. False when it does not (no other core, a log under 1 MiB, the
  // other not started by the time this thread reached that point, or the
  // point's first sync word not where an event of the whole log begins):
  // this thread then read the whole log itself, its part 0 is all of it,
  // and what part 1 visited is to be dropped. Every message of part 1
  // before its own first RMS_OPERATOR_INPUT has session_time_s 0 (a reader
  // that needs the session time reads with Read).
  static constexpr std::uintmax_t kTwoPartsFromBytes = 1 << 20;  // smaller: one part
  bool ReadInTwo(std::initializer_list<std::string_view> channels,
                 const std::function<void(int part, const LogMessage&)>& visit,
                 const TwoParts& parts);

  // Decodes a message; a malformed one is counted (malformed()) and false.
  template <class Msg>
  bool Decode(const LogMessage& m, Msg* out) {
    if (wire::SafeDecode(m.data, m.size, out) == wire::DecodeError::kNone) return true;
    ++malformed_.n;
    return false;
  }
  // The same for a message of a fixed-size type kept undecoded
  // (wire::CheckEncoded): true exactly when Decode would be.
  template <class Msg>
  bool Check(const LogMessage& m) {
    if (wire::CheckEncoded<Msg>(m.data, m.size) == wire::DecodeError::kNone) return true;
    ++malformed_.n;
    return false;
  }
  const std::string& dir() const { return dir_; }
  const std::string& log_path() const { return log_path_; }
  const std::string& suffix() const { return suffix_; }
  double frame_rate_hz() const { return rate_hz_; }
  // Of the last Read: events in the log, its first and last event's time.
  std::int64_t events() const { return events_; }
  std::int64_t first_us() const { return first_us_; }
  std::int64_t last_us() const { return last_us_; }
  std::int64_t malformed() const { return malformed_.n; }
  // Of the last Read: bytes at the log's end that are no whole event (a log
  // cut short, or garbage after it): left out, and said by its readers.
  std::int64_t unread_bytes() const { return unread_bytes_; }
  // Of the last Read: bytes passed over inside the log, between whole
  // events (damage: docs/sessions.md "A damaged log"), in how many places,
  // and the first few of them ({from byte, bytes}).
  std::int64_t skipped_bytes() const { return skipped_bytes_; }
  std::int64_t skipped_places() const { return skipped_places_; }
  const std::vector<std::pair<std::int64_t, std::int64_t>>& skipped_stretches() const {
    return skipped_stretches_;
  }
  SenderCheck& check() { return check_; }

 private:
  // One reading's tally, its own sender check's counts among it.
  struct Pass {
    SenderCheck* check = nullptr;
    std::int64_t events = 0, first_us = -1, last_us = -1, input_frame = -1;
  };
  void ReadEvents(RawLogReader& log, std::initializer_list<std::string_view> channels, Pass* pass,
                  const std::function<void(const LogMessage&)>& visit);

  std::string dir_, log_path_, suffix_;
  double rate_hz_ = 30.0;
  SenderCheck check_;
  std::int64_t events_ = 0, first_us_ = -1, last_us_ = -1, unread_bytes_ = 0;
  std::int64_t skipped_bytes_ = 0, skipped_places_ = 0;
  std::vector<std::pair<std::int64_t, std::int64_t>> skipped_stretches_;
  void NoteSkipped(const RawLogReader& log);  // adds the reader's damage
  // Counted by both parts' readers (ReadInTwo); copied with the log.
  struct Count {
    std::atomic<std::int64_t> n = 0;
    Count() = default;
    Count(const Count& o) : n(o.n.load()) {}
    Count& operator=(const Count& o) {
      n = o.n.load();
      return *this;
    }
  } malformed_;
};

}  // namespace rms::session
