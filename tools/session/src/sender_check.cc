#include "rms/session/sender_check.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "rms/base/check.h"
#include "rms/sender_t.hpp"
#include "rms/session/manifest.h"
#include "rms/session/session_folder.h"
#include "rms/wire/channels.h"
#include "rms/wire/message_io.h"

namespace fs = std::filesystem;

namespace rms::session {

namespace {

// Who publishes each channel (docs/protocol.md "Channels").
bool Publishes(std::string_view base, std::int8_t process) {
  using S = sender_t;
  if (base == wire::channels::kOperatorInput || base == wire::channels::kOperatorState)
    return process == S::PROCESS_OPERATOR_STATION;
  if (base == wire::channels::kDcpFrame || base == wire::channels::kDcpTelemetry ||
      base == wire::channels::kDcpState) {
    return process == S::PROCESS_DYNAMICS;
  }
  if (base == wire::channels::kEsgFrame) return process == S::PROCESS_SCENE;
  if (base == wire::channels::kWindowKeys) return process == S::PROCESS_ESG;
  if (base == wire::channels::kControlAnswer)
    return process == S::PROCESS_OPERATOR_STATION || process == S::PROCESS_DYNAMICS;
  if (base == wire::channels::kControl) {
    return process == S::PROCESS_CONTROL || process == S::PROCESS_OPERATOR_STATION ||
           process == S::PROCESS_INSTRUCTOR;
  }
  if (base == wire::channels::kStatus) {
    return process == S::PROCESS_OPERATOR_STATION || process == S::PROCESS_DYNAMICS ||
           process == S::PROCESS_SCENE || process == S::PROCESS_ESG ||
           process == S::PROCESS_INSTRUCTOR;
  }
  return false;
}

}  // namespace

SenderCheck::SenderCheck(const std::string& dir) {
  if (fs::exists(fs::path(dir) / "manifest.json")) {
    const SessionInfo info = ReadSessionInfo(dir);
    session_id_ = info.session_id;
    tagged_ = !info.message_auth.empty();
    // A copy without its run/ folder is read with its tags unchecked, and
    // says so (docs/security.md "Authenticated messages").
    if (tagged_ && fs::exists(fs::path(dir) / "run" / "session.key")) key_ = ReadSessionKey(dir);
    if (tags_unchecked())
      std::fprintf(stderr,
                   "%s: its messages carry tags but run/session.key is not there: read WITHOUT "
                   "checking them (a stranger's message with the session's id would be taken)\n",
                   dir.c_str());
  }
  std::error_code ec;
  std::istringstream f(fs::exists(fs::symlink_status(fs::path(dir) / "run" / "pids", ec))
                           ? ReadSessionFile(dir, "run/pids", kMaxRunFileBytes)
                           : std::string());
  std::string name;
  long pid = 0;
  while (f >> name >> pid) pids_[wire::ProcessCode(name)].insert(static_cast<std::int32_t>(pid));
}

const char* SenderCheck::Ignore(std::string_view base, std::string_view channel, const void* data,
                                int* size) {
  if (session_id_ == 0) return nullptr;  // recorded before session ids: nothing to tell them by
  const char* why = nullptr;
  std::int64_t id = 0;
  std::int8_t process = 0;
  std::int32_t pid = 0;
  if (!wire::ReadSessionId(data, *size, &id) ||
      !wire::ReadSenderProcess(data, *size, &process, &pid)) {
    why = "no_sender";
  } else if (id != session_id_) {
    why = "other_session";
    other_sessions_.insert(id);
  } else if ((tagged_ && *size <= 8 + wire::kSenderBytes + wire::kMacBytes) ||
             (key_ && !wire::VerifyMessageMac(*key_, channel, data, *size))) {
    why = "bad_mac";
  } else if (!Publishes(base, process)) {
    why = "not_the_publisher";
  } else if (pids_.count(process) && !pids_.at(process).count(pid)) {
    // Only the pids the launcher knows (run/pids); a process it knows none
    // of (one on an ssh host; rms_control, which a person runs) is taken by
    // the session id alone.
    why = "not_the_sessions_process";
  }
  if (why) {
    ++ignored_[why];
    return why;
  }
  if (tagged_) *size -= wire::kMacBytes;  // the message's own bytes, its tag left off
  return nullptr;
}

void SenderCheck::Add(const SenderCheck& other) {
  for (const auto& [reason, n] : other.ignored_) ignored_[reason] += n;
  other_sessions_.insert(other.other_sessions_.begin(), other.other_sessions_.end());
}

std::int64_t SenderCheck::ignored_total() const {
  std::int64_t n = 0;
  for (const auto& [k, v] : ignored_) n += v;
  return n;
}

nlohmann::ordered_json SenderCheck::Json() const {
  nlohmann::ordered_json j;
  j["total"] = ignored_total();
  j["by_reason"] = nlohmann::ordered_json::object();
  for (const auto& [k, v] : ignored_) j["by_reason"][k] = v;
  j["other_sessions"] = nlohmann::ordered_json::array();
  for (std::int64_t id : other_sessions_) j["other_sessions"].push_back(wire::FormatSessionId(id));
  j["session_id_checked"] = session_id_ != 0;
  j["macs_checked"] = key_.has_value();
  j["tags_unchecked"] = tags_unchecked();
  j["pids_checked"] = !pids_.empty();
  // The processes whose pids were checked; the others (not in run/pids: an
  // ssh host, a process that never became ready) by the id and publisher only.
  j["pids_checked_for"] = nlohmann::ordered_json::array();
  j["pids_not_checked_for"] = nlohmann::ordered_json::array();
  if (!pids_.empty()) {
    for (std::int8_t p : {sender_t::PROCESS_OPERATOR_STATION, sender_t::PROCESS_DYNAMICS,
                          sender_t::PROCESS_SCENE, sender_t::PROCESS_ESG}) {
      j[pids_.count(p) ? "pids_checked_for" : "pids_not_checked_for"].push_back(
          wire::ProcessCodeName(p));
    }
  }
  return j;
}

}  // namespace rms::session
