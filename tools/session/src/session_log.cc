#include "rms/session/session_log.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/base/other_core.h"
#include "rms/session/manifest.h"
#include "rms/session/session_folder.h"
#include "rms/wire/channels.h"

#include "raw_log.h"

namespace fs = std::filesystem;

namespace rms::session {

namespace {

// The session's frame rate from its config.toml; a session without its
// config: the report's rate (docs/config.md).
double SessionFrameRate(const std::string& session_dir) {
  try {
    return LoadSessionConfig(session_dir).session.frame_rate_hz;
  } catch (const std::exception&) {
    return 30.0;
  }
}

}  // namespace

SessionLog::SessionLog(const std::string& session_dir, double frame_rate_hz,
                       const std::string& log_name)
    : dir_(session_dir),
      log_path_((fs::path(session_dir) / log_name).string()),
      rate_hz_(frame_rate_hz) {
  if (!fs::exists(log_path_))
    throw InputError(session_dir + ": not a session folder (no " + log_name + ")");
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
  Pass pass{&check_};
  ReadEvents(log, channels, &pass, visit);
  events_ = pass.events;
  first_us_ = pass.first_us;
  last_us_ = pass.last_us;
  unread_bytes_ = static_cast<std::int64_t>(log.size() - log.good_end());
  skipped_bytes_ = skipped_places_ = 0;
  skipped_stretches_.clear();
  NoteSkipped(log);
}

void SessionLog::NoteSkipped(const RawLogReader& log) {
  skipped_bytes_ += static_cast<std::int64_t>(log.skipped_bytes());
  skipped_places_ += static_cast<std::int64_t>(log.skipped_count());
  for (const auto& st : log.skipped_stretches()) {
    if (skipped_stretches_.size() < RawLogReader::kMaxStretches)
      skipped_stretches_.emplace_back(static_cast<std::int64_t>(st.from),
                                      static_cast<std::int64_t>(st.bytes));
  }
}

void SessionLog::ReadEvents(RawLogReader& log, std::initializer_list<std::string_view> channels,
                            Pass* pass, const std::function<void(const LogMessage&)>& visit) {
  RawLogEvent ev;
  while (log.Next(&ev)) {
    ++pass->events;
    if (pass->first_us < 0) pass->first_us = ev.timestamp_us;
    pass->last_us = ev.timestamp_us;
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
    int size = ev.size;
    if (pass->check->Ignore(channel, ev.channel, ev.data, &size)) continue;
    std::int64_t f = 0;
    if (input && wire::ReadFrameNumber(ev.data, ev.size, &f) && f >= 0) pass->input_frame = f;
    if (!wanted) continue;
    LogMessage m;
    m.base = channel;
    m.channel = ev.channel;
    m.log_us = ev.timestamp_us;
    m.log_time_s = (ev.timestamp_us - pass->first_us) * 1e-6;
    m.session_time_s = pass->input_frame < 0 ? 0.0 : pass->input_frame / rate_hz_;
    m.data = ev.data;
    m.size = size;
    visit(m);
  }
}

bool SessionLog::ReadInTwo(std::initializer_list<std::string_view> channels,
                           const std::function<void(int part, const LogMessage&)>& visit,
                           const TwoParts& parts) {
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(log_path_, ec);
  if (ec || size < kTwoPartsFromBytes || !parts.other) {
    if (parts.meanwhile) parts.meanwhile();
    Read(channels, [&](const LogMessage& m) { visit(0, m); });
    return false;
  }
  OtherCore* other = parts.other;
  const double share = std::clamp(parts.second_share, 0.0, 1.0);
  const auto middle = static_cast<std::size_t>(static_cast<double>(size) * (1.0 - share));
  SenderCheck second_check = check_;
  Pass second{&second_check};
  std::size_t second_start = 0, second_unread = 0;
  std::optional<RawLogReader> second_reader;
  other->Start([&] {
    RawLogEvent ev;
    RawLogReader start(log_path_);  // the log's first time, for log_time_s
    if (start.Next(&ev)) second.first_us = ev.timestamp_us;
    RawLogReader& log = second_reader.emplace(log_path_, middle);
    ReadEvents(log, channels, &second, [&](const LogMessage& m) { visit(1, m); });
    second_start = log.first_event_start();
    second_unread = log.size() - log.good_end();
  });
  std::optional<RawLogReader> reader;
  Pass first{&check_};
  try {
    if (parts.meanwhile) parts.meanwhile();
    reader.emplace(log_path_);
    reader->StopAt(middle);
    ReadEvents(*reader, channels, &first, [&](const LogMessage& m) { visit(0, m); });
  } catch (...) {
    other->Finish();  // the other part's reading refers to this frame's variables
    throw;
  }
  // An event of the whole log starts where this thread stopped; the other
  // began at the first sync word at or after the middle: the same event
  // exactly when both name one place.
  RawLogReader& log = *reader;
  skipped_bytes_ = skipped_places_ = 0;
  skipped_stretches_.clear();
  const bool stands = other->Finish() && !other->error() && log.stopped() && second.events > 0 &&
                      log.stopped_at() == second_start;
  if (stands) {
    check_.Add(second_check);
    events_ = first.events + second.events;
    first_us_ = first.first_us;
    last_us_ = second.last_us;
    unread_bytes_ = static_cast<std::int64_t>(second_unread);
    NoteSkipped(log);
    if (second_start > log.good_end()) {  // damage just before the second part's first event
      skipped_bytes_ += static_cast<std::int64_t>(second_start - log.good_end());
      ++skipped_places_;
      if (skipped_stretches_.size() < RawLogReader::kMaxStretches)
        skipped_stretches_.emplace_back(static_cast<std::int64_t>(log.good_end()),
                                        static_cast<std::int64_t>(second_start - log.good_end()));
    }
    NoteSkipped(*second_reader);
    return true;
  }
  log.Resume();  // this thread reads on through the second part
  ReadEvents(log, channels, &first, [&](const LogMessage& m) { visit(0, m); });
  events_ = first.events;
  first_us_ = first.first_us;
  last_us_ = first.last_us;
  unread_bytes_ = static_cast<std::int64_t>(log.size() - log.good_end());
  NoteSkipped(log);
  return false;
}

}  // namespace rms::session
