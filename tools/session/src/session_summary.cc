#include "rms/session/session_summary.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/base/counters.h"
#include "rms/base/text.h"
#include "rms/base/version.h"
#include "rms/control_answer_t.hpp"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_state_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/operator_input_t.hpp"
#include "rms/operator_state_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/sender_t.hpp"
#include "rms/session/sender_check.h"
#include "rms/session/session_folder.h"
#include "rms/session/session_log.h"
#include "rms/session_control_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/transport/process.h"
#include "rms/wire/channels.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/collision_bits.h"
#include "rms/wire/control_word.h"
#include "rms/wire/malfunction.h"
#include "rms/wire/message_io.h"

#include "attempts.h"

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

constexpr int kCollisionBits = wire::collision_bits::kCount;

// The hand controllers' modes over the session, from RMS_OPERATOR_STATE
// (docs/sessions.md "summary.json", "by_hand").
class HandControlLog {
 public:
  void Observe(const operator_state_t& m, double t_s) {
    if (m.source != operator_state_t::SOURCE_BY_HAND) return;
    seen_ = true;
    const int key = m.control_mode * 100 + m.command_frame * 10 + m.scale;
    if (key != last_key_) {
      static const char* kModes[3] = {"?", "single joint", "manual augmented"};
      static const char* kFrames[4] = {"?", "end effector", "orbiter", "payload"};
      static const char* kScales[4] = {"?", "coarse", "vernier",
                                       "fine"};  // operator_state_t SCALE_*
      changes_.push_back(
          {{"time_s", t_s},
           {"frame", m.frame},
           {"control_mode",
            kModes[m.control_mode >= 1 && m.control_mode <= 2 ? m.control_mode : 0]},
           {"command_frame",
            kFrames[m.command_frame >= 1 && m.command_frame <= 3 ? m.command_frame : 0]},
           {"scale", kScales[m.scale >= 1 && m.scale <= 3 ? m.scale : 0]}});
      last_key_ = key;
    }
    key_actions_ = std::max<std::int64_t>(key_actions_, m.key_actions);
    joint_limit_frames_ += m.joint_limits != 0;
    singular_frames_ += m.singular;
  }
  nlohmann::ordered_json Json() const {
    if (!seen_) return nullptr;
    return {{"control_changes", changes_},
            {"key_actions", key_actions_},
            {"joint_limit_frames", joint_limit_frames_},
            {"singular_frames", singular_frames_}};
  }

 private:
  bool seen_ = false;
  int last_key_ = -1;
  nlohmann::ordered_json changes_ = nlohmann::ordered_json::array();
  std::int64_t key_actions_ = 0, joint_limit_frames_ = 0, singular_frames_ = 0;
};

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

// A DCP frame as logged: what confirms the telemetry of the same frame.
struct DcpFrameRecord {
  std::int64_t input_frame = -1;
  wire::ControlWord word;
  // Two different DCP frames of this number in the log, both with the
  // session's id and the DCP's pid: one is forged, and neither is believed.
  bool disputed = false;
};

// First pass: the session's own DCP frames (as logged, in the log's order),
// by frame number. The DCP numbers its frames upward, across restarts and
// restores, so the frames believed are the longest run of increasing numbers in the log's order; a
// frame off it -- a forgery far ahead or behind, with the DCP's own id and
// pid -- is left out (out_of_sequence), and its telemetry with it. Two
// different frames of one number mark that number disputed.
struct DcpFrames {
  std::map<std::int64_t, DcpFrameRecord> by_frame;
  std::int64_t out_of_sequence = 0;
};

DcpFrames BelieveDcpFrames(const std::vector<dcp_frame_t>& frames) {
  std::vector<std::int64_t> numbers;
  std::map<std::int64_t, DcpFrameRecord> first;
  std::set<std::int64_t> disputed;
  for (const dcp_frame_t& m : frames) {
    try {
      const DcpFrameRecord r{m.input_frame, wire::UnpackControlWord(m.control_word)};
      const auto [it, fresh] = first.emplace(m.frame, r);
      if (!fresh && (it->second.input_frame != r.input_frame || it->second.word != r.word))
        disputed.insert(m.frame);
      numbers.push_back(m.frame);
    } catch (const InputError&) {
    }
  }
  DcpFrames out;
  for (const std::size_t i : LongestIncreasingRun(numbers)) {
    DcpFrameRecord r = first.at(numbers[i]);
    r.disputed = disputed.count(numbers[i]) > 0;
    out.by_frame.emplace(numbers[i], r);
  }
  for (const std::int64_t n : numbers) {
    if (!out.by_frame.count(n)) ++out.out_of_sequence;
  }
  return out;
}

DcpFrames ReadDcpFrames(SessionLog& log) {
  std::vector<dcp_frame_t> frames;
  log.Read({wire::channels::kDcpFrame}, [&](const LogMessage& ev) {
    frames.emplace_back();
    if (!log.Decode(ev, &frames.back())) frames.pop_back();
  });
  return BelieveDcpFrames(frames);
}

// The telemetry agrees with the DCP frame of its number: the same input
// frame, mode, acquisition and docking.
bool Agrees(const dcp_telemetry_t& t, const DcpFrameRecord& f) {
  return t.input_frame == f.input_frame && t.mode == f.word.mode && t.acquired == f.word.acquired &&
         t.docked == f.word.docked;
}

// The mission as the DCP's telemetry tells it: mode changes, collision runs,
// docking and the phases' boundaries (DCP frame numbers; -1: not reached).
class TelemetryLog {
 public:
  explicit TelemetryLog(double rate_hz = 30.0) : rate_hz_(rate_hz) {
    for (const char* name : wire::kCollisionNames) totals_[name] = {0, 0, 0};
  }
  // wall_s: the message's wall time, s from the session's first logged
  // message (-1 where there is no log: a run made in memory).
  void Observe(const dcp_telemetry_t& m, double wall_s) {
    ++frames_;
    // Session time (docs/sessions.md "Session time"): the operator frame it
    // answers over the frame rate.
    const double t_s = m.input_frame / rate_hz_;
    // (Phases and docking are each attempt's: AttemptLog.)
    if (m.mode != last_mode_) {
      if (last_mode_ != 0) {
        nlohmann::ordered_json e = {{"frame", m.frame}, {"time_s", t_s}};
        if (wall_s >= 0) e["wall_s"] = wall_s;
        e["from"] = last_mode_;
        e["to"] = m.mode;
        mode_changes.push_back(std::move(e));
      }
      last_mode_ = m.mode;
    }
    acquired = acquired || m.acquired;
    docked = docked || m.docked;
    held_frames += m.held;
    // Detrimental collisions only: the finger resting on the bar is the essential contact.
    const auto bits =
        wire::DetrimentalCollisions(static_cast<std::uint32_t>(m.collisions), m.finger_held, m.held,
                                    m.master_finger > m.slave_finger);
    for (int b = 0; b < kCollisionBits; ++b) {
      const bool on = bits & (1u << b), was = last_bits_ & (1u << b);
      if (on && !was) {
        run_start_s_[b] = t_s;
        run_start_wall_s_[b] = wall_s;
        run_frames_[b] = 0;
      }
      if (on) ++run_frames_[b];
      if (was && !on) EndRun(b, false);
    }
    last_bits_ = bits;
  }
  // Collisions still on at the end of the log; events in time order.
  void Finish() {
    for (int b = 0; b < kCollisionBits; ++b) {
      if (last_bits_ & (1u << b)) EndRun(b, true);
    }
    std::sort(collisions.begin(), collisions.end(), [](const auto& a, const auto& b) {
      return a["start_s"].template get<double>() < b["start_s"].template get<double>();
    });
  }
  nlohmann::ordered_json ByKind() const {
    nlohmann::ordered_json by_kind = nlohmann::ordered_json::object();
    for (const auto& [kind, t] : totals_) {
      by_kind[kind] = {{"events", static_cast<std::int64_t>(t[0])},
                       {"frames", static_cast<std::int64_t>(t[1])},
                       {"duration_s", t[2]}};
    }
    return by_kind;
  }
  std::int64_t frames() const { return frames_; }

  nlohmann::ordered_json mode_changes = nlohmann::ordered_json::array();
  nlohmann::ordered_json collisions = nlohmann::ordered_json::array();
  bool acquired = false, docked = false;
  std::int64_t held_frames = 0;

 private:
  // A run's session time: a frame period each of its frames (as the
  // attempts' collisions count it).
  void EndRun(int b, bool open) {
    const double dur = static_cast<double>(run_frames_[b]) / rate_hz_;
    nlohmann::ordered_json e = {{"kind", wire::kCollisionNames[b]},
                                {"start_s", run_start_s_[b]},
                                {"duration_s", dur},
                                {"frames", run_frames_[b]}};
    if (run_start_wall_s_[b] >= 0) e["wall_s"] = run_start_wall_s_[b];
    if (open) e["open"] = true;
    collisions.push_back(e);
    auto& tot = totals_[wire::kCollisionNames[b]];
    tot[0] += 1;
    tot[1] += run_frames_[b];
    tot[2] += dur;
  }
  std::map<std::string, std::array<double, 3>> totals_;  // events, frames, seconds; every kind
  std::array<double, kCollisionBits> run_start_s_{}, run_start_wall_s_{};
  std::array<std::int64_t, kCollisionBits> run_frames_{};
  std::uint32_t last_bits_ = 0;
  int last_mode_ = 0;
  std::int64_t frames_ = 0;
  double rate_hz_;
};

// Each process's runs (a restart after a fault is a new pid): the last
// counters each run reported on RMS_STATUS.
struct StatusRuns {
  std::map<std::string, std::map<int, std::map<std::string, std::int64_t>>> runs;
  std::map<std::string, int> last_pid;
  std::map<std::string, bool> final_seen;
};

// What one pass over the log finds, the session's own messages only.
struct LogScan {
  std::map<std::string, std::int64_t> by_channel;
  std::int64_t events = 0, first_us = -1, last_us = -1, malformed = 0;
  double session_s = 0;  // the session time its operator frames reach (the last one's end)
  wire::SequenceTracker input, dcp, esg;  // frame numbers as logged
  // The distinct numbers of the operator's and the ESG's frames, of those
  // not refused as far ahead: what the record holds (RecordJson), where a
  // number sent again after a resync is one frame, not a stale one.
  std::set<std::int64_t> input_logged, esg_logged;
  double rate_hz = 30.0;
  std::set<std::int64_t> telemetry_frames;  // believed
  std::set<std::int64_t> telemetry_logged;  // of the DCP's frames, whether believed or not
  int final_mode = 0;
  std::set<int> modes;
  TelemetryLog telemetry;
  HandControlLog hand;
  StatusRuns status;
  nlohmann::ordered_json control = nlohmann::ordered_json::array();
  // Each command's place in `control`, by its id (sender process, pid,
  // sequence): where its answers go (RMS_CONTROL_ANSWER).
  std::map<std::tuple<int, std::int32_t, std::int64_t>, std::size_t> control_index;
  AttemptLog* attempts = nullptr;
  std::string last_restore_name;
  std::int64_t answers_unmatched = 0;
  // docs/sessions.md "Malfunctions": each change of the malfunctions in
  // force, as the DCP's logged states show it, and those in force now.
  nlohmann::ordered_json malfunctions = nlohmann::ordered_json::array();
  std::vector<std::string> in_force;
};

// Why a telemetry message is not believed, as SenderCheck counts it, or
// nullptr when it is: it is believed only where the DCP frame of its number
// (believed, not disputed) says the same, and once a frame (`believed`: the
// frames whose telemetry was; docs/security.md "What the summary trusts").
const char* Disbelief(const dcp_telemetry_t& m, const std::map<std::int64_t, DcpFrameRecord>& dcp,
                      std::set<std::int64_t>* believed) {
  const auto it = dcp.find(m.frame);
  if (it == dcp.end()) return "telemetry_without_its_dcp_frame";
  if (it->second.disputed) return "disputed_dcp_frame";
  if (!Agrees(m, it->second)) return "telemetry_contradicts_its_dcp_frame";
  if (!believed->insert(m.frame).second) return "repeated_frame";
  return nullptr;
}

void ScanTelemetry(const LogMessage& ev, const std::map<std::int64_t, DcpFrameRecord>& dcp,
                   SenderCheck* check, LogScan* s) {
  dcp_telemetry_t m{};
  if (wire::SafeDecode(ev.data, ev.size, &m) != wire::DecodeError::kNone) {
    ++s->malformed;
    return;
  }
  if (dcp.count(m.frame)) s->telemetry_logged.insert(m.frame);  // in the record, believed or not
  if (const char* why = Disbelief(m, dcp, &s->telemetry_frames)) return check->Count(why);
  s->telemetry.Observe(m, (ev.log_us - s->first_us) * 1e-6);
  s->attempts->ObserveFrame(m, dcp.at(m.frame).word.reset, m.input_frame / s->rate_hz);
}

void ScanStatus(const LogMessage& ev, LogScan* s) {
  process_status_t m;
  if (wire::SafeDecode(ev.data, ev.size, &m) != wire::DecodeError::kNone) {
    ++s->malformed;
    return;
  }
  if (m.final) s->status.final_seen[m.process] = true;
  auto& run = s->status.runs[m.process][m.pid];
  for (int i = 0; i < m.num_counters; ++i) run[m.counter_names[i]] = m.counter_values[i];
  s->status.last_pid[m.process] = m.pid;
}

// Session control as sent (RMS_CONTROL; docs/sessions.md "Freeze, run, step,
// checkpoint"), each with the answers of the processes that acted on it
// (ScanAnswer).
void ScanControl(const LogMessage& ev, LogScan* s) {
  session_control_t m;
  if (wire::SafeDecode(ev.data, ev.size, &m) != wire::DecodeError::kNone) {
    ++s->malformed;
    return;
  }
  const char* what = wire::ControlCommandName(m.command);
  // Session time: the operator's last frame before it (it stands still in
  // a freeze; each step moves it one frame); wall_s the wall clock's.
  nlohmann::ordered_json e = {{"time_s", ev.session_time_s},
                              {"wall_s", (ev.log_us - s->first_us) * 1e-6},
                              {"command", what},
                              {"process", wire::ProcessCodeName(m.sender.process)},
                              {"pid", m.sender.pid},
                              {"sequence", m.sequence}};
  if (!m.name.empty()) e["name"] = m.name;
  e["answers"] = nlohmann::ordered_json::array();
  if (m.command == session_control_t::RESTORE) s->last_restore_name = m.name;
  s->control_index[{m.sender.process, m.sender.pid, m.sequence}] = s->control.size();
  s->control.push_back(e);
}

// RMS_CONTROL_ANSWER: a process's answer to a command (docs/protocol.md),
// put with the command it answers; one whose command is not in the log is
// counted (control_answers_unmatched) and kept out.
void ScanAnswer(const LogMessage& ev, LogScan* s) {
  control_answer_t m;
  if (wire::SafeDecode(ev.data, ev.size, &m) != wire::DecodeError::kNone) {
    ++s->malformed;
    return;
  }
  const auto it = s->control_index.find({m.command_process, m.command_pid, m.command_sequence});
  if (it == s->control_index.end()) {
    ++s->answers_unmatched;
    return;
  }
  s->control[it->second]["answers"].push_back(
      {{"process", wire::ProcessCodeName(m.sender.process)},
       {"outcome", m.outcome == control_answer_t::DONE ? "done" : "refused"},
       {"frame", m.frame},
       {"text", m.text},
       {"wall_s", (ev.log_us - s->first_us) * 1e-6}});
}

void ScanFrameNumbers(const std::string& base, const LogMessage& ev,
                      const std::map<std::int64_t, DcpFrameRecord>& dcp, LogScan* s) {
  if (base == wire::channels::kOperatorState) {
    operator_state_t m;
    if (wire::SafeDecode(ev.data, ev.size, &m) == wire::DecodeError::kNone) {
      s->hand.Observe(m, m.frame / s->rate_hz);
      s->attempts->ObserveOperator(m);
    } else {
      ++s->malformed;
    }
  } else if (base == wire::channels::kOperatorInput) {
    operator_input_t m;
    if (wire::SafeDecode(ev.data, ev.size, &m) == wire::DecodeError::kNone) {
      if (s->input.Accept(m.frame) != wire::SequenceTracker::Verdict::kFarAhead)
        s->input_logged.insert(m.frame);
      s->session_s = std::max(s->session_s, (m.frame + 1) / s->rate_hz);
    } else {
      ++s->malformed;
    }
  } else if (base == wire::channels::kDcpFrame) {
    // Only the frames of the increasing run (ReadDcpFrames) count.
    dcp_frame_t m;
    if (wire::SafeDecode(ev.data, ev.size, &m) != wire::DecodeError::kNone) {
      ++s->malformed;
    } else if (const auto it = dcp.find(m.frame); it != dcp.end()) {
      s->dcp.Accept(m.frame);
      s->final_mode = it->second.word.mode;
      s->modes.insert(s->final_mode);
    }
  } else if (base == wire::channels::kEsgFrame) {
    esg_frame_t m;
    if (wire::SafeDecode(ev.data, ev.size, &m) != wire::DecodeError::kNone)
      ++s->malformed;
    else if (s->esg.Accept(m.frame) != wire::SequenceTracker::Verdict::kFarAhead)
      s->esg_logged.insert(m.frame);
  }
}

// A restore the DCP made (RMS_DCP_STATE RESTORE) starts an attempt.
void ScanState(const LogMessage& ev, LogScan* s) {
  dcp_state_t m;
  if (wire::SafeDecode(ev.data, ev.size, &m) != wire::DecodeError::kNone) {
    ++s->malformed;
    return;
  }
  if (m.reason == dcp_state_t::RESTORE) s->attempts->ObserveRestore(s->last_restore_name);
  std::vector<std::string> now;
  try {
    now = wire::MalfunctionTexts(wire::ParseCheckpoint(m.checkpoint, "RMS_DCP_STATE").dcp);
    for (const auto& x : now) (void)wire::ParseMalfunction(x);  // each one readable
  } catch (const InputError&) {
    ++s->malformed;
    return;
  }
  if (now == s->in_force) return;
  // Each part's malfunction (its repair's name: "joint 2", "finger" ...):
  // one taken away while another of the same part came is replaced.
  auto part = [](const std::string& text) {
    return wire::RepairText(wire::RepairFor(wire::ParseMalfunction(text)));
  };
  auto has = [](const std::vector<std::string>& v, const std::string& x) {
    return std::find(v.begin(), v.end(), x) != v.end();
  };
  nlohmann::ordered_json injected = nlohmann::ordered_json::array(),
                         repaired = nlohmann::ordered_json::array(),
                         replaced = nlohmann::ordered_json::array();
  std::vector<std::string> new_parts;
  for (const auto& x : now) {
    if (!has(s->in_force, x)) {
      injected.push_back(x);
      new_parts.push_back(part(x));
    }
  }
  for (const auto& x : s->in_force) {
    if (has(now, x)) continue;
    (has(new_parts, part(x)) ? replaced : repaired).push_back(x);
  }
  static constexpr const char* kReasons[] = {"?",       "start",  "periodic",
                                             "restore", "resume", "malfunction"};
  // Session time as mode_changes has it: the operator frames answered over
  // the frame rate (it stands still in a freeze).
  s->malfunctions.push_back({{"time_s", (m.input_frame + 1) / s->rate_hz},
                             {"wall_s", (ev.log_us - s->first_us) * 1e-6},
                             {"dcp_frame", m.next_frame},
                             {"why", m.reason >= 1 && m.reason <= 5 ? kReasons[m.reason] : "?"},
                             {"injected", injected},
                             {"repaired", repaired},
                             {"replaced", replaced},
                             {"in_force", now}});
  s->in_force = std::move(now);
}

LogScan ScanLog(SessionLog& log, const std::map<std::int64_t, DcpFrameRecord>& dcp,
                AttemptLog* attempts) {
  LogScan s;
  s.attempts = attempts;
  s.rate_hz = log.frame_rate_hz();
  s.telemetry = TelemetryLog(s.rate_hz);
  SenderCheck* check = &log.check();
  log.Read({}, [&](const LogMessage& ev) {
    // The wall clock's zero: the session's first message logged.
    if (s.first_us < 0) s.first_us = ev.log_us;
    ++s.by_channel[std::string(ev.channel)];
    if (ev.base == wire::channels::kDcpTelemetry)
      ScanTelemetry(ev, dcp, check, &s);
    else if (ev.base == wire::channels::kStatus)
      ScanStatus(ev, &s);
    else if (ev.base == wire::channels::kControl)
      ScanControl(ev, &s);
    else if (ev.base == wire::channels::kControlAnswer)
      ScanAnswer(ev, &s);
    else if (ev.base == wire::channels::kDcpState)
      ScanState(ev, &s);
    else
      ScanFrameNumbers(std::string(ev.base), ev, dcp, &s);
  });
  s.events = log.events();
  if (s.first_us < 0) s.first_us = log.first_us();  // none of the session's own
  s.last_us = log.last_us();
  s.malformed += log.malformed();
  s.telemetry.Finish();
  return s;
}

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

std::string BeganFrom(const nlohmann::json& m) {
  if (m.contains("began_from") && m["began_from"].is_string()) return m["began_from"];
  return m.contains("branch") ? "branch" : m.contains("restored_from") ? "restore" : "start";
}

nlohmann::ordered_json MakeManifest(const std::string& dir, const ManifestFields& f) {
  const std::string &pilot = f.pilot, &url = f.url, &suffix = f.suffix,
                    &config_sha256 = f.config_sha256, &timeline = f.timeline, &restore = f.restore,
                    &command = f.command;
  const std::vector<std::string>& hosts = f.hosts;
  nlohmann::ordered_json j;
  j["format"] = "rmslab-session-1";
  j["session"] = fs::absolute(dir).lexically_normal().filename().string();
  if (!f.session_id.empty())
    j["session_id"] =
        wire::FormatSessionId(transport::ParseSessionId(f.session_id, "--session-id"));
  const std::int64_t now = transport::WallTimeUs();
  const std::time_t secs = static_cast<std::time_t>(now / 1000000);
  char utc[32];
  std::strftime(utc, sizeof utc, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&secs));
  j["started_utc"] = utc;
  j["started_us"] = now;
  j["pilot"] = pilot;
  j["kind"] = f.kind;
  if (!f.parent.empty()) j[f.kind == "re-simulation" ? "resimulation_of" : "replay_of"] = f.parent;
  if (!f.subject.empty()) j["subject"] = f.subject;
  if (!f.note.empty()) j["note"] = f.note;
  if (!timeline.empty()) j["timeline"] = {{"file", "timeline.tl"}, {"source", timeline}};
  if (!restore.empty()) j["restored_from"] = restore;
  if (!f.branch_of.empty()) {
    j["branch"] = {{"parent", f.branch_of},
                   {"frame", f.branch_frame},
                   {"time_s", f.branch_time_s},
                   {"parent_log_sha256", f.branch_parent_log_sha256}};
  }
  if (!f.study.name.empty()) {
    if (f.study.condition.empty() || f.study.kind.empty() || f.study.trial < 1 || f.study.run < 1)
      throw InputError(
          "--study: give --condition, --trial (1 or more), --trial-kind and --trial-run");
    j["study"] = {{"name", f.study.name},           {"file_sha256", f.study.file_sha256},
                  {"condition", f.study.condition}, {"trial", f.study.trial},
                  {"kind", f.study.kind},           {"run", f.study.run}};
  }
  j["began_from"] = !f.began_from.empty()  ? f.began_from
                    : !f.branch_of.empty() ? "branch"
                    : !restore.empty()     ? "restore"
                                           : "start";
  if (!f.message_auth.empty()) {
    if (f.message_auth != wire::kMessageAuthName)
      throw InputError("--message-auth '" + f.message_auth + "': the one kind is " +
                       wire::kMessageAuthName);
    j["message_auth"] = f.message_auth;
  }
  j["config"] = {{"file", "config.toml"}, {"sha256", config_sha256}};
  if (!f.config_source.empty()) j["config"]["source"] = f.config_source;
  j["software"] = {{"version", VersionString()},         {"project", Version().project},
                   {"describe", Version().describe},     {"commit", Version().commit},
                   {"build_type", Version().build_type}, {"compiler", Version().compiler}};
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  j["lab_host"] = host;
  // A re-simulation ran on no network (no url), but its log's channels may
  // carry a suffix: said, so its readers find them.
  if (!url.empty() || !suffix.empty()) j["lcm"] = {{"url", url}, {"channel_suffix", suffix}};
  nlohmann::ordered_json layout = nlohmann::ordered_json::object();
  for (const char* p :
       {"operator_station", "dynamics_proc", "scene_proc", "esg_renderer", "lcm-logger"})
    layout[p] = "localhost";
  for (const std::string& h : hosts) {
    const auto eq = h.find('=');
    if (eq == std::string::npos) throw InputError("--host must be PROCESS=HOST, got '" + h + "'");
    layout[h.substr(0, eq)] = h.substr(eq + 1);
  }
  j["hosts"] = layout;
  if (!command.empty()) j["command"] = command;
  return j;
}

nlohmann::ordered_json ProbeAddress(const std::string& url, double seconds) {
  lcm::LCM lcm(url);
  if (!lcm.good())
    throw transport::TransportError("cannot listen on '" + url +
                                    "' (no route for multicast? scripts/lab adds one)");
  struct Heard {
    std::map<std::string, std::int64_t> channels;
    std::set<std::string> senders;
  };
  std::map<std::int64_t, Heard> sessions;
  struct Handler {
    std::map<std::int64_t, Heard>* out;
    void On(const lcm::ReceiveBuffer* rb, const std::string& channel) {
      std::int64_t fp = 0, id = 0;
      std::int8_t process = 0;
      std::int32_t pid = 0;
      const int n = static_cast<int>(rb->data_size);
      if (!wire::ReadFingerprint(rb->data, n, &fp) || !wire::IsRmslabFingerprint(fp) ||
          !wire::ReadSessionId(rb->data, n, &id))
        return;
      wire::ReadSenderProcess(rb->data, n, &process, &pid);
      Heard& h = (*out)[id];
      ++h.channels[channel];
      h.senders.insert(std::string(wire::ProcessCodeName(process)) + " pid " + std::to_string(pid));
    }
  } handler{&sessions};
  lcm.subscribe("RMS_.*", &Handler::On, &handler);
  const std::int64_t end = transport::WallTimeUs() + static_cast<std::int64_t>(seconds * 1e6);
  for (std::int64_t now = transport::WallTimeUs(); now < end; now = transport::WallTimeUs()) {
    lcm.handleTimeout(static_cast<int>(std::max<std::int64_t>(1, (end - now) / 1000)));
  }
  nlohmann::ordered_json j;
  j["url"] = url;
  j["seconds"] = seconds;
  j["sessions"] = nlohmann::ordered_json::array();
  for (const auto& [id, h] : sessions) {
    j["sessions"].push_back({{"session_id", wire::FormatSessionId(id)},
                             {"channels", h.channels},
                             {"senders", h.senders}});
  }
  return j;
}

SessionInfo ReadSessionInfo(const std::string& dir) {
  const fs::path p = fs::path(dir) / "manifest.json";
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(p, ec)))
    throw InputError("no manifest.json in " + dir + ": not a session folder");
  const std::string text = ReadSessionFile(dir, "manifest.json", kMaxJsonBytes);
  SessionInfo s;
  s.dir = dir;
  try {
    const auto j = nlohmann::json::parse(text);
    if (j.contains("lcm")) {  // a re-simulation's folder has none: it ran on no network
      s.lcm_url = j.at("lcm").value("url", "");
      s.channel_suffix = j.at("lcm").value("channel_suffix", "");
    }
    if (j.contains("session_id"))
      s.session_id = transport::ParseSessionId(j.at("session_id").get<std::string>(),
                                               p.string() + " session_id");
    if (j.contains("message_auth")) s.message_auth = j.at("message_auth").get<std::string>();
  } catch (const InputError&) {
    throw;
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(p.string() + ": not valid JSON (at byte " + std::to_string(e.byte) +
                     "): not a session's manifest");
  } catch (const std::exception& e) {
    throw InputError(p.string() + ": not a session's manifest (" +
                     std::string(e.what()).substr(std::string(e.what()).find(']') + 1) + ")");
  }
  return s;
}

std::optional<wire::SessionKey> ReadSessionKey(const std::string& dir) {
  const SessionInfo info = ReadSessionInfo(dir);
  if (info.message_auth.empty()) return std::nullopt;
  if (info.message_auth != wire::kMessageAuthName)
    throw InputError(dir + "/manifest.json: message_auth '" + info.message_auth +
                     "' is not one this build knows (" + wire::kMessageAuthName + ")");
  try {
    return wire::ReadSessionKeyFile((fs::path(dir) / "run" / "session.key").string());
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) +
                     ": the session's messages carry tags (manifest.json message_auth), and "
                     "without its key no reader can tell its own from a stranger's");
  }
}

nlohmann::ordered_json CompareEsgFrames(const std::string& original_dir,
                                        const std::string& replay_dir) {
  auto read = [](const std::string& dir) {
    std::map<std::int64_t, esg_frame_t> by_dcp;
    SessionLog log(dir);  // each session's own ESG frames
    log.Read({wire::channels::kEsgFrame}, [&](const LogMessage& ev) {
      esg_frame_t m;
      if (log.Decode(ev, &m)) by_dcp[m.dcp_frame] = m;
    });
    return by_dcp;
  };
  const auto a = read(original_dir);
  const auto b = read(replay_dir);
  std::int64_t identical = 0, missing = 0;
  std::string first;
  for (const auto& [dcp_frame, m] : a) {
    const auto it = b.find(dcp_frame);
    if (it == b.end()) {
      ++missing;
      if (first.empty()) first = "DCP frame " + std::to_string(dcp_frame) + ": not replayed";
      continue;
    }
    if (it->second.frame == m.frame && it->second.words == m.words)
      ++identical;
    else if (first.empty())
      first = "DCP frame " + std::to_string(dcp_frame) + ": words differ";
  }
  nlohmann::ordered_json j;
  j["recorded"] = static_cast<std::int64_t>(a.size());
  j["replayed"] = static_cast<std::int64_t>(b.size());
  j["identical"] = identical;
  j["missing"] = missing;
  j["first_difference"] = first;
  return j;
}

}  // namespace rms::session
