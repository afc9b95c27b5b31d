#include "rms/instructor_station/session_watch.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <spdlog/spdlog.h>

#include "rms/dcp_state_t.hpp"
#include "rms/session/session_log.h"
#include "rms/session_control_t.hpp"
#include "rms/transport/process.h"
#include "rms/wire/acquisition_conditions.h"
#include "rms/wire/channels.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/collision_bits.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/frame_receiver.h"
#include "rms/wire/malfunction.h"
#include "rms/wire/message_io.h"

namespace rms::instructor_station {

namespace {

// A point of the path every this many DCP frames (about 6 a second at 30 Hz).
constexpr std::int64_t kPathEveryFrames = 5;
// A process whose reports stop this long is shown as silent.
constexpr std::int64_t kSilentUs = 3'000'000;

std::string ModeText(int mode) {
  const wire::DcpModeInfo* m = wire::DcpModeOf(mode);
  return m ? "Mode " + std::to_string(mode) + " (" + m->name + ")" : "no mode";
}

// The collision bits less the essential contact (the finger closing onto
// the BAR), as the summary counts them (docs/collision.md).
std::uint32_t Detrimental(const dcp_telemetry_t& t) {
  return wire::DetrimentalCollisions(static_cast<std::uint32_t>(t.collisions), t.finger_held,
                                     t.held, t.master_finger > t.slave_finger);
}

bool Finite(const dcp_telemetry_t& t) {
  bool ok = std::isfinite(t.dock_distance_ft) && std::isfinite(t.dock_angle_deg) &&
            std::isfinite(t.bay_clearance_ft) && std::isfinite(t.envelope_margin_ft);
  for (double v : t.p_RoA_R_ft) ok = ok && std::isfinite(v);
  for (double v : t.acquisition_margin_ft) ok = ok && std::isfinite(v);
  return ok;
}

}  // namespace

SessionWatch::SessionWatch(const LabConfig& config, transport::LcmInterface* lcm,
                           Counters* counters, bool live)
    : config_(config),
      lcm_(lcm),
      counters_(counters),
      instance_(std::to_string(getpid()) + "-" + std::to_string(lcm->NowUs())) {
  dcp_frames_.SetClock(transport::SessionFrameClock(config.session.frame_rate_hz));
  telemetry_seq_.SetClock(transport::SessionFrameClock(config.session.frame_rate_hz));
  debrief_ = !live;
  if (!live) return;
  lcm_->Subscribe(wire::channels::kDcpFrame,
                  [this](const void* d, int n, std::int64_t t) { OnDcpFrame(d, n, t); });
  lcm_->Subscribe(wire::channels::kDcpTelemetry,
                  [this](const void* d, int n, std::int64_t t) { OnTelemetry(d, n, t); });
  lcm_->Subscribe(wire::channels::kStatus,
                  [this](const void* d, int n, std::int64_t) { OnStatus(d, n); });
  lcm_->Subscribe(wire::channels::kControl,
                  [this](const void* d, int n, std::int64_t) { OnControl(d, n); });
  lcm_->Subscribe(wire::channels::kDcpState,
                  [this](const void* d, int n, std::int64_t) { OnDcpState(d, n); });
  lcm_->Subscribe(wire::channels::kControlAnswer,
                  [this](const void* d, int n, std::int64_t) { OnAnswer(d, n); });
  lcm_->Subscribe(wire::channels::kOperatorState,
                  [this](const void* d, int n, std::int64_t) { OnOperatorState(d, n); });
}

std::int64_t SessionWatch::Now() const { return reading_log_ ? log_now_us_ : lcm_->NowUs(); }

void SessionWatch::OnDcpFrame(const void* data, int size, std::int64_t recv_us) {
  std::lock_guard<std::mutex> lock(mu_);
  auto got = wire::ReceiveFrame<dcp_frame_t>(
      data, size, &dcp_frames_, counters_,
      [](const dcp_frame_t& m) { return wire::UnpackDcpFrame(m); }, recv_us);
  if (!got) return;
  wire::DcpFrameData& d = got->second;
  if (d.control.reset && !reset_bit_) {
    AddEvent("reset", "RESET: back to Mode 1, attempt " + std::to_string(score_.attempts + 1));
    ++score_.attempts;
    score_.acquired_s = score_.docked_s = -1;
  }
  reset_bit_ = d.control.reset;
  // Kept for the debrief's scrubbing, in frame order (a restored or
  // reset session's numbers still rise).
  if (history_.empty() || d.frame > history_.back().frame) {
    history_.push_back(d);
    history_lost_.push_back(lost_stations_);
    if (history_.size() > kMaxHistoryFrames) {
      history_.pop_front();
      history_lost_.pop_front();
    }
  }
  dcp_ = std::move(d);
  counters_->Set(Counter::kDcpMissing, dcp_frames_.missing());
}

void SessionWatch::OnTelemetry(const void* data, int size, std::int64_t recv_us) {
  dcp_telemetry_t t{};
  if (const wire::DecodeError e = wire::SafeDecode(data, size, &t); e != wire::DecodeError::kNone) {
    counters_->Add(wire::DroppedTelemetryCounter(e));
    return;
  }
  if (!Finite(t)) {
    counters_->Add(Counter::kDroppedTelemetryNonFinite);
    return;
  }
  std::lock_guard<std::mutex> lock(mu_);
  // As the operator station: old, repeated and impossible frame numbers are
  // refused, so one forged packet from the far future cannot stand for the
  // session (docs/instructor.md "Bounds").
  switch (telemetry_seq_.Accept(t.frame, recv_us)) {
    case wire::SequenceTracker::Verdict::kDuplicate:
    case wire::SequenceTracker::Verdict::kStale:
      return;
    case wire::SequenceTracker::Verdict::kFarAhead:
      counters_->Add(Counter::kDroppedFarAhead);
      return;
    default:
      break;
  }
  TelemetryEvents(t);
  Score(t);
  if (t.frame - last_path_frame_ >= kPathEveryFrames || t.frame < last_path_frame_) {
    TelemetryPlot(t);
    path_.push_back({t.frame / config_.session.frame_rate_hz, t.p_RoA_R_ft[0], t.p_RoA_R_ft[1],
                     t.p_RoA_R_ft[2]});
    if (path_.size() > kMaxPathPoints) {
      path_.pop_front();
      ++path_first_;
    }
    last_path_frame_ = t.frame;
  }
  telemetry_ = t;
}

// Mode changes, acquisition, docking, release, collisions and holds, each
// at its start (and a hold's end).
void SessionWatch::TelemetryEvents(const dcp_telemetry_t& t) {
  const dcp_telemetry_t* p = telemetry_ ? &*telemetry_ : nullptr;
  if (!p || p->mode != t.mode) AddEvent("mode", ModeText(t.mode));
  if (t.acquired && (!p || !p->acquired)) AddEvent("acquired", "ACQUIRED: the payload is held");
  if (t.docked && (!p || !p->docked)) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "DOCKED: %.3f ft, %.2f deg", t.dock_distance_ft,
                  t.dock_angle_deg);
    AddEvent("docked", buf);
  }
  if (t.released && (!p || !p->released)) AddEvent("released", "released: the arm is free");
  const std::uint32_t before = p ? Detrimental(*p) : 0;
  if (const std::uint32_t began = Detrimental(t) & ~before; began)
    AddEvent("collision", "COLLISION " + wire::CollisionNames(began) + " begins");
  if (t.held && (!p || !p->held)) AddEvent("hold", "HELD: the DCP holds the arm");
  if (!t.held && p && p->held) AddEvent("hold", "the arm moves again");
}

void SessionWatch::OnStatus(const void* data, int size) {
  process_status_t m{};
  if (wire::SafeDecode(data, size, &m) != wire::DecodeError::kNone) {
    counters_->Add(Counter::kDroppedStatusMalformed);
    return;
  }
  std::lock_guard<std::mutex> lock(mu_);
  if (!TakeStatus(m)) counters_->Add(Counter::kDroppedStatusRefused);
}

namespace {

// The counters of a process the page shows by name (docs/instructor.md "/api/status").
constexpr const char* kShownCounters[] = {
    "frames.late",     "superseded",       "input.missing", "dcp.missing",
    "esg.missing",     "control.freezes",  "control.steps", "control.malfunctions",
    "control.repairs", "arm.not_following"};

bool Shown(const std::string& name) {
  for (const char* k : kShownCounters) {
    if (name == k) return true;
  }
  return false;
}

bool EndsWith(const std::string& s, const char* tail) {
  const std::size_t n = std::strlen(tail);
  return s.size() >= n && s.compare(s.size() - n, n, tail) == 0;
}

}  // namespace

// A status is its sender's own: its name is the one its sender's process
// code stands for (any name for a tool) and its pid the sender's. A new
// process beyond kMaxProcesses is refused.
bool SessionWatch::TakeStatus(const process_status_t& m) {
  if (m.pid != m.sender.pid || wire::ProcessCode(m.process) != m.sender.process) return false;
  auto it = processes_.find(m.process);
  if (it == processes_.end()) {
    if (processes_.size() >= kMaxProcesses) return false;
    it = processes_.emplace(m.process, Process{}).first;
    AddEvent("process", m.process + " up (pid " + std::to_string(m.pid) + " on " + m.host + ")");
    it->second.pid = m.pid;
  }
  Process& p = it->second;
  const std::int64_t now = Now();
  if (p.pid != m.pid) {
    AddEvent("process", m.process + " RESTARTED (pid " + std::to_string(p.pid) + " -> " +
                            std::to_string(m.pid) + ")");
    p.rate_hz = 0;
    p.not_following = 0;
  } else if (p.last_us > 0 && now > p.last_us) {
    p.rate_hz = static_cast<double>(m.frame - p.frame) * 1e6 / static_cast<double>(now - p.last_us);
  }
  if (m.final && !p.ended) AddEvent("process", m.process + " ended");
  // The operator station is the session's clock: its end is the session's
  // (docs/instructor.md "The banner").
  if (m.final && !p.ended && m.process == "operator_station" && !state_.ended) {
    state_.ended = true;
    state_.ended_wall_us = now;
    char how[160];
    if (telemetry_ && telemetry_->docked)
      std::snprintf(how, sizeof how, "DOCKED (%.3f ft, %.2f deg) at %.1f s of session time",
                    telemetry_->dock_distance_ft, telemetry_->dock_angle_deg,
                    score_.docked_s >= 0 ? score_.docked_s : 0.0);
    else if (telemetry_)
      std::snprintf(how, sizeof how, "ended in Mode %d without docking, at %.1f s of session time",
                    telemetry_->mode, telemetry_->frame / config_.session.frame_rate_hz);
    else
      std::snprintf(how, sizeof how, "ended before any telemetry");
    state_.ended_how = how;
    AddEvent("station", std::string("SESSION ENDED: ") + how);
  }
  if (m.process == "instructor_station" && m.pid != getpid() && reading_log_ && !debrief_)
    restarted_ = true;
  p.dropped = 0;
  p.figures.clear();
  p.latency.clear();
  std::int64_t not_following = 0;
  for (int i = 0; i < m.num_counters; ++i) {
    const std::string& k = m.counter_names[i];
    const std::int64_t v = m.counter_values[i];
    if (k.rfind("dropped.", 0) == 0) p.dropped += v;
    if (k == CounterName(Counter::kNotFollowing)) not_following = v;
    if (Shown(k)) p.figures[k] = v;
    if (k.rfind("latency.", 0) == 0 && (EndsWith(k, ".p50_us") || EndsWith(k, ".p99_us")) &&
        p.latency.size() < kMaxLatencyFigures)
      p.latency[k] = v;
  }
  // The operator station saw a joint or the finger stop following its
  // command (docs/operator.md "A joint that does not follow").
  if (not_following > p.not_following) {
    AddEvent("failure", m.process + " reports " + NotFollowingWhat() +
                            " NOT FOLLOWING its command (" + std::to_string(not_following) +
                            " so far)");
  }
  p.not_following = not_following;
  p.ended = m.final;
  p.pid = m.pid;
  p.host = m.host;
  p.frame = m.frame;
  p.last_us = now;
  return true;
}

void SessionWatch::OnControl(const void* data, int size) {
  session_control_t m;
  if (wire::SafeDecode(data, size, &m) != wire::DecodeError::kNone) {
    counters_->Add(Counter::kDroppedControlMalformed);
    return;
  }
  std::string text = std::string(wire::ControlCommandName(m.command));
  if (!m.name.empty()) text += " " + m.name.substr(0, 64);
  std::lock_guard<std::mutex> lock(mu_);
  const auto id = std::make_tuple(int{m.sender.process}, m.sender.pid, m.sequence);
  if (!commands_seen_.insert(id).second) return;  // read from the log and heard live
  if (command_texts_.size() >= kMaxEvents) command_texts_.erase(command_texts_.begin());
  command_texts_[id] = text;
  AddEvent("control", text + " (from " + wire::ProcessCodeName(m.sender.process) + ")");
  // An earlier instance's command (read back from the log): the page's id
  // for it still answers.
  if (m.sender.process == sender_t::PROCESS_INSTRUCTOR && m.sender.pid != getpid())
    RecordCommand(m.sequence, m.sender.pid, m.command, m.name.substr(0, 64), m.send_time_us);
}

// RMS_CONTROL_ANSWER (docs/protocol.md): each answer an event; the
// operator station's say whether the session is frozen; this station's own
// commands keep theirs for the page.
void SessionWatch::OnAnswer(const void* data, int size) {
  control_answer_t a;
  if (wire::SafeDecode(data, size, &a) != wire::DecodeError::kNone) {
    counters_->Add(Counter::kDroppedAnswerMalformed);
    return;
  }
  // Only the processes that act on commands answer them.
  if (a.sender.process != sender_t::PROCESS_OPERATOR_STATION &&
      a.sender.process != sender_t::PROCESS_DYNAMICS)
    return;
  std::lock_guard<std::mutex> lock(mu_);
  const auto key = std::make_tuple(int{a.command_process}, a.command_pid, a.command_sequence,
                                   int{a.sender.process});
  if (!answers_seen_.insert(key).second) return;
  if (answers_seen_.size() > kMaxEvents) answers_seen_.erase(answers_seen_.begin());
  const bool done = a.outcome == control_answer_t::DONE;
  const char* by = wire::ProcessCodeName(a.sender.process);
  const auto it = command_texts_.find({a.command_process, a.command_pid, a.command_sequence});
  const std::string what =
      it != command_texts_.end() ? it->second : wire::ControlCommandName(a.command);
  AddEvent("answer",
           what + (done ? ": done, " : ": REFUSED, ") + a.text.substr(0, 200) + " (" + by + ")");
  if (done && a.sender.process == sender_t::PROCESS_OPERATOR_STATION) {
    const bool freezes =
        a.command == session_control_t::FREEZE || a.command == session_control_t::RESTORE;
    if (freezes && !state_.frozen) {
      state_.frozen = true;
      state_.frozen_wall_us = Now();
      state_.frozen_session_s = dcp_ ? dcp_->frame / config_.session.frame_rate_hz : 0.0;
    }
    if (a.command == session_control_t::RUN) state_.frozen = false;
  }
  // A restore begins an attempt, as the summary counts them.
  if (done && a.sender.process == sender_t::PROCESS_DYNAMICS &&
      a.command == session_control_t::RESTORE) {
    ++score_.attempts;
    score_.acquired_s = score_.docked_s = -1;
  }
  if (a.command_process != sender_t::PROCESS_INSTRUCTOR) return;
  for (CommandRecord& c : own_commands_) {
    if (c.id == a.command_sequence && c.pid == a.command_pid)
      c.answers.push_back({by, done, a.text.substr(0, 400)});
  }
}

// RMS_OPERATOR_STATE: the trainee's control mode, command frame, hand
// controllers and guidance, as the trainee's own screen shows them.
void SessionWatch::OnOperatorState(const void* data, int size) {
  operator_state_t m;
  if (const wire::DecodeError e = wire::SafeDecode(data, size, &m); e != wire::DecodeError::kNone) {
    counters_->Add(wire::DroppedOperatorStateCounter(e));
    return;
  }
  std::lock_guard<std::mutex> lock(mu_);
  if (operator_ && m.sender.pid == operator_->sender.pid && m.frame <= operator_->frame) return;
  operator_ = std::move(m);
}

// The malfunctions in force, from the DCP's state (sent when one is
// injected or repaired, and every 5 s): each change is an event.
void SessionWatch::OnDcpState(const void* data, int size) {
  dcp_state_t m;
  if (wire::SafeDecode(data, size, &m) != wire::DecodeError::kNone) {
    counters_->Add(Counter::kDroppedStateMalformed);
    return;
  }
  std::vector<std::string> now;
  std::uint32_t lost = 0;
  try {
    now = wire::MalfunctionTexts(wire::ParseCheckpoint(m.checkpoint, "RMS_DCP_STATE").dcp);
    for (const std::string& t : now) {
      const wire::Malfunction f = wire::ParseMalfunction(t);
      if (f.kind == wire::MalfunctionKind::kCameraLost) lost |= 1u << (f.target - 1);
    }
  } catch (const InputError&) {
    counters_->Add(Counter::kDroppedStateMalformed);
    return;
  }
  std::lock_guard<std::mutex> lock(mu_);
  auto has = [](const std::vector<std::string>& v, const std::string& x) {
    return std::find(v.begin(), v.end(), x) != v.end();
  };
  const std::string from = " (from DCP frame " + std::to_string(m.next_frame) + ")";
  for (const std::string& t : now) {
    if (!has(malfunctions_, t)) {
      AddEvent("malfunction", std::string("MALFUNCTION: ").append(t) + from);
      ++score_.malfunctions;
    }
  }
  for (const std::string& t : malfunctions_) {
    if (!has(now, t)) AddEvent("malfunction", std::string("repaired: ").append(t) + from);
  }
  malfunctions_ = std::move(now);
  lost_stations_ = lost;
}

std::uint32_t SessionWatch::LostStations() const {
  std::lock_guard<std::mutex> lock(mu_);
  return lost_stations_;
}

void SessionWatch::NoteLocal(const std::string& kind, const std::string& text) {
  std::lock_guard<std::mutex> lock(mu_);
  AddEvent(kind, text);
}

void SessionWatch::AddEvent(const std::string& kind, const std::string& text) {
  Event e;
  e.seq = next_event_seq_++;
  e.wall_us = Now();
  e.session_s = reading_log_ && std::isfinite(log_session_s_) ? log_session_s_
                : dcp_ ? static_cast<double>(dcp_->frame) / config_.session.frame_rate_hz
                       : 0.0;
  e.kind = kind;
  e.text = text;
  events_.push_back(std::move(e));
  if (events_.size() > kMaxEvents) events_.pop_front();
}

std::optional<wire::DcpFrameData> SessionWatch::LatestDcpFrame() const {
  std::lock_guard<std::mutex> lock(mu_);
  return dcp_;
}

std::optional<dcp_telemetry_t> SessionWatch::LatestTelemetry() const {
  std::lock_guard<std::mutex> lock(mu_);
  return telemetry_;
}

std::int64_t SessionWatch::events_seen() const {
  std::lock_guard<std::mutex> lock(mu_);
  return next_event_seq_;
}

nlohmann::json SessionWatch::EventsJson(std::int64_t since, int limit) const {
  std::lock_guard<std::mutex> lock(mu_);
  nlohmann::json out = nlohmann::json::array();
  limit = std::min(limit, kMaxEventsAnswer);
  const std::int64_t first = next_event_seq_ - static_cast<std::int64_t>(events_.size());
  for (std::int64_t i = std::max(first, since);
       i < next_event_seq_ && static_cast<int>(out.size()) < limit; ++i) {
    const Event& e = events_[static_cast<std::size_t>(i - first)];
    out.push_back({{"seq", e.seq},
                   {"wall_us", e.wall_us},
                   {"session_s", e.session_s},
                   {"kind", e.kind},
                   {"text", e.text}});
  }
  return out;
}

nlohmann::json SessionWatch::PathJson(std::size_t since) const {
  std::lock_guard<std::mutex> lock(mu_);
  nlohmann::json points = nlohmann::json::array();
  std::size_t i = std::max(since, path_first_);
  const std::size_t end = path_first_ + path_.size();
  for (; i < end && points.size() < kMaxPathAnswer; ++i) {
    const auto& q = path_[i - path_first_];
    points.push_back({q[0], q[1], q[2], q[3]});
  }
  return {{"first", path_first_}, {"next", std::max(i, since)}, {"points", points}};
}

namespace {

nlohmann::json TelemetryJson(const dcp_telemetry_t& t, const LabConfig& config) {
  nlohmann::json conditions = nlohmann::json::array();
  for (int i = 0; i < wire::kNumAcquisitionConditions; ++i) {
    conditions.push_back({{"name", wire::kAcquisitionConditionNames[i].brief},
                          {"holds", static_cast<bool>(t.acquisition_conditions[i])},
                          {"margin_ft", t.acquisition_margin_ft[i]}});
  }
  return {{"frame", t.frame},
          {"session_s", t.frame / config.session.frame_rate_hz},
          {"mode", t.mode},
          {"acquired", static_cast<bool>(t.acquired)},
          {"docked", static_cast<bool>(t.docked)},
          {"released", static_cast<bool>(t.released)},
          {"held", static_cast<bool>(t.held)},
          {"collisions", wire::CollisionNames(Detrimental(t))},
          {"acquisition_conditions", conditions},
          {"finger_gap_ft", t.finger_gap_ft},
          {"bay_clearance_ft", t.bay_clearance_ft},
          {"dock_distance_ft", t.dock_distance_ft},
          {"dock_angle_deg", t.dock_angle_deg},
          {"dock_distance_limit_ft", config.dcp.dock_distance_ft},
          {"dock_angle_limit_deg", config.dcp.dock_angle_deg},
          {"p_RoA_R_ft", {t.p_RoA_R_ft[0], t.p_RoA_R_ft[1], t.p_RoA_R_ft[2]}},
          {"slave_angles_deg", t.slave_angles_deg},
          {"master_angles_deg", t.master_angles_deg},
          {"master_finger", t.master_finger},
          {"slave_finger", t.slave_finger}};
}

}  // namespace

nlohmann::json SessionWatch::StatusJson() const {
  std::lock_guard<std::mutex> lock(mu_);
  nlohmann::json j;
  j["frame_rate_hz"] = config_.session.frame_rate_hz;
  j["dcp"] = telemetry_ ? TelemetryJson(*telemetry_, config_) : nlohmann::json(nullptr);
  j["camera_station"] = dcp_ ? dcp_->control.camera_station : 0;
  const std::int64_t now = lcm_->NowUs();
  nlohmann::json procs = nlohmann::json::object();
  for (const auto& [name, p] : processes_) {
    nlohmann::json q = {{"pid", p.pid},
                        {"host", p.host},
                        {"frame", p.frame},
                        {"rate_hz", p.rate_hz},
                        {"state", p.ended                       ? "ended"
                                  : now - p.last_us > kSilentUs ? "silent"
                                                                : "running"}};
    nlohmann::json latency = nlohmann::json::object();
    for (const auto& [k, v] : p.latency)  // latency.NAME.p50_us -> NAME: p50_ms
      latency[k.substr(8, k.size() - 15)][EndsWith(k, ".p50_us") ? "p50_ms" : "p99_ms"] =
          v / 1000.0;
    q["dropped"] = p.dropped;
    q["latency"] = latency;
    for (const auto& [k, v] : p.figures) q["counters"][k] = v;
    procs[name] = q;
  }
  j["processes"] = procs;
  j["events"] = next_event_seq_;
  j["malfunctions"] = malfunctions_;
  j["session"] = StateJson();
  j["operator"] = OperatorJson();
  j["warnings"] = WarningsJson();
  j["scorecard"] = {
      {"attempts", score_.attempts},
      {"session_s", score_.frames / config_.session.frame_rate_hz},
      {"mode_s",
       {score_.mode_frames[1] / config_.session.frame_rate_hz,
        score_.mode_frames[2] / config_.session.frame_rate_hz,
        score_.mode_frames[3] / config_.session.frame_rate_hz}},
      {"collisions", score_.collisions},
      {"collision_s", score_.collision_frames / config_.session.frame_rate_hz},
      {"holds", score_.holds},
      {"malfunctions", score_.malfunctions},
      {"acquired_at_s",
       score_.acquired_s >= 0 ? nlohmann::json(score_.acquired_s) : nlohmann::json(nullptr)},
      {"docked_at_s",
       score_.docked_s >= 0 ? nlohmann::json(score_.docked_s) : nlohmann::json(nullptr)},
      {"closest_to_port_ft",
       score_.min_goal_ft >= 0 ? nlohmann::json(score_.min_goal_ft) : nlohmann::json(nullptr)},
      {"key_actions", operator_ ? operator_->key_actions : 0}};
  j["history"] = history_.empty() ? nlohmann::json(nullptr)
                                  : nlohmann::json{{"first_frame", history_.front().frame},
                                                   {"last_frame", history_.back().frame}};
  // This station's run: a page that sees it change (the station restarted)
  // reads the events and the path again from the start.
  j["instance"] = instance_;
  return j;
}

// ------------------------------------------------------------------ the trainee

// What a NOT FOLLOWING report is about: the joints (and the finger) whose
// angle is off its command in the newest telemetry, by name.
std::string SessionWatch::NotFollowingWhat() const {
  if (!telemetry_) return "a joint or the finger";
  std::string out;
  for (int j = 0; j < wire::kNumJoints; ++j) {
    if (std::abs(telemetry_->master_angles_deg[j] - telemetry_->slave_angles_deg[j]) > 0.5)
      out.append(out.empty() ? "" : ", ")
          .append("joint ")
          .append(std::to_string(j + 1))
          .append(" ")
          .append(wire::JointName(j + 1));
  }
  if (std::abs(telemetry_->master_finger - telemetry_->slave_finger) > 0.02)
    out.append(out.empty() ? "" : ", ").append("the finger");
  return out.empty() ? "a joint or the finger" : out;
}

// The live scorecard: as the summary counts (docs/sessions.md "Scorecard"),
// from the telemetry this station saw.
void SessionWatch::Score(const dcp_telemetry_t& t) {
  const dcp_telemetry_t* p = telemetry_ ? &*telemetry_ : nullptr;
  const double t_s = t.frame / config_.session.frame_rate_hz;
  ++score_.frames;
  if (t.mode >= 0 && t.mode <= wire::DcpMode::kManoeuvring)
    ++score_.mode_frames[static_cast<std::size_t>(t.mode)];
  const std::uint32_t now = Detrimental(t), before = p ? Detrimental(*p) : 0;
  if (now & ~before) ++score_.collisions;
  if (now) ++score_.collision_frames;
  if (t.held && (!p || !p->held)) ++score_.holds;
  if (t.acquired && score_.acquired_s < 0) score_.acquired_s = t_s;
  if (t.docked && score_.docked_s < 0) score_.docked_s = t_s;
}

void SessionWatch::TelemetryPlot(const dcp_telemetry_t& t) {
  PlotPoint q;
  q.session_s = t.frame / config_.session.frame_rate_hz;
  q.frame = t.frame;
  q.mode = t.mode;
  q.goal_ft = std::numeric_limits<double>::quiet_NaN();
  if (t.mode >= wire::DcpMode::kExtraction)
    q.goal_ft = t.dock_distance_ft;
  else if (operator_ && operator_->guidance_valid && operator_->mode == t.mode)
    q.goal_ft = operator_->distance_ft;
  for (int i = 0; i < wire::kNumAcquisitionConditions; ++i)
    q.margin_ft[static_cast<std::size_t>(i)] = t.acquisition_margin_ft[i];
  q.dock_angle_deg = t.dock_angle_deg;
  if (std::isfinite(q.goal_ft) && (score_.min_goal_ft < 0 || q.goal_ft < score_.min_goal_ft) &&
      t.mode >= wire::DcpMode::kExtraction)
    score_.min_goal_ft = q.goal_ft;
  plot_.push_back(q);
  if (plot_.size() > kMaxPlotPoints) {
    plot_.pop_front();
    ++plot_first_;
  }
}

namespace {

const char* ControlModeName(int m) {
  return m == 1 ? "single joint" : m == 2 ? "manual augmented" : "--";
}
const char* CommandFrameName(int f) {
  return f == 1 ? "end effector" : f == 2 ? "orbiter" : f == 3 ? "payload" : "--";
}
const char* SourceName(int s) {
  return s == operator_state_t::SOURCE_TIMELINE    ? "timeline"
         : s == operator_state_t::SOURCE_BY_HAND   ? "by hand"
         : s == operator_state_t::SOURCE_AUTOPILOT ? "autopilot"
                                                   : "?";
}

nlohmann::json Array(const double* v, int n) {
  nlohmann::json a = nlohmann::json::array();
  for (int i = 0; i < n; ++i) a.push_back(std::isfinite(v[i]) ? nlohmann::json(v[i]) : nullptr);
  return a;
}

}  // namespace

// docs/instructor.md "The trainee's view": what the trainee's own screen shows.
nlohmann::json SessionWatch::OperatorJson() const {
  if (!operator_) return nullptr;
  const operator_state_t& m = *operator_;
  nlohmann::json limits = nlohmann::json::array();
  nlohmann::json near = nlohmann::json::array();
  for (int j = 0; j < wire::kNumJoints; ++j) {
    if ((m.joint_limits >> j) & 1) limits.push_back(wire::JointName(j + 1));
    if ((m.joints_near_limit >> j) & 1) near.push_back(wire::JointName(j + 1));
  }
  nlohmann::json j = {{"frame", m.frame},
                      {"source", SourceName(m.source)},
                      {"control_mode", ControlModeName(m.control_mode)},
                      {"command_frame", CommandFrameName(m.command_frame)},
                      {"scale", m.scale == operator_state_t::SCALE_FINE      ? "fine"
                                : m.scale == operator_state_t::SCALE_VERNIER ? "vernier"
                                                                             : "coarse"},
                      {"joints_near_limit", near},
                      {"automatic", m.automatic},
                      {"joint", m.control_mode == 1 ? wire::JointName(m.joint + 1) : ""},
                      {"hand_rate", Array(m.hand_rate, 6)},
                      {"joints_at_limit", limits},
                      {"singular", static_cast<bool>(m.singular)},
                      {"rate_limited", static_cast<bool>(m.rate_limited)},
                      {"key_actions", m.key_actions}};
  if (m.guidance_valid) {
    nlohmann::json margins = Array(m.margin_ft, 6);
    j["guidance"] = {{"mode", m.mode},
                     {"target", m.target == 1 ? "the grasp on the BAR" : "the CAE's port"},
                     {"offset_ft", Array(m.offset_ft, 3)},
                     {"rotation_deg", Array(m.rotation_deg, 3)},
                     {"distance_ft", m.distance_ft},
                     {"angle_deg", m.angle_deg},
                     {"margins_ft", margins},
                     {"close_gap_ft", m.close_gap_ft},
                     {"close_ok", static_cast<bool>(m.close_ok)},
                     {"bay_clearance_ft", m.bay_clearance_ft},
                     {"turn_clearance_ft", m.turn_clearance_ft},
                     {"clearance_warning", static_cast<bool>(m.clearance_warning)}};
  } else {
    j["guidance"] = nullptr;
  }
  return j;
}

namespace {

// A malfunction's text as the page says it: its value's unit and the
// joint's name ("inputs delayed 300 ms", "joint 2 drift 0.5 deg/s
// (shoulder pitch)"); a text that does not parse, as it came.
std::string MalfunctionSaid(const std::string& text) {
  wire::Malfunction m;
  try {
    m = wire::ParseMalfunction(text);
  } catch (const InputError&) {
    return text;
  }
  std::string said = text;
  const wire::MalfunctionKindInfo& kind = wire::KindInfo(m.kind);
  if (kind.value[0] != '\0') said.append(" ").append(kind.unit);
  if (kind.part == wire::MalfunctionPart::kJoint)
    said.append(" (").append(wire::JointName(m.target)).append(")");
  return said;
}

}  // namespace

// What the trainee is warned of, and what the instructor should see at a
// glance: collisions, holds, joints at their limits, a singular pose,
// parts not following, the malfunctions in force (an input delay named).
nlohmann::json SessionWatch::WarningsJson() const {
  nlohmann::json w = nlohmann::json::array();
  if (telemetry_) {
    if (const std::uint32_t c = Detrimental(*telemetry_))
      w.push_back("COLLISION " + wire::CollisionNames(c));
    if (telemetry_->held) w.push_back("HELD: the DCP holds the arm");
  }
  if (operator_) {
    for (int j = 0; j < wire::kNumJoints; ++j)
      if ((operator_->joint_limits >> j) & 1)
        w.push_back(std::string("joint ") + std::to_string(j + 1) + " " + wire::JointName(j + 1) +
                    " at its limit");
    if (operator_->singular) w.push_back("near a singular pose: some direction is damped");
    if (operator_->rate_limited) w.push_back("hand-controller rates limited");
    for (int j = 0; j < wire::kNumJoints; ++j)
      if ((operator_->joints_near_limit >> j) & 1)
        w.push_back(std::string("joint ") + std::to_string(j + 1) + " " + wire::JointName(j + 1) +
                    " near its limit (the trainee is warned; unwind is the way out)");
    if (operator_->guidance_valid && operator_->clearance_warning)
      w.push_back(
          fmt::format("CLEARANCE: the payload {:.2f} ft above the orbiter's sill line over "
                      "the turn (margin {:.0f} ft)",
                      operator_->turn_clearance_ft, operator_state_t::CLEARANCE_MARGIN_FT));
  }
  for (const std::string& t : malfunctions_)
    w.push_back("MALFUNCTION in force: " + MalfunctionSaid(t));
  if (dcp_ && dcp_->control.no_video) w.push_back("NO VIDEO on the operator's monitor");
  return w;
}

nlohmann::json SessionWatch::StateJson() const {
  const dcp_telemetry_t* t = telemetry_ ? &*telemetry_ : nullptr;
  nlohmann::json j = {{"frozen", state_.frozen},
                      {"ended", state_.ended},
                      {"debrief", debrief_},
                      {"restarted", restarted_}};
  j["state"] = debrief_        ? "DEBRIEF"
               : state_.ended  ? "SESSION ENDED"
               : state_.frozen ? "FROZEN"
               : t             ? "RUNNING"
                               : "WAITING";
  if (state_.frozen) {
    j["frozen_wall_us"] = state_.frozen_wall_us;
    j["frozen_session_s"] = state_.frozen_session_s;
  }
  if (state_.ended) {
    j["ended_wall_us"] = state_.ended_wall_us;
    j["ended_how"] = state_.ended_how;
  }
  if (!session_dir_.empty()) j["session_dir"] = session_dir_;
  return j;
}

// ------------------------------------------------------------------ commands

void SessionWatch::NoteCommand(std::int64_t id, std::int8_t command, const std::string& name) {
  std::lock_guard<std::mutex> lock(mu_);
  RecordCommand(id, getpid(), command, name, Now());
}

void SessionWatch::RecordCommand(std::int64_t id, std::int32_t pid, std::int8_t command,
                                 const std::string& name, std::int64_t wall_us) {
  CommandRecord c;
  c.id = id;
  c.pid = pid;
  c.command = command;
  c.name = name;
  c.sent_wall_us = wall_us;
  switch (command) {
    case session_control_t::CHECKPOINT:
    case session_control_t::MALFUNCTION:
    case session_control_t::REPAIR:
      c.expected = {"dynamics_proc"};
      break;
    case session_control_t::RESTORE:
      c.expected = {"dynamics_proc", "operator_station"};
      break;
    default:
      c.expected = {"operator_station"};
  }
  next_command_id_ = std::max(next_command_id_, id + 1);
  own_commands_.push_back(std::move(c));
  if (own_commands_.size() > kMaxCommands) own_commands_.pop_front();
}

std::int64_t SessionWatch::NextCommandId() const {
  std::lock_guard<std::mutex> lock(mu_);
  return next_command_id_;
}

nlohmann::json SessionWatch::CommandJson(std::int64_t id) const {
  std::lock_guard<std::mutex> lock(mu_);
  // The newest with the id (one command through restarts: NextCommandId).
  for (auto it = own_commands_.rbegin(); it != own_commands_.rend(); ++it) {
    const CommandRecord& c = *it;
    if (c.id != id) continue;
    nlohmann::json answers = nlohmann::json::array();
    bool refused = false;
    std::size_t answered = 0;
    for (const std::string& who : c.expected) {
      for (const CommandRecord::Heard& h : c.answers) {
        if (h.process != who) continue;
        ++answered;
        refused = refused || !h.done;
        answers.push_back({{"process", h.process}, {"done", h.done}, {"text", h.text}});
        break;
      }
    }
    // No answer within 3 s: the process that acts on it is not there (or
    // is stopped); said so, never "sent".
    const bool late = Now() - c.sent_wall_us > 3'000'000;
    const char* state = refused                         ? "refused"
                        : answered == c.expected.size() ? "done"
                        : late                          ? "unanswered"
                                                        : "pending";
    return {{"id", c.id},
            {"command", wire::ControlCommandName(c.command)},
            {"name", c.name},
            {"state", state},
            {"expected", c.expected},
            {"answers", answers}};
  }
  return nullptr;
}

// ------------------------------------------------------------------ plots, history

nlohmann::json SessionWatch::PlotJson(std::size_t since) const {
  std::lock_guard<std::mutex> lock(mu_);
  nlohmann::json points = nlohmann::json::array();
  std::size_t i = std::max(since, plot_first_);
  const std::size_t end = plot_first_ + plot_.size();
  for (; i < end && points.size() < kMaxPathAnswer; ++i) {
    const PlotPoint& q = plot_[i - plot_first_];
    nlohmann::json m = nlohmann::json::array();
    for (double v : q.margin_ft) m.push_back(std::isfinite(v) ? nlohmann::json(v) : nullptr);
    points.push_back({q.session_s, q.frame, q.mode,
                      std::isfinite(q.goal_ft) ? nlohmann::json(q.goal_ft) : nullptr, m,
                      q.dock_angle_deg});
  }
  return {{"first", plot_first_}, {"next", std::max(i, since)}, {"points", points}};
}

SessionWatch::PastFrames SessionWatch::HistoryAt(std::int64_t frame, std::size_t lead) const {
  std::lock_guard<std::mutex> lock(mu_);
  PastFrames out;
  if (history_.empty()) return out;
  auto it =
      std::upper_bound(history_.begin(), history_.end(), frame,
                       [](std::int64_t f, const wire::DcpFrameData& d) { return f < d.frame; });
  if (it == history_.begin()) ++it;  // before the first kept: the first
  const std::size_t end = static_cast<std::size_t>(it - history_.begin());
  const std::size_t begin = end > lead + 1 ? end - lead - 1 : 0;
  out.frames.assign(history_.begin() + static_cast<std::ptrdiff_t>(begin),
                    history_.begin() + static_cast<std::ptrdiff_t>(end));
  out.lost_stations = history_lost_[end - 1];
  return out;
}

std::pair<std::int64_t, std::int64_t> SessionWatch::HistoryRange() const {
  std::lock_guard<std::mutex> lock(mu_);
  if (history_.empty()) return {-1, -1};
  return {history_.front().frame, history_.back().frame};
}

// ------------------------------------------------------------------ the log, marks

// The session's record once it has ended (lcmlog); while it runs, what
// the network's recorder has written so far (wire.lcmlog, then its parts
// .1, .2 ... after a restart of the recorder: docs/sessions.md "The record").
namespace {

std::vector<std::string> SessionLogNames(const std::string& dir) {
  namespace fs = std::filesystem;
  if (fs::exists(fs::path(dir) / "lcmlog")) return {"lcmlog"};
  std::vector<std::string> names;
  if (!fs::exists(fs::path(dir) / "wire.lcmlog"))
    throw InputError(dir + ": no lcmlog nor wire.lcmlog (not a session folder)");
  names.push_back("wire.lcmlog");
  for (int i = 1; fs::exists(fs::path(dir) / ("wire.lcmlog." + std::to_string(i))); ++i)
    names.push_back("wire.lcmlog." + std::to_string(i));
  return names;
}

}  // namespace

std::int64_t SessionWatch::ReadLog(const std::string& session_dir) {
  const std::vector<std::string> names = SessionLogNames(session_dir);
  std::int64_t n = 0;
  {
    std::lock_guard<std::mutex> lock(mu_);
    reading_log_ = true;
    session_dir_ = std::filesystem::absolute(session_dir).string();
  }
  for (const std::string& name : names) ReadLogFile(session_dir, name, {}, &n);
  // What the network's recorder missed (a burst of commands, a stall) is in
  // the processes' own journals: their commands and answers are read from
  // them too, each once (by its id), at its session time.
  std::int64_t from_journals = 0;
  if (names.front() != "lcmlog") {
    std::error_code ec;
    std::vector<std::string> journals;
    for (const auto& e :
         std::filesystem::directory_iterator(std::filesystem::path(session_dir) / "journal", ec)) {
      const std::string f = e.path().filename().string();
      if (e.is_regular_file(ec) && !e.is_symlink(ec) && f.size() > 7 &&
          f.compare(f.size() - 7, 7, ".lcmlog") == 0)
        journals.push_back("journal/" + f);
    }
    std::sort(journals.begin(), journals.end());
    const std::int64_t events_before = events_seen();
    for (const std::string& j : journals) {
      std::int64_t taken = 0;
      try {
        ReadLogFile(session_dir, j, {wire::channels::kControl, wire::channels::kControlAnswer},
                    &taken);
      } catch (const InputError& e) {
        spdlog::warn("journal {} not read: {}", j, e.what());
      }
    }
    from_journals = events_seen() - events_before;
  }
  std::lock_guard<std::mutex> lock(mu_);
  reading_log_ = false;
  log_times_.clear();
  if (restarted_) {
    AddEvent("station", "STATION RESTARTED: its history recovered from the session's log (" +
                            std::to_string(n) + " messages; " + std::to_string(from_journals) +
                            " events only the processes' journals held)");
  }
  SortEvents();
  return n;
}

// The events in session-time order (what a log and journals read at start
// gave out of order), numbered again: done before anyone has read them.
void SessionWatch::SortEvents() {
  std::stable_sort(events_.begin(), events_.end(),
                   [](const Event& a, const Event& b) { return a.session_s < b.session_s; });
  std::int64_t seq = next_event_seq_ - static_cast<std::int64_t>(events_.size());
  for (Event& e : events_) e.seq = seq++;
}

// The session time at recorder time `log_us`, from the network log's
// messages read (a journal's own messages carry no operator frames).
double SessionWatch::LogSessionTime(std::int64_t log_us) const {
  if (log_times_.empty()) return 0.0;
  auto it = std::upper_bound(
      log_times_.begin(), log_times_.end(), log_us,
      [](std::int64_t t, const std::pair<std::int64_t, double>& p) { return t < p.first; });
  if (it == log_times_.begin()) return it->second;
  return std::prev(it)->second;
}

void SessionWatch::ReadLogFile(const std::string& session_dir, const std::string& name,
                               std::initializer_list<std::string_view> channels,
                               std::int64_t* taken) {
  session::SessionLog log(session_dir, config_.session.frame_rate_hz, name);
  const bool journal = name.rfind("journal/", 0) == 0;
  std::int64_t& n = *taken;
  log.Read(channels, [&](const session::LogMessage& m) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      log_now_us_ = m.log_us;
      if (journal) {
        log_session_s_ = LogSessionTime(m.log_us);
      } else {
        log_session_s_ = m.session_time_s;
        if (log_times_.empty() || log_times_.back().second != m.session_time_s)
          log_times_.emplace_back(m.log_us, m.session_time_s);
      }
    }
    ++n;
    const std::string_view b = m.base;
    if (b == wire::channels::kDcpFrame)
      OnDcpFrame(m.data, m.size, m.log_us);
    else if (b == wire::channels::kDcpTelemetry)
      OnTelemetry(m.data, m.size, m.log_us);
    else if (b == wire::channels::kStatus)
      OnStatus(m.data, m.size);
    else if (b == wire::channels::kControl)
      OnControl(m.data, m.size);
    else if (b == wire::channels::kControlAnswer)
      OnAnswer(m.data, m.size);
    else if (b == wire::channels::kDcpState)
      OnDcpState(m.data, m.size);
    else if (b == wire::channels::kOperatorState)
      OnOperatorState(m.data, m.size);
    else
      --n;
  });
}

bool SessionWatch::restarted() const {
  std::lock_guard<std::mutex> lock(mu_);
  return restarted_;
}

namespace {
std::string MarkEventText(double session_s, const std::string& text) {
  char at[32];
  std::snprintf(at, sizeof at, "%.1f s", session_s);
  return std::string("MARK at ") + at + ": " + text;
}
}  // namespace

void SessionWatch::SetMarksFile(const std::string& path) {
  std::lock_guard<std::mutex> lock(mu_);
  marks_path_ = path;
  // A session's folder is untrusted (docs/security.md): marks are read from
  // a regular file only, never through a link, each line bounded.
  std::error_code ec;
  if (!std::filesystem::is_regular_file(std::filesystem::symlink_status(path, ec))) return;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line) && marks_.size() < kMaxMarks) {
    if (line.size() > kMaxMarkLineBytes) continue;
    const nlohmann::json m = nlohmann::json::parse(line, nullptr, false);
    if (!m.is_object() || !m.contains("session_s") || !m["session_s"].is_number() ||
        !m.contains("text") || !m["text"].is_string())
      continue;
    const double t = m["session_s"].get<double>();
    const std::string text = m["text"].get<std::string>();
    if (!(t >= 0 && t <= kMaxMarkSessionS) || text.empty() || text.size() > kMaxMarkTextBytes)
      continue;  // not a mark the page could have placed
    marks_.push_back(m);
    Event e;
    e.seq = next_event_seq_++;
    e.wall_us = m.value("wall_us", std::int64_t{0});
    e.session_s = t;
    e.kind = "mark";
    e.text = MarkEventText(t, text);
    events_.push_back(std::move(e));
    if (events_.size() > kMaxEvents) events_.pop_front();
  }
  SortEvents();
}

nlohmann::json SessionWatch::AddMark(double session_s, const std::string& text) {
  std::lock_guard<std::mutex> lock(mu_);
  if (text.find_first_not_of(" \t") == std::string::npos)
    throw InputError("form field 'text': a note, not only spaces");
  const double newest =
      dcp_ ? static_cast<double>(dcp_->frame) / config_.session.frame_rate_hz : 0.0;
  // Live, the page's "now" may be a little ahead of the newest frame here;
  // once the session has ended (or in a debrief), nothing is after its end.
  const double ahead_s = state_.ended || debrief_ ? 0.5 / config_.session.frame_rate_hz : 1.0;
  if (session_s > newest + ahead_s) {
    char why[160];
    std::snprintf(why, sizeof why, "parameter t=%.3f: beyond the session's newest frame (%.3f s)",
                  session_s, newest);
    throw InputError(why);
  }
  if (marks_.size() >= kMaxMarks)
    throw InputError("at most " + std::to_string(kMaxMarks) + " marks a session");
  nlohmann::json m = {{"session_s", session_s}, {"wall_us", Now()}, {"text", text}};
  if (!marks_path_.empty()) {
    // Appended whole, never through a link (docs/security.md).
    const std::string line =
        m.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
    const int fd =
        open(marks_path_.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
    const bool ok =
        fd >= 0 && write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size());
    const int err = errno;
    if (fd >= 0) close(fd);
    if (!ok)
      throw InputError("cannot keep the mark in " + marks_path_ + ": " +
                       (err == ELOOP ? std::string("it is a link, refused (docs/security.md)")
                                     : std::string(std::strerror(err))) +
                       " (nothing marked)");
  }
  marks_.push_back(m);
  Event e;
  e.seq = next_event_seq_++;
  e.wall_us = Now();
  e.session_s = session_s;
  e.kind = "mark";
  e.text = MarkEventText(session_s, text);
  events_.push_back(std::move(e));
  if (events_.size() > kMaxEvents) events_.pop_front();
  return m;
}

nlohmann::json SessionWatch::MarksJson() const {
  std::lock_guard<std::mutex> lock(mu_);
  return marks_;
}

}  // namespace rms::instructor_station
