#include "rms/session/session_summary.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/base/counters.h"
#include "rms/base/text.h"
#include "rms/control_answer_t.hpp"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_state_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/operator_state_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/session/sender_check.h"
#include "rms/session/session_folder.h"
#include "rms/session/session_log.h"
#include "rms/session_control_t.hpp"
#include "rms/transport/process.h"
#include "rms/wire/channels.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/collision_bits.h"
#include "rms/wire/control_word.h"
#include "rms/wire/malfunction.h"
#include "rms/wire/message_io.h"

#include "attempts.h"
#include "log_scan.h"

namespace fs = std::filesystem;

namespace rms::session {

namespace {

// A run/ file of the session ("" when it has none), read as untrusted
// (rms/session/session_folder.h).
std::string RunFile(const fs::path& root, const std::string& name) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(root / name, ec))) return "";
  return ReadSessionFile(root.string(), name, kMaxRunFileBytes);
}

nlohmann::json ReadJson(const fs::path& p) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(p, ec))) return nlohmann::json::object();
  try {
    return nlohmann::json::parse(
        ReadRegularFile(p.string(), "the session's " + p.filename().string(), kMaxJsonBytes));
  } catch (const std::exception&) {
    return nlohmann::json::object();
  }
}

// A counter of a process's stats (stats/PROCESS.json), 0 when absent.
std::int64_t CounterOf(const nlohmann::json& stats, rms::Counter counter) {
  if (!stats.contains("counters")) return 0;
  const auto& c = stats["counters"];
  const std::string name(CounterName(counter));
  return c.contains(name) ? c[name].get<std::int64_t>() : 0;
}

// The sum of a family of counters (kDroppedPrefix, kClampedPrefix), by name:
// a session of another version may have had other members.
std::int64_t SumPrefix(const nlohmann::json& stats, std::string_view prefix) {
  std::int64_t s = 0;
  if (!stats.contains("counters")) return 0;
  for (auto it = stats["counters"].begin(); it != stats["counters"].end(); ++it) {
    if (it.key().rfind(prefix, 0) == 0) s += it.value().get<std::int64_t>();
  }
  return s;
}

}  // namespace

std::string BaseChannel(const std::string& channel) {
  for (const char* base :
       {wire::channels::kOperatorInput, wire::channels::kOperatorState, wire::channels::kWindowKeys,
        wire::channels::kDcpTelemetry, wire::channels::kDcpFrame, wire::channels::kEsgFrame,
        wire::channels::kStatus, wire::channels::kControl, wire::channels::kDcpState}) {
    if (channel.rfind(base, 0) == 0) return base;
  }
  return channel;
}

// Declared in session_summary.h.
std::vector<std::size_t> LongestIncreasingRun(const std::vector<std::int64_t>& v) {
  std::vector<std::size_t> tails;
  std::vector<std::ptrdiff_t> parent(v.size(), -1);
  for (std::size_t i = 0; i < v.size(); ++i) {
    const auto it = std::lower_bound(tails.begin(), tails.end(), v[i],
                                     [&v](std::size_t a, std::int64_t x) { return v[a] < x; });
    // A repeat of the value its run ends in (the network's second copy):
    // the first copy stays on the run.
    if (it != tails.end() && v[*it] == v[i]) continue;
    if (it != tails.begin()) parent[i] = static_cast<std::ptrdiff_t>(*(it - 1));
    if (it == tails.end())
      tails.push_back(i);
    else
      *it = i;
  }
  std::vector<std::size_t> run;
  for (std::ptrdiff_t i = tails.empty() ? -1 : static_cast<std::ptrdiff_t>(tails.back()); i >= 0;
       i = parent[i]) {
    run.push_back(static_cast<std::size_t>(i));
  }
  std::reverse(run.begin(), run.end());
  return run;
}

namespace {
// A status run no real process could have reported: a negative count, or
// more frames than the session's length allows at any speed.
bool Plausible(const std::map<std::string, std::int64_t>& run, double duration_s, double rate_hz) {
  const double most = (duration_s + 10.0) * rate_hz * transport::kMaxSessionSpeed + 1000.0;
  for (const auto& [k, v] : run) {
    if (v < 0) return false;
    if (k.rfind("latency.", 0) != 0 && static_cast<double>(v) > most * 100.0) return false;
    if ((k == CounterName(rms::Counter::kPublished) || k == CounterName(rms::Counter::kRendered) ||
         k == CounterName(rms::Counter::kReceived)) &&
        static_cast<double>(v) > most)
      return false;
  }
  return true;
}

// Each process's stats file (the last run's), with the counts of earlier
// runs (ended in a fault, restarted by the launcher) that only RMS_STATUS in
// the log kept (counts only: not the mode, not latency percentiles).
std::map<std::string, nlohmann::json> MergedStats(const fs::path& root, const StatusRuns& st,
                                                  double duration_s, double rate_hz,
                                                  SenderCheck* check) {
  std::map<std::string, nlohmann::json> stats;
  for (const char* p : {"operator_station", "dynamics_proc", "scene_proc", "esg_renderer"}) {
    stats[p] = ReadJson(root / "stats" / (std::string(p) + ".json"));
    const auto runs = st.runs.find(p);
    if (runs == st.runs.end()) continue;
    // No stats file (a full disk at exit, a crash): the last run's counts
    // are its last RMS_STATUS report in the log (said in "stats_from_log").
    const bool no_file = !stats[p].contains("counters");
    if (no_file) stats[p]["from_log"] = true;
    for (const auto& [pid, counters] : runs->second) {
      if (pid == st.last_pid.at(p) && !no_file) continue;
      if (!Plausible(counters, duration_s, rate_hz)) {
        check->Count("implausible_status");
        continue;
      }
      if (!stats[p].contains("counters")) stats[p]["counters"] = nlohmann::json::object();
      for (const auto& [k, v] : counters) {
        if (k == CounterName(rms::Counter::kMode) || k.rfind("latency.", 0) == 0) continue;
        stats[p]["counters"][k] = stats[p]["counters"].value(k, std::int64_t{0}) + v;
      }
    }
  }
  return stats;
}

LabConfig ConfigOf(const fs::path& root);  // below

double FrameRate(const fs::path& root) { return ConfigOf(root).session.frame_rate_hz; }

nlohmann::ordered_json Restarts(const fs::path& root) {
  // Processes the launcher restarted after a fault (docs/sessions.md
  // "Faults"): run/restarts, one line "NAME N EXIT_CODE DOWN_AT READY_AT".
  nlohmann::ordered_json restarts = nlohmann::ordered_json::array();
  std::istringstream f(RunFile(root, "run/restarts"));
  std::string name;
  int n = 0, rc = 0;
  double down = 0, ready = 0;
  while (f >> name >> n >> rc >> down >> ready) {
    restarts.push_back({{"process", name},
                        {"restart", n},
                        {"exit_code", rc},
                        {"signal", rc > 128 ? rc - 128 : 0},
                        {"restart_s", ready - down}});
  }
  return restarts;
}

// What the session's re-simulation at its end came to (SESSION/
// resimulation.json, written by rms_resim --verdict-json; docs/sessions.md
// "Does it re-simulate"), or null when it was not run.
nlohmann::ordered_json Resimulation(const fs::path& root) {
  const nlohmann::json v = ReadJson(root / "resimulation.json");
  if (!v.is_object() || !v.contains("verdict") || !v["verdict"].is_string()) return nullptr;
  nlohmann::ordered_json out;
  // A verdict of another log (the log changed since it was judged: its
  // SHA-256 differs) is not this log's.
  if (v.contains("log_sha256") && v["log_sha256"].is_string()) {
    std::string now;
    try {
      now = SessionFileSha256(root.string(), "lcmlog");
    } catch (const std::exception&) {
    }
    if (now != v["log_sha256"].get<std::string>()) {
      out["verdict"] = "stale";
      out["exact"] = false;
      out["why"] =
          "resimulation.json judged another log (its SHA-256 differs from the lcmlog's now): "
          "re-simulate it again (scripts/lab resim)";
      return out;
    }
  }
  for (const char* k :
       {"verdict", "exact", "frames_compared", "frames_identical", "frames_unchecked",
        "frames_skipped_at_start", "unchecked", "first_difference", "why", "note", "log_note"}) {
    if (v.contains(k)) out[k] = v[k];
  }
  return out;
}

void AddMission(int final_mode, const std::set<int>& modes, const TelemetryLog& telemetry,
                nlohmann::ordered_json* out) {
  nlohmann::ordered_json& j = *out;
  j["final_mode"] = final_mode;
  j["modes_seen"] = std::vector<int>(modes.begin(), modes.end());
  j["acquired"] = telemetry.acquired;
  j["docked"] = telemetry.docked;
}

// Messages a receiver refused for a reason of its own, not malformed
// (docs/protocol.md): too late to act on, of another session, beyond the
// session's clock.
constexpr rms::Counter kRefused[] = {
    rms::Counter::kDroppedLate,        rms::Counter::kDroppedOtherSession,
    rms::Counter::kDroppedOtherSender, rms::Counter::kDroppedBadMac,
    rms::Counter::kDroppedReplayed,    rms::Counter::kDroppedFarAhead};

std::int64_t Malformed(const nlohmann::json& st) {
  std::int64_t n = SumPrefix(st, kDroppedPrefix);
  for (rms::Counter c : kRefused) n -= CounterOf(st, c);
  return n;
}

// A count in record.json (docs/sessions.md "The record"), 0 when it is not
// there or not a count.
std::int64_t RecordCount(const nlohmann::json& j, std::initializer_list<const char*> path) {
  const nlohmann::json* at = &j;
  for (const char* k : path) {
    if (!at->is_object() || !at->contains(k)) return 0;
    at = &(*at)[k];
  }
  return at->is_number_integer() ? at->get<std::int64_t>() : 0;
}

// What the processes' journals hold of a channel (record.json), or -1 when
// the record was not made from journals.
std::int64_t Journaled(const nlohmann::json& record, const std::string& channel) {
  if (!record.is_object() || !(record.value("made", false) == true) ||
      !record.contains("journals") || !record["journals"].is_array())
    return -1;
  std::int64_t n = 0;
  for (const auto& jf : record["journals"]) n += RecordCount(jf, {"by_channel", channel.c_str()});
  return n;
}

// The bytes of a journal (record.json's entry) that are no event: at its
// end (cut short) and inside it (damage read past).
std::int64_t JournalBadBytes(const nlohmann::json& jf) {
  return RecordCount(jf, {"unread_bytes"}) + RecordCount(jf, {"skipped_bytes"});
}

// Whether a journal of PROCESS holds bytes that are no event (damaged, or
// cut where the cut could not be made): its count is short.
bool JournalDamaged(const nlohmann::json& record, const std::string& process) {
  for (const auto& jf : record["journals"])
    if (jf.value("process", std::string()) == process && JournalBadBytes(jf) > 0) return true;
  return false;
}

// What PROCESS published on CHANNEL (with the session's suffix): what its
// journals hold, every run's (docs/sessions.md "The record"), or, in a
// session without journals, its own final counter (PROCESS_STATS); with a
// damaged journal, the larger of the two (what the journal could not hold
// up is then a loss of the record, not none).
std::int64_t Published(const nlohmann::json& process_stats, const nlohmann::json& record,
                       const std::string& channel, const std::string& process) {
  // The journals' distinct frame numbers where the record counted them (a
  // number sent twice is one frame, as the log's reader counts it), else
  // their messages.
  const std::int64_t journaled = record.is_object() && record.contains("frames_by_channel") &&
                                         record["frames_by_channel"].is_object()
                                     ? RecordCount(record, {"frames_by_channel", channel.c_str()})
                                     : Journaled(record, channel);
  const std::int64_t counted = CounterOf(process_stats, rms::Counter::kPublished);
  if (journaled < 0) return counted;
  return JournalDamaged(record, process) ? std::max(journaled, counted) : journaled;
}

// Frames each process published: what its journals hold (every run's, a
// process killed and restarted among them: the exact count, docs/sessions.md
// "The record"), or, in a session without journals, its own final counter.
nlohmann::ordered_json FramesJson(const std::map<std::string, nlohmann::json>& stats,
                                  const nlohmann::json& record, const std::string& suffix) {
  const auto &op = stats.at("operator_station"), &dcp = stats.at("dynamics_proc"),
             &scene = stats.at("scene_proc"), &esg = stats.at("esg_renderer");
  nlohmann::ordered_json frames;
  frames["operator_published"] =
      Published(op, record, wire::channels::kOperatorInput + suffix, "operator_station");
  frames["dcp_published"] =
      Published(dcp, record, wire::channels::kDcpFrame + suffix, "dynamics_proc");
  frames["esg_published"] =
      Published(scene, record, wire::channels::kEsgFrame + suffix, "scene_proc");
  frames["rendered"] = CounterOf(esg, rms::Counter::kRendered);
  frames["superseded"] = CounterOf(esg, rms::Counter::kSuperseded);
  frames["scenes_drawn"] = CounterOf(esg, rms::Counter::kRenderedScenes);
  frames["skipped_unchanged"] = CounterOf(esg, rms::Counter::kSkippedUnchanged);
  frames["png_written"] = CounterOf(esg, rms::Counter::kPngWritten);
  frames["video_frames"] = CounterOf(esg, rms::Counter::kVideoFrames);
  frames["video_dropped"] = CounterOf(esg, rms::Counter::kVideoDropped);
  frames["late_operator_frames"] = CounterOf(op, rms::Counter::kFramesLate);
  frames["dropped"] = {
      {"operator_to_dcp", CounterOf(dcp, rms::Counter::kInputMissing)},
      {"dcp_to_scene", CounterOf(scene, rms::Counter::kDcpMissing)},
      {"scene_to_esg", CounterOf(esg, rms::Counter::kEsgMissing)},
      {"malformed_at_dcp", Malformed(dcp)},
      {"malformed_at_scene", Malformed(scene)},
      {"malformed_at_esg", Malformed(esg)},
  };
  nlohmann::ordered_json refused = nlohmann::ordered_json::object();
  for (rms::Counter c : kRefused) {
    const std::string reason(
        CounterName(c).substr(kDroppedPrefix.size()));  // "late", "other_session", ...
    refused[reason] =
        CounterOf(op, c) + CounterOf(dcp, c) + CounterOf(scene, c) + CounterOf(esg, c);
  }
  frames["refused"] = refused;
  frames["clamped_inputs"] = {{"operator_station", SumPrefix(op, kClampedPrefix)},
                              {"dynamics_proc", SumPrefix(dcp, kClampedPrefix)},
                              {"scene_proc", SumPrefix(scene, kClampedPrefix)}};
  return frames;
}

nlohmann::ordered_json Links(const nlohmann::json& st) {
  nlohmann::ordered_json l = nlohmann::ordered_json::object();
  if (!st.contains("latency_us")) return l;
  for (auto it = st["latency_us"].begin(); it != st["latency_us"].end(); ++it) {
    l[it.key()] = {{"p50_ms", it.value()["p50"].get<double>() / 1000.0},
                   {"p99_ms", it.value()["p99"].get<double>() / 1000.0},
                   {"max_ms", it.value()["max"].get<double>() / 1000.0}};
  }
  return l;
}

// Timing health, by process: frames lost on the way in (from the frame
// numbers), frames late (more than a frame period after the operator sent
// them), malformed ones dropped, and each link's latency.
nlohmann::ordered_json TimingJson(const std::map<std::string, nlohmann::json>& stats,
                                  double rate_hz) {
  const auto &op = stats.at("operator_station"), &dcp = stats.at("dynamics_proc"),
             &scene = stats.at("scene_proc"), &esg = stats.at("esg_renderer");
  nlohmann::ordered_json timing;
  timing["frame_period_ms"] = 1000.0 / rate_hz;
  // What each process's CPU wake-latency request came to (docs/sessions.md
  // "The launcher"); a process without a stats file did not say.
  nlohmann::ordered_json wake;
  for (const char* p : {"operator_station", "dynamics_proc", "scene_proc", "esg_renderer"}) {
    const auto& st = stats.at(p);
    wake[p] = st.contains("cpu_wake_latency") && st["cpu_wake_latency"].is_string()
                  ? st["cpu_wake_latency"].get<std::string>()
                  : "not said";
  }
  timing["cpu_wake_latency"] = wake;
  timing["operator_station"] = {{"late_frames", CounterOf(op, rms::Counter::kFramesLate)}};
  timing["dynamics_proc"] = {{"dropped_frames", CounterOf(dcp, rms::Counter::kInputMissing)},
                             {"late_frames", CounterOf(dcp, rms::Counter::kFramesLate)},
                             {"too_late_dropped", CounterOf(dcp, rms::Counter::kDroppedLate)},
                             {"malformed", Malformed(dcp)},
                             {"latency", Links(dcp)}};
  timing["scene_proc"] = {{"dropped_frames", CounterOf(scene, rms::Counter::kDcpMissing)},
                          {"late_frames", CounterOf(scene, rms::Counter::kFramesLate)},
                          {"too_late_dropped", CounterOf(scene, rms::Counter::kDroppedLate)},
                          {"malformed", Malformed(scene)},
                          {"latency", Links(scene)}};
  timing["esg_renderer"] = {{"dropped_frames", CounterOf(esg, rms::Counter::kEsgMissing)},
                            {"superseded", CounterOf(esg, rms::Counter::kSuperseded)},
                            {"late_frames", CounterOf(esg, rms::Counter::kFramesLate)},
                            {"too_late_dropped", CounterOf(esg, rms::Counter::kDroppedLate)},
                            {"malformed", Malformed(esg)},
                            {"latency", Links(esg)}};
  return timing;
}

// Journals that hold bytes that are no event (damaged inside or at the end;
// a disk that filled mid-write and could not be cut back): their counts are
// what could be read, and what the damage held is only the network's.
void AddDamagedJournals(const nlohmann::json& record, nlohmann::ordered_json* r) {
  std::int64_t unread = 0;
  nlohmann::ordered_json damaged = nlohmann::ordered_json::array();
  for (const auto& jf : record["journals"]) {
    const std::int64_t n = JournalBadBytes(jf);
    if (n <= 0) continue;
    unread += n;
    damaged.push_back(jf.value("file", std::string()));
  }
  (*r)["journal_unread_bytes"] = unread;
  (*r)["journals_damaged"] = damaged;
}

// The record's own losses (docs/sessions.md "Losses", "The record"): each
// channel's frames its publisher sent -- what its journals hold, or (a
// session without journals) the publisher's own count -- against those the
// log holds; and what the network's recorder missed, which the journals made
// good.
nlohmann::ordered_json RecordJson(const std::map<std::string, nlohmann::json>& stats,
                                  const LogScan& s, const nlohmann::json& record,
                                  const std::string& suffix) {
  struct Row {
    const char* channel;
    std::int64_t published, logged;
  };
  const bool journals = Journaled(record, "") >= 0;
  auto published = [&](const char* channel, const char* process) {
    return Published(stats.at(process), record, channel + suffix, process);
  };
  const Row rows[] = {
      {wire::channels::kOperatorInput,
       published(wire::channels::kOperatorInput, "operator_station"),
       static_cast<std::int64_t>(s.input_logged.size())},
      {wire::channels::kDcpFrame, published(wire::channels::kDcpFrame, "dynamics_proc"),
       s.dcp.received()},
      {wire::channels::kDcpTelemetry, published(wire::channels::kDcpTelemetry, "dynamics_proc"),
       static_cast<std::int64_t>(s.telemetry_logged.size())},
      {wire::channels::kEsgFrame, published(wire::channels::kEsgFrame, "scene_proc"),
       static_cast<std::int64_t>(s.esg_logged.size())},
  };
  nlohmann::ordered_json r;
  r["source"] = journals ? "journals" : "network";
  std::int64_t lost = 0;
  for (const Row& row : rows) {
    if (row.published <= 0)
      continue;  // no count from the publisher: nothing to hold the log against
    const std::int64_t l = std::max<std::int64_t>(0, row.published - row.logged);
    r["by_channel"][row.channel] = {
        {"published", row.published}, {"logged", row.logged}, {"lost", l}};
    lost += l;
  }
  r["lost"] = lost;
  std::int64_t journal_failed = 0;
  for (const auto& [p, st] : stats) journal_failed += CounterOf(st, rms::Counter::kJournalFailed);
  r["journal_failed"] = journal_failed;
  if (journals) {
    AddDamagedJournals(record, &r);
    nlohmann::ordered_json missed = nlohmann::ordered_json::object();
    if (record["wire"].is_object() && record["wire"].contains("missed") &&
        record["wire"]["missed"].contains("by_channel") &&
        record["wire"]["missed"]["by_channel"].is_object()) {
      for (const auto& [ch, n] : record["wire"]["missed"]["by_channel"].items()) {
        std::string base = ch;
        if (!suffix.empty() && base.size() > suffix.size() &&
            base.compare(base.size() - suffix.size(), suffix.size(), suffix) == 0)
          base.resize(base.size() - suffix.size());
        if (n.is_number_integer()) missed[base] = n.get<std::int64_t>();
      }
    }
    const bool wire = !record["wire"].is_object() || record["wire"].value("present", true);
    r["network"] = {{"present", wire},
                    {"missed", wire ? RecordCount(record, {"wire", "missed", "total"}) : 0},
                    {"missed_by_channel", missed},
                    {"only_in_network", RecordCount(record, {"wire", "only_there"})},
                    {"duplicated", RecordCount(record, {"wire", "duplicated", "total"})}};
  }
  return r;
}

nlohmann::ordered_json LogJson(const LogScan& s) {
  nlohmann::ordered_json lj;
  lj["file"] = "lcmlog";
  lj["events"] = s.events;
  lj["by_channel"] = s.by_channel;
  lj["operator_frames"] = s.input.received();
  lj["dcp_frames"] = s.dcp.received();
  lj["esg_frames"] = s.esg.received();
  lj["esg_frames_missing"] = s.esg.missing();
  lj["malformed"] = s.malformed;
  lj["final_status_from"] = nlohmann::json::array();
  for (const auto& [p, seen] : s.status.final_seen) lj["final_status_from"].push_back(p);
  return lj;
}

}  // namespace

// Every number but the times to 9 significant digits, so the summary reads
// 20.9 ft and not 20.899999999999999 (docs/sessions.md "summary.json").
// Times -- every key ending in "_s", and what is under one (reached_s,
// phase_durations_s) -- are kept at full precision (the shortest text that
// reads back as the same double): session time is frames over the frame
// rate, and 9 digits would round 41.13333333333333 s (docs/sessions.md
// "Session time").
static bool IsTimeKey(const std::string& key) {
  return key.size() >= 2 && key.compare(key.size() - 2, 2, "_s") == 0;
}
static void ForPeople(nlohmann::ordered_json* j, bool time = false) {
  if (j->is_number_float()) {
    const double v = j->get<double>();
    if (std::isfinite(v) && !time) *j = std::strtod(Sprintf("%.9g", v).c_str(), nullptr);
    return;
  }
  if (j->is_object()) {
    for (auto it = j->begin(); it != j->end(); ++it)
      ForPeople(&it.value(), time || IsTimeKey(it.key()));
  } else if (j->is_array()) {
    for (auto& child : *j) ForPeople(&child, time);
  }
}

namespace {

// The session's configuration, or the default one when its copy is gone.
LabConfig ConfigOf(const fs::path& root) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(root / "config.toml", ec)))
    return LoadConfig(DefaultConfigPath());  // a session kept without its configuration
  return LoadSessionConfig(root.string());   // one that is there and not one: said
}

// Which session, how long, the mission and who flew it.
void AddSessionFields(const fs::path& root, const LogScan& s, double wall_s,
                      std::int64_t session_id, nlohmann::ordered_json* j) {
  (*j)["session"] = fs::absolute(root).lexically_normal().filename().string();
  if ((*j)["session"].get<std::string>().empty())
    (*j)["session"] = fs::absolute(root).parent_path().filename().string();
  if (session_id != 0) (*j)["session_id"] = wire::FormatSessionId(session_id);
  // Session time (docs/sessions.md "Session time"), and the wall clock's.
  (*j)["duration_s"] = s.session_s;
  (*j)["wall_duration_s"] = wall_s;
  AddMission(s.final_mode, s.modes, s.telemetry, j);
  std::istringstream pilot(RunFile(root, "run/pilot"));
  std::string who;
  if (pilot >> who) (*j)["pilot"] = who;
}

// The session's result (docs/sessions.md "summary.json"): its last attempt
// that docked, or else its last attempt.
void AddResult(nlohmann::ordered_json* j) {
  (*j)["result_attempt"] = nullptr;
  (*j)["phase_durations_s"] = nullptr;
  (*j)["docking"] = nullptr;
  nlohmann::ordered_json result = nullptr;
  for (const auto& a : (*j)["attempts"]) {
    if (a["outcome"] == "docked" || result.is_null() || !(result["outcome"] == "docked"))
      result = a;
  }
  if (!result.is_object()) return;
  (*j)["result_attempt"] = result["index"];
  (*j)["phase_durations_s"] = result["phase_durations_s"];
  (*j)["docking"] = result["docking"];
  // A docking a restore brought (a checkpoint saved just before it): said,
  // not hidden (docs/security.md "What the summary trusts").
  if ((*j)["docking"].is_object())
    (*j)["docking"]["after_restore"] = result["started_by"] == "restore";
}

// Each link's latency from the processes' stats, ms.
nlohmann::ordered_json LatencyJson(const std::map<std::string, nlohmann::json>& stats) {
  nlohmann::ordered_json lat = nlohmann::ordered_json::object();
  for (const auto& [proc, st] : stats) {
    if (!st.contains("latency_us")) continue;
    for (auto it = st["latency_us"].begin(); it != st["latency_us"].end(); ++it) {
      lat[it.key()] = {{"count", it.value()["count"]},
                       {"p50_ms", it.value()["p50"].get<double>() / 1000.0},
                       {"p99_ms", it.value()["p99"].get<double>() / 1000.0},
                       {"max_ms", it.value()["max"].get<double>() / 1000.0}};
    }
  }
  return lat;
}

// The log: its events, what could not be read at its end, whose counts it kept.
nlohmann::ordered_json LogSection(const LogScan& s, const SessionLog& log,
                                  const std::map<std::string, nlohmann::json>& stats) {
  nlohmann::ordered_json l = LogJson(s);
  l["unread_bytes"] = log.unread_bytes();  // a log cut short or damaged at its end
  // Damage inside the log, read past (docs/sessions.md "A damaged log").
  l["skipped_bytes"] = log.skipped_bytes();
  l["skipped_places"] = log.skipped_places();
  nlohmann::ordered_json where = nlohmann::ordered_json::array();
  for (const auto& [from, bytes] : log.skipped_stretches())
    where.push_back({{"from_byte", from}, {"bytes", bytes}});
  l["skipped_stretches"] = where;
  l["stats_from_log"] = nlohmann::json::array();
  for (const auto& [p, st] : stats) {
    if (st.value("from_log", false)) l["stats_from_log"].push_back(p);
  }
  return l;
}

}  // namespace

// In passes over the log (docs/sessions.md "summary.json"): the DCP frames
// to believe first, then everything else against them; then the stats.
nlohmann::ordered_json Summarize(const std::string& dir) {
  const fs::path root(dir);
  SessionLog first_pass(dir);
  const DcpFrames dcp_frames = ReadDcpFrames(first_pass);
  SessionLog log(dir);
  SenderCheck& check = log.check();
  check.Count("dcp_frame_out_of_sequence", dcp_frames.out_of_sequence);
  AttemptLog attempts(ConfigOf(root));
  const LogScan s = ScanLog(log, dcp_frames.by_frame, &attempts);
  const double rate_hz = FrameRate(root);
  const double wall_s = s.first_us >= 0 ? (s.last_us - s.first_us) * 1e-6 : 0.0;
  const auto stats = MergedStats(root, s.status, wall_s, rate_hz, &check);

  nlohmann::ordered_json j;
  AddSessionFields(root, s, wall_s, check.session_id(), &j);
  j["resimulation"] = Resimulation(root);
  j["restarts"] = Restarts(root);
  for (std::size_t i = 0; i < j["restarts"].size(); ++i) attempts.ObserveRestart();
  nlohmann::ordered_json a = attempts.Json();
  j["attempts"] = std::move(a["attempts"]);
  j["totals"] = std::move(a["totals"]);
  j["mode_changes"] = s.telemetry.mode_changes;
  j["control"] = s.control;
  j["control_answers_unmatched"] = s.answers_unmatched;
  j["malfunctions"] = s.malfunctions;
  AddResult(&j);
  j["by_hand"] = s.hand.Json();
  if (j["by_hand"].is_object()) {
    // The station's own count has the last key too (a quit ends it before
    // another state message goes out).
    j["by_hand"]["key_actions"] =
        std::max(j["by_hand"]["key_actions"].get<std::int64_t>(),
                 CounterOf(stats.at("operator_station"), rms::Counter::kKeyActions));
  }
  j["collisions"] = s.telemetry.collisions;
  j["collisions_by_kind"] = s.telemetry.ByKind();
  j["held_frames"] = s.telemetry.held_frames;
  j["telemetry_frames"] = s.telemetry.frames();
  const nlohmann::json record = ReadJson(root / "record.json");
  j["frames"] = FramesJson(stats, record, log.suffix());
  j["latency"] = LatencyJson(stats);
  j["timing"] = TimingJson(stats, rate_hz);
  j["record"] = RecordJson(stats, s, record, log.suffix());
  j["log"] = LogSection(s, log, stats);
  j["ignored"] = check.Json();
  ForPeople(&j);
  return j;
}

nlohmann::ordered_json SummarizeDcpRun(const LabConfig& config, const DcpRun& run) {
  // The frames believed, as ReadDcpFrames finds them in a log of this run.
  const std::map<std::int64_t, DcpFrameRecord> believed = BelieveDcpFrames(run.frames).by_frame;
  // ScanFrameNumbers: each frame of a believed number, in order, sets the mode.
  int final_mode = 0;
  std::set<int> modes;
  for (const dcp_frame_t& m : run.frames) {
    if (const auto it = believed.find(m.frame); it != believed.end()) {
      final_mode = it->second.word.mode;
      modes.insert(final_mode);
    }
  }
  // The telemetry they confirm, and the restores in their places, as ScanLog reads them.
  const double rate_hz = config.session.frame_rate_hz;
  TelemetryLog telemetry(rate_hz);
  AttemptLog attempts(config);
  std::set<std::int64_t> seen;
  std::size_t restore = 0;
  for (std::size_t i = 0; i < run.telemetry.size(); ++i) {
    for (; restore < run.restores_before.size() && run.restores_before[restore] <= i; ++restore)
      attempts.ObserveRestore("");  // no RMS_CONTROL in such a log: no checkpoint's name
    const dcp_telemetry_t& m = run.telemetry[i];
    if (Disbelief(m, believed, &seen)) continue;
    telemetry.Observe(m, -1);
    attempts.ObserveFrame(m, believed.at(m.frame).word.reset, m.input_frame / rate_hz);
  }
  nlohmann::ordered_json j;
  AddMission(final_mode, modes, telemetry, &j);
  nlohmann::ordered_json a = attempts.Json();
  j["attempts"] = std::move(a["attempts"]);
  j["totals"] = std::move(a["totals"]);
  AddResult(&j);
  j["held_frames"] = telemetry.held_frames;
  ForPeople(&j);
  return j;
}

}  // namespace rms::session
