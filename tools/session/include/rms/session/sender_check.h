#pragma once
// Which logged messages are the session's own (docs/security.md "What the
// summary trusts"). The recorder logs everything on the session's channels,
// strangers' messages included; every tool that reads the log -- the
// summary, the export, the re-simulation, the report -- takes only messages
// that carry the session's id (manifest.json) from a process of the session
// that publishes that channel, with one of the pids the session's processes
// wrote in their ready files (run/pids). What it leaves out is counted by
// reason, and the summary lists it.
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <string_view>

#include "rms/wire/message_auth.h"

namespace rms::session {

class SenderCheck {
 public:
  // Reads SESSION/manifest.json (session_id, message_auth), the session's
  // key when its messages carry tags (run/session.key: an InputError when
  // it is there and cannot be read; when it is not there, the tags are
  // left off unchecked, and Json() says so) and SESSION/run/pids ("NAME
  // PID" lines). A session from before session ids
  // (no session_id) takes every message; a process with no pid in run/pids (on an ssh host, or
  // rms_control) is checked by the id and the publisher only.
  explicit SenderCheck(const std::string& session_dir);
  // Takes no session: everything (a log that is not a session's).
  SenderCheck() = default;

  // The reason to leave this logged message out, or nullptr to take it:
  // "other_session", "bad_mac" (the session's messages carry tags and this
  // one's is not its key's), "not_the_publisher" (a process that does not
  // publish that channel), "not_the_sessions_process" (a pid none of the
  // session's processes had), "no_sender" (too short to carry one).
  // base_channel: the channel without the session's suffix; channel: as
  // logged. Taken, *size is the message's own (its tag left off). Counts
  // what it leaves out.
  const char* Ignore(std::string_view base_channel, std::string_view channel, const void* data,
                     int* size);
  // A message left out for a reason of the caller's own (e.g. telemetry no
  // DCP frame confirms): counted with the rest.
  void Count(const std::string& reason, std::int64_t n = 1) {
    if (n > 0) ignored_[reason] += n;
  }

  // Another check's counts (of another part of the same log) added to these.
  void Add(const SenderCheck& other);

  std::int64_t session_id() const { return session_id_; }
  bool checks_macs() const { return key_.has_value(); }
  // The session's messages carry tags, but its key is missing: read
  // without checking them.
  bool tags_unchecked() const { return tagged_ && !key_; }
  bool checks_pids() const { return !pids_.empty(); }
  std::int64_t ignored_total() const;
  // {"total": N, "by_reason": {...}, "other_sessions": ["0x...", ...]}
  nlohmann::ordered_json Json() const;

 private:
  std::int64_t session_id_ = 0;
  std::optional<wire::SessionKey> key_;
  bool tagged_ = false;
  std::map<std::int8_t, std::set<std::int32_t>> pids_;  // by sender_t::PROCESS_*
  std::map<std::string, std::int64_t> ignored_;
  std::set<std::int64_t> other_sessions_;
};

}  // namespace rms::session
