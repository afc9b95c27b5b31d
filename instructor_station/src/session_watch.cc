#include "rms/instructor_station/session_watch.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>

#include "rms/dcp_state_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/session_control_t.hpp"
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
  lcm_->Subscribe(wire::channels::kDcpFrame,
                  [this](const void* d, int n, std::int64_t t) { OnDcpFrame(d, n, t); });
  lcm_->Subscribe(wire::channels::kDcpTelemetry,
                  [this](const void* d, int n, std::int64_t) { OnTelemetry(d, n); });
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

void SessionWatch::OnTelemetry(const void* data, int size) {
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
  if (telemetry_ && t.frame <= telemetry_->frame && t.frame != 0) return;  // old or repeated
  TelemetryEvents(t);
  if (t.frame - last_path_frame_ >= kPathEveryFrames || t.frame < last_path_frame_) {
    path_.push_back({t.frame / config_.session.frame_rate_hz, t.p_RoA_R_ft[0], t.p_RoA_R_ft[1],
                     t.p_RoA_R_ft[2]});
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
  const std::int64_t now = lcm_->NowUs();
  auto [it, is_new] = processes_.try_emplace(m.process);
  Process& p = it->second;
  if (is_new) {
    AddEvent("process", m.process + " up (pid " + std::to_string(m.pid) + " on " + m.host + ")");
  } else if (p.pid != m.pid) {
    AddEvent("process", m.process + " RESTARTED (pid " + std::to_string(p.pid) + " -> " +
                            std::to_string(m.pid) + ")");
    p.rate_hz = 0;
  } else if (p.last_us > 0 && now > p.last_us) {
    p.rate_hz = static_cast<double>(m.frame - p.frame) * 1e6 / static_cast<double>(now - p.last_us);
  }
  if (m.final && !p.ended) AddEvent("process", m.process + " ended");
  // The operator station saw a joint or the finger stop following its
  // command (docs/operator.md "A joint that does not follow").
  const std::string kNotFollowing(CounterName(Counter::kNotFollowing));
  std::int64_t before = 0, after = 0;
  if (auto f = p.figures.find(kNotFollowing); f != p.figures.end()) before = f->second;
  for (int i = 0; i < m.num_counters; ++i) {
    if (m.counter_names[i] == kNotFollowing) after = m.counter_values[i];
  }
  if (after > before && p.pid == m.pid) {
    AddEvent("failure", m.process + " reports a joint or the finger NOT FOLLOWING its command (" +
                            std::to_string(after) + " so far)");
  }
  p.ended = m.final;
  p.pid = m.pid;
  p.host = m.host;
  p.frame = m.frame;
  p.last_us = now;
  p.figures.clear();
  for (int i = 0; i < m.num_counters; ++i) p.figures[m.counter_names[i]] = m.counter_values[i];
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
  e.seq = static_cast<std::int64_t>(events_.size());
  e.wall_us = lcm_->NowUs();
  e.session_s = dcp_ ? static_cast<double>(dcp_->frame) / config_.session.frame_rate_hz : 0.0;
  e.kind = kind;
  e.text = text;
  events_.push_back(std::move(e));
}

std::optional<wire::DcpFrameData> SessionWatch::LatestDcpFrame() const {
  std::lock_guard<std::mutex> lock(mu_);
  return dcp_;
}

std::int64_t SessionWatch::events_seen() const {
  std::lock_guard<std::mutex> lock(mu_);
  return static_cast<std::int64_t>(events_.size());
}

nlohmann::json SessionWatch::EventsJson(std::int64_t since, int limit) const {
  std::lock_guard<std::mutex> lock(mu_);
  nlohmann::json out = nlohmann::json::array();
  for (std::int64_t i = std::max<std::int64_t>(0, since);
       i < static_cast<std::int64_t>(events_.size()) && static_cast<int>(out.size()) < limit; ++i) {
    const Event& e = events_[static_cast<std::size_t>(i)];
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
  for (std::size_t i = since; i < path_.size(); ++i)
    points.push_back({path_[i][0], path_[i][1], path_[i][2], path_[i][3]});
  return {{"next", path_.size()}, {"points", points}};
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
    std::int64_t dropped = 0;
    nlohmann::json latency = nlohmann::json::object();
    for (const auto& [k, v] : p.figures) {
      if (k.rfind("dropped.", 0) == 0) dropped += v;
      if (k.rfind("latency.", 0) == 0 && k.size() > 7 && k.compare(k.size() - 7, 7, ".p50_us") == 0)
        latency[k.substr(8, k.size() - 15)]["p50_ms"] = v / 1000.0;
      if (k.rfind("latency.", 0) == 0 && k.size() > 7 && k.compare(k.size() - 7, 7, ".p99_us") == 0)
        latency[k.substr(8, k.size() - 15)]["p99_ms"] = v / 1000.0;
    }
    q["dropped"] = dropped;
    q["latency"] = latency;
    for (const char* k : {"frames.late", "superseded", "input.missing", "dcp.missing",
                          "esg.missing", "control.freezes", "control.steps", "control.malfunctions",
                          "control.repairs", "arm.not_following"}) {
      if (auto f = p.figures.find(k); f != p.figures.end()) q["counters"][k] = f->second;
    }
    procs[name] = q;
  }
  j["processes"] = procs;
  j["events"] = static_cast<std::int64_t>(events_.size());
  j["malfunctions"] = malfunctions_;
  // This station's run: a page that sees it change (the station restarted)
  // reads the events and the path again from the start.
  j["instance"] = instance_;
  return j;
}

}  // namespace rms::instructor_station
