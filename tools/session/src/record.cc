#include "rms/session/record.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <queue>
#include <set>
#include <unordered_map>
#include <vector>

#include "rms/base/check.h"
#include "rms/base/text.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/operator_input_t.hpp"
#include "rms/session/session_summary.h"
#include "rms/transport/journal.h"
#include "rms/wire/channels.h"
#include "rms/wire/message_auth.h"
#include "rms/wire/message_io.h"

#include "raw_log.h"

namespace fs = std::filesystem;

namespace rms::session {

namespace {

constexpr const char* kJournalDir = "journal";
constexpr const char* kWireLog = "wire.lcmlog";

// A message by its channel and bytes: two 64-bit hashes and the size (two
// different messages alike in all three: about one chance in 2^128).
struct MessageKey {
  std::size_t a = 0, b = 0;
  std::int32_t size = 0;
  bool operator==(const MessageKey&) const = default;
};
struct MessageKeyHash {
  std::size_t operator()(const MessageKey& k) const { return k.a; }
};
MessageKey KeyOf(const RawLogEvent& ev) {
  // Fixed seeds: the same sources always make the same record.
  const std::size_t ca = std::_Hash_bytes(ev.channel.data(), ev.channel.size(), 0x9e3779b9u);
  const std::size_t cb = std::_Hash_bytes(ev.channel.data(), ev.channel.size(), 0x85ebca6bu);
  return {std::_Hash_bytes(ev.data, static_cast<std::size_t>(ev.size), ca),
          std::_Hash_bytes(ev.data, static_cast<std::size_t>(ev.size), cb ^ 0xc2b2ae35u), ev.size};
}

// A journal file and what its name says.
struct JournalFile {
  fs::path path;
  std::string process;
  int run = 0;
};

// SESSION/journal/PROCESS.N.lcmlog, in name order (the process, then the run).
std::vector<JournalFile> FindJournals(const fs::path& dir) {
  std::vector<JournalFile> out;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    constexpr std::string_view kExt = ".lcmlog";
    if (!entry.is_regular_file() || name.size() <= kExt.size() ||
        name.compare(name.size() - kExt.size(), kExt.size(), kExt) != 0)
      continue;
    const std::string stem = name.substr(0, name.size() - kExt.size());
    const auto dot = stem.rfind('.');
    JournalFile j{entry.path(), stem, 0};
    if (dot != std::string::npos && dot + 1 < stem.size() &&
        stem.find_first_not_of("0123456789", dot + 1) == std::string::npos) {
      j.process = stem.substr(0, dot);
      j.run = std::stoi(stem.substr(dot + 1, 6));
    }
    out.push_back(std::move(j));
  }
  if (ec) throw InputError(dir.string() + ": cannot be listed: " + ec.message());
  std::sort(out.begin(), out.end(), [](const JournalFile& x, const JournalFile& y) {
    return x.process != y.process ? x.process < y.process : x.run < y.run;
  });
  return out;
}

// The record written beside its place, whole or not at all.
class LogWriter {
 public:
  explicit LogWriter(std::string path) : path_(std::move(path)) {
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0) throw InputError("cannot write " + path_ + ": " + std::strerror(errno));
    buf_.reserve(kFlushBytes + 4096);
  }
  ~LogWriter() {
    if (fd_ >= 0) {
      ::close(fd_);
      ::unlink(path_.c_str());  // not finished: no part of a record stays
    }
  }
  void Write(const RawLogEvent& ev) {
    transport::AppendLogEvent(events_++, ev.timestamp_us, ev.channel, ev.data, ev.size, &buf_);
    if (buf_.size() >= kFlushBytes) Flush();
  }
  // Written and on the disk, then renamed into `final_path`.
  void Finish(const std::string& final_path) {
    Flush();
    if (::fsync(fd_) != 0) Fail();
    if (::close(fd_) != 0) {
      fd_ = -1;
      ::unlink(path_.c_str());
      throw InputError("cannot write " + path_ + ": " + std::strerror(errno));
    }
    fd_ = -1;
    if (std::rename(path_.c_str(), final_path.c_str()) != 0) {
      const int e = errno;
      ::unlink(path_.c_str());
      throw InputError("cannot make " + final_path + ": " + std::strerror(e));
    }
  }
  std::int64_t events() const { return events_; }

 private:
  static constexpr std::size_t kFlushBytes = 1 << 20;
  void Flush() {
    std::size_t done = 0;
    while (done < buf_.size()) {
      const ssize_t n = ::write(fd_, buf_.data() + done, buf_.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) Fail();
      done += static_cast<std::size_t>(n);
    }
    buf_.clear();
  }
  [[noreturn]] void Fail() {
    const int e = errno ? errno : ENOSPC;
    throw InputError("cannot write " + path_ + ": " + std::strerror(e) +
                     " (the journals and wire.lcmlog are left as they were)");
  }
  std::string path_;
  int fd_ = -1;
  std::int64_t events_ = 0;
  std::vector<std::uint8_t> buf_;
};

// One source of the merge: a log read event by event, its current event
// held; the recorder's skips what a journal holds.
struct Source {
  std::unique_ptr<RawLogReader> reader;
  RawLogEvent ev;
  bool has = false;
  bool wire = false;
  std::size_t index = 0;  // the order among sources, for events of one time
};

struct Tally {
  std::int64_t events = 0;
  std::map<std::string, std::int64_t> by_channel;
  std::int64_t unread_bytes = 0;   // at its end: no whole event
  std::int64_t skipped_bytes = 0;  // inside it: damage read past
};

using Counts = std::unordered_map<MessageKey, std::int64_t, MessageKeyHash>;

// The frame numbers the journals hold, by channel as logged, of the four
// numbered streams (docs/sessions.md "The record": `frames_by_channel`).
using FrameNumbers = std::map<std::string, std::set<std::int64_t>>;

template <typename T>
void AddFrameOf(const RawLogEvent& ev, FrameNumbers* frames) {
  T m;  // a session with a key: the message's bytes, then its tag
  if (wire::SafeDecode(ev.data, ev.size, &m) == wire::DecodeError::kNone ||
      (ev.size > wire::kMacBytes &&
       wire::SafeDecode(ev.data, ev.size - wire::kMacBytes, &m) == wire::DecodeError::kNone))
    (*frames)[std::string(ev.channel)].insert(m.frame);
}

// A publisher may send one number twice (a receiver that followed a
// sender's numbering back: docs/protocol.md "Frame numbers"), so the
// summary holds the log's distinct numbers against these, not against the
// journals' message counts.
void AddFrameNumber(const RawLogEvent& ev, FrameNumbers* frames) {
  const std::string base = BaseChannel(std::string(ev.channel));
  if (base == wire::channels::kOperatorInput)
    AddFrameOf<operator_input_t>(ev, frames);
  else if (base == wire::channels::kDcpFrame)
    AddFrameOf<dcp_frame_t>(ev, frames);
  else if (base == wire::channels::kDcpTelemetry)
    AddFrameOf<dcp_telemetry_t>(ev, frames);
  else if (base == wire::channels::kEsgFrame)
    AddFrameOf<esg_frame_t>(ev, frames);
}

// Pass one: every journal's events by message, and each one's tally.
std::vector<Tally> CountJournals(const std::vector<JournalFile>& journals, Counts* held,
                                 FrameNumbers* frames) {
  std::vector<Tally> tallies(journals.size());
  for (std::size_t i = 0; i < journals.size(); ++i) {
    RawLogReader r(journals[i].path.string());
    RawLogEvent ev;
    while (r.Next(&ev)) {
      ++(*held)[KeyOf(ev)];
      ++tallies[i].events;
      ++tallies[i].by_channel[std::string(ev.channel)];
      AddFrameNumber(ev, frames);
    }
    tallies[i].unread_bytes = static_cast<std::int64_t>(r.size() - r.good_end());
    tallies[i].skipped_bytes = static_cast<std::int64_t>(r.skipped_bytes());
  }
  return tallies;
}

// What the merge made of the recorder's events.
struct WireTally {
  Tally heard;                  // every event of wire.lcmlog
  std::int64_t only = 0;        // kept: no journal holds the message
  std::int64_t duplicated = 0;  // left out: a journal's message the wire delivered again
  std::map<std::string, std::int64_t> duplicated_by_channel;
};

// The next event of a source; the recorder's own only where no journal
// holds the message (each journal event answers one of the recorder's; a
// copy of a journal's message beyond those is the network's duplicate, not
// something published: counted and left out, since its receive time would
// put it after what its sender published next).
bool Advance(Source* s, Counts* held, WireTally* wire) {
  while (s->reader->Next(&s->ev)) {
    if (!s->wire) return s->has = true;
    ++wire->heard.events;
    ++wire->heard.by_channel[std::string(s->ev.channel)];
    const auto it = held->find(KeyOf(s->ev));
    if (it != held->end()) {
      if (it->second > 0) {
        --it->second;
      } else {
        ++wire->duplicated;
        ++wire->duplicated_by_channel[std::string(s->ev.channel)];
      }
      continue;
    }
    ++wire->only;
    return s->has = true;
  }
  return s->has = false;
}

nlohmann::ordered_json TallyJson(const Tally& t) {
  return {{"events", t.events},
          {"by_channel", t.by_channel},
          {"unread_bytes", t.unread_bytes},
          {"skipped_bytes", t.skipped_bytes}};
}

// What the merge made of its sources.
struct Merged {
  std::int64_t events = 0, from_journals = 0;
  WireTally wire;
};

// Pass two: the journals' events and the recorder's that no journal holds,
// in time order (of one time: journals by name, the recorder last: every
// source's own order kept), written to `out_path` whole.
Merged Merge(const std::vector<JournalFile>& journals, const std::vector<Tally>& tallies,
             const fs::path& wire_path, Counts* held, const fs::path& out_path) {
  std::vector<Source> sources;
  for (std::size_t i = 0; i < journals.size(); ++i) {
    sources.push_back(
        {std::make_unique<RawLogReader>(journals[i].path.string()), {}, false, false, i});
  }
  const bool have_wire = fs::exists(wire_path);
  if (have_wire)
    sources.push_back(
        {std::make_unique<RawLogReader>(wire_path.string()), {}, false, true, journals.size()});
  Merged m;
  auto later = [&](std::size_t x, std::size_t y) {
    const Source &a = sources[x], &b = sources[y];
    return a.ev.timestamp_us != b.ev.timestamp_us ? a.ev.timestamp_us > b.ev.timestamp_us
                                                  : a.index > b.index;
  };
  std::priority_queue<std::size_t, std::vector<std::size_t>, decltype(later)> next(later);
  for (std::size_t i = 0; i < sources.size(); ++i)
    if (Advance(&sources[i], held, &m.wire)) next.push(i);
  LogWriter out(out_path.string() + ".making");
  while (!next.empty()) {
    const std::size_t i = next.top();
    next.pop();
    out.Write(sources[i].ev);
    if (Advance(&sources[i], held, &m.wire)) next.push(i);
  }
  if (have_wire) {
    const RawLogReader& w = *sources.back().reader;
    m.wire.heard.unread_bytes = static_cast<std::int64_t>(w.size() - w.good_end());
    m.wire.heard.skipped_bytes = static_cast<std::int64_t>(w.skipped_bytes());
  }
  for (const Tally& t : tallies) m.from_journals += t.events;
  m.events = out.events();
  RMS_CHECK(m.events == m.from_journals + m.wire.only);
  out.Finish(out_path.string());
  return m;
}

// The journals' messages no recorder event answered (`held` after the
// merge), by channel: what the network's recorder missed.
std::map<std::string, std::int64_t> MissedByWire(const std::vector<JournalFile>& journals,
                                                 Counts held, std::int64_t* total) {
  std::map<std::string, std::int64_t> missed;
  *total = 0;
  for (const JournalFile& jf : journals) {
    RawLogReader r(jf.path.string());
    RawLogEvent ev;
    while (r.Next(&ev)) {
      const auto it = held.find(KeyOf(ev));
      if (it != held.end() && it->second > 0) {
        --it->second;
        ++missed[std::string(ev.channel)];
        ++*total;
      }
    }
  }
  return missed;
}

// record.json (docs/sessions.md "The record").
nlohmann::ordered_json RecordJson(const std::vector<JournalFile>& journals,
                                  const std::vector<Tally>& tallies, const Merged& m,
                                  bool have_wire, const std::map<std::string, std::int64_t>& missed,
                                  std::int64_t missed_total, bool kept) {
  nlohmann::ordered_json j;
  j["format"] = "rmslab-record-1";
  j["made"] = true;
  j["lcmlog"] = {
      {"events", m.events}, {"from_journals", m.from_journals}, {"from_wire_only", m.wire.only}};
  j["journals"] = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < journals.size(); ++i) {
    nlohmann::ordered_json e = {
        {"file", std::string(kJournalDir) + "/" + journals[i].path.filename().string()},
        {"process", journals[i].process},
        {"run", journals[i].run}};
    e.update(TallyJson(tallies[i]));
    j["journals"].push_back(std::move(e));
  }
  j["wire"] = {{"file", kWireLog}, {"present", have_wire}};
  if (have_wire) j["wire"].update(TallyJson(m.wire.heard));
  j["wire"]["only_there"] = m.wire.only;
  j["wire"]["duplicated"] = {{"total", m.wire.duplicated},
                             {"by_channel", m.wire.duplicated_by_channel}};
  j["wire"]["missed"] = {{"total", missed_total}, {"by_channel", missed}};
  j["journals_kept"] = kept;
  return j;
}

nlohmann::ordered_json NotMade(const std::string& why) {
  return {{"format", "rmslab-record-1"}, {"made", false}, {"why", why}};
}

}  // namespace

nlohmann::ordered_json MakeRecord(const std::string& session_dir, const RecordOptions& options) {
  const fs::path root(session_dir);
  const fs::path jdir = root / kJournalDir, wire_path = root / kWireLog;
  if (!fs::is_directory(jdir)) {
    return NotMade(fs::exists(root / "lcmlog")
                       ? "no journal/ folder: the record is made already, or the session kept "
                         "no journals"
                       : "no journal/ folder and no lcmlog");
  }
  const std::vector<JournalFile> journals = FindJournals(jdir);
  // Nothing to make it from (a session whose processes kept no journal, or
  // a re-simulation's folder): whatever lcmlog there is stays.
  if (journals.empty()) return NotMade("no journal in journal/");
  Counts held;
  FrameNumbers frames;
  const std::vector<Tally> tallies = CountJournals(journals, &held, &frames);
  const Merged m = Merge(journals, tallies, wire_path, &held, root / "lcmlog");
  std::int64_t missed_total = 0;
  const auto missed = MissedByWire(journals, held, &missed_total);
  // A journal that holds bytes that are no event (damaged inside, or cut
  // short by a full disk) is kept, with every other, for whoever looks into
  // it: what the damage held is not in the record.
  const bool damaged = std::any_of(tallies.begin(), tallies.end(), [](const Tally& t) {
    return t.unread_bytes > 0 || t.skipped_bytes > 0;
  });
  const bool keep = options.keep_journals || damaged;
  nlohmann::ordered_json j =
      RecordJson(journals, tallies, m, fs::exists(wire_path), missed, missed_total, keep);
  for (const auto& [channel, numbers] : frames)
    j["frames_by_channel"][channel] = static_cast<std::int64_t>(numbers.size());
  WriteWholeFile((root / "record.json").string(), j.dump(2) + "\n");
  if (!keep) {
    for (const JournalFile& jf : journals) fs::remove(jf.path);
    std::error_code ec;
    fs::remove(jdir, ec);  // only when empty: anything else there stays
  }
  return j;
}

}  // namespace rms::session
