#include "log_scan.h"

#include <algorithm>
#include <string>
#include <utility>

#include "rms/base/check.h"
#include "rms/control_answer_t.hpp"
#include "rms/dcp_state_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/session/sender_check.h"
#include "rms/session/session_summary.h"
#include "rms/session_control_t.hpp"
#include "rms/wire/channels.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/malfunction.h"

namespace rms::session {

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

namespace {

// The telemetry agrees with the DCP frame of its number: the same input
// frame, mode, acquisition and docking.
bool Agrees(const dcp_telemetry_t& t, const DcpFrameRecord& f) {
  return t.input_frame == f.input_frame && t.mode == f.word.mode && t.acquired == f.word.acquired &&
         t.docked == f.word.docked;
}

}  // namespace

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

namespace {

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

}  // namespace

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

}  // namespace rms::session
