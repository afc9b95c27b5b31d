#include "rms/session/session_log.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/session/session_summary.h"
#include "rms/wire/channels.h"

#include "raw_log.h"

namespace fs = std::filesystem;

namespace rms::session {

namespace {

// RMS_OPERATOR_INPUT's frame without decoding the rest: it follows the
// fingerprint and the sender (docs/protocol.md "RMS_OPERATOR_INPUT").
bool InputFrame(const void* data, int size, std::int64_t* frame) {
  constexpr int kAt = 8 + wire::kSenderBytes;
  if (size < kAt + 8) return false;
  const auto* p = static_cast<const std::uint8_t*>(data) + kAt;
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  *frame = static_cast<std::int64_t>(v);
  return true;
}

// The session's frame rate from its config.toml; a session without its
// config: the report's rate (docs/config.md).
double SessionFrameRate(const std::string& session_dir) {
  try {
    return LoadConfig((fs::path(session_dir) / "config.toml").string()).session.frame_rate_hz;
  } catch (const std::exception&) {
    return 30.0;
  }
}

}  // namespace

SessionLog::SessionLog(const std::string& session_dir, double frame_rate_hz)
    : dir_(session_dir),
      log_path_((fs::path(session_dir) / "lcmlog").string()),
      rate_hz_(frame_rate_hz) {
  if (!fs::exists(log_path_)) throw InputError(session_dir + ": not a session folder (no lcmlog)");
  if (fs::exists(fs::path(session_dir) / "manifest.json")) {
    suffix_ = ReadSessionInfo(session_dir).channel_suffix;
    check_ = SenderCheck(session_dir);
  }
}

SessionLog::SessionLog(const std::string& session_dir)
    : SessionLog(session_dir, SessionFrameRate(session_dir)) {}

void SessionLog::Read(std::initializer_list<std::string_view> channels,
                      const std::function<void(const LogMessage&)>& visit) {
  RawLogReader log(log_path_);
  events_ = 0;
  first_us_ = last_us_ = -1;
  std::int64_t input_frame = -1;
  RawLogEvent ev;
  while (log.Next(&ev)) {
    ++events_;
    if (first_us_ < 0) first_us_ = ev.timestamp_us;
    last_us_ = ev.timestamp_us;
    std::string_view channel = ev.channel;
    if (!suffix_.empty()) {
      if (channel.size() <= suffix_.size() ||
          channel.substr(channel.size() - suffix_.size()) != suffix_)
        continue;
      channel.remove_suffix(suffix_.size());
    }
    // Only the channels asked for are looked at (and the operator's, for the
    // session time): the rest are skipped by their length, unread.
    const bool wanted = channels.size() == 0 ||
                        std::find(channels.begin(), channels.end(), channel) != channels.end();
    const bool input = channel == wire::channels::kOperatorInput;
    if (!wanted && !input) continue;
    if (check_.Ignore(channel, ev.data, ev.size)) continue;
    std::int64_t f = 0;
    if (input && InputFrame(ev.data, ev.size, &f) && f >= 0) input_frame = f;
    if (!wanted) continue;
    LogMessage m;
    m.base = channel;
    m.channel = ev.channel;
    m.log_us = ev.timestamp_us;
    m.log_time_s = (ev.timestamp_us - first_us_) * 1e-6;
    m.session_time_s = input_frame < 0 ? 0.0 : input_frame / rate_hz_;
    m.data = ev.data;
    m.size = ev.size;
    visit(m);
  }
  unread_bytes_ = static_cast<std::int64_t>(log.size() - log.good_end());
}

}  // namespace rms::session
