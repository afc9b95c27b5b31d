#include "rms/instructor_station/session_watch.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "rms/dcp_state_t.hpp"
#include "rms/session_control_t.hpp"
#include "rms/transport/process.h"
#include "rms/wire/acquisition_conditions.h"
#include "rms/wire/channels.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/collision_bits.h"
#include "rms/wire/frame_receiver.h"
#include "rms/wire/malfunction.h"
#include "rms/wire/message_io.h"

namespace rms::instructor_station {

namespace {

// A point of the path every this many DCP frames (about 6 a second at 30 Hz).
constexpr std::int64_t kPathEveryFrames = 5;
// A process whose reports stop this long is shown as silent.
constexpr std::int64_t kSilentUs = 3'000'000;

const char* ModeText(int mode) {
  switch (mode) {
    case 1:
      return "Mode 1 (acquisition)";
    case 2:
      return "Mode 2 (extraction)";
    case 3:
      return "Mode 3 (manoeuvring and docking)";
    default:
      return "no mode";
  }
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
                           Counters* counters)
    : config_(config),
      lcm_(lcm),
      counters_(counters),
      instance_(std::to_string(getpid()) + "-" + std::to_string(lcm->NowUs())) {
  dcp_frames_.SetClock(transport::SessionFrameClock(config.session.frame_rate_hz));
  telemetry_seq_.SetClock(transport::SessionFrameClock(config.session.frame_rate_hz));
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
}

void SessionWatch::OnDcpFrame(const void* data, int size, std::int64_t recv_us) {
  std::lock_guard<std::mutex> lock(mu_);
  auto got = wire::ReceiveFrame<dcp_frame_t>(
      data, size, &dcp_frames_, counters_,
      [](const dcp_frame_t& m) { return wire::UnpackDcpFrame(m); }, recv_us);
  if (!got) return;
  wire::DcpFrameData& d = got->second;
  if (d.control.reset && !reset_bit_) AddEvent("reset", "RESET: back to Mode 1");
  reset_bit_ = d.control.reset;
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
  if (t.frame - last_path_frame_ >= kPathEveryFrames || t.frame < last_path_frame_) {
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
  const std::int64_t now = lcm_->NowUs();
  if (p.pid != m.pid) {
    AddEvent("process", m.process + " RESTARTED (pid " + std::to_string(p.pid) + " -> " +
                            std::to_string(m.pid) + ")");
    p.rate_hz = 0;
    p.not_following = 0;
  } else if (p.last_us > 0 && now > p.last_us) {
    p.rate_hz = static_cast<double>(m.frame - p.frame) * 1e6 / static_cast<double>(now - p.last_us);
  }
  if (m.final && !p.ended) AddEvent("process", m.process + " ended");
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
    AddEvent("failure", m.process + " reports a joint or the finger NOT FOLLOWING its command (" +
                            std::to_string(not_following) + " so far)");
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
  text += std::string(" (from ") + wire::ProcessCodeName(m.sender.process) + ")";
  std::lock_guard<std::mutex> lock(mu_);
  AddEvent("control", text);
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
    if (!has(malfunctions_, t))
      AddEvent("malfunction", std::string("MALFUNCTION: ").append(t) + from);
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
  e.wall_us = lcm_->NowUs();
  e.session_s = dcp_ ? static_cast<double>(dcp_->frame) / config_.session.frame_rate_hz : 0.0;
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
  // This station's run: a page that sees it change (the station restarted)
  // reads the events and the path again from the start.
  j["instance"] = instance_;
  return j;
}

}  // namespace rms::instructor_station
