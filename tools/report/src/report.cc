#include "rms/report/report.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <set>
#include <sstream>

#include "rms/base/analog_inputs.h"
#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/base/text.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/operator_input_t.hpp"
#include "rms/operator_state_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/session/session_folder.h"
#include "rms/session/session_log.h"
#include "rms/session/session_summary.h"
#include "rms/session_control_t.hpp"
#include "rms/wire/channels.h"
#include "rms/wire/collision_bits.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/message_io.h"

namespace fs = std::filesystem;

namespace rms::report {

std::string DefaultChartJsPath() { return "/usr/share/javascript/chart.js/chart.min.js"; }

namespace {

std::string F(double v, int digits = 3) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(digits);
  os << v;
  return os.str();
}

// Percentile of a sample (sorted copy), q in [0, 1].
double Pct(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::round(q * (v.size() - 1)))];
}

// What the report reads from the log in one pass (SessionLog): the series
// of its plots, its events, and the operator's frame intervals outside
// freezes.
struct Traces {
  nlohmann::json t_s = nlohmann::json::array(), mode = nlohmann::json::array(),
                 attempt = nlohmann::json::array(), p_ft = nlohmann::json::array(),
                 payload_ft = nlohmann::json::array(), joints_deg = nlohmann::json::array(),
                 finger = nlohmann::json::array(), goal_ft = nlohmann::json::array(),
                 dock_angle_deg = nlohmann::json::array(), inputs = nlohmann::json::array();
  bool by_hand = false;
  nlohmann::json events = nlohmann::json::array();
  std::vector<double> intervals_ms, to_dcp_ms, to_esg_ms;
  double longest_stall_ms = 0, longest_stall_at_s = 0;
  long frames = 0;
};

struct TraceReader {
  TraceReader(const LabConfig& c, const nlohmann::ordered_json& a) : config(c), attempts(a) {}
  const LabConfig& config;
  const nlohmann::ordered_json& attempts;
  Traces t;
  std::size_t every = 1;  // keep one telemetry sample in `every`
  int last_mode = 0;
  bool last_held = false;
  double held_since = 0;
  std::int64_t last_input_send = -1;
  bool frozen = false;
  bool froze_since_input = false;  // a freeze (or a restore, which freezes) since the last input
  bool last_input_frozen = false;  // the last input was made frozen (a step)
  std::int64_t frozen_us = 0;
  double frozen_at_s = 0;
  std::map<std::string, int> status_pid;
  // What the hand controllers command (operator_state_t hand_rate): x, y, z
  // ft/s, roll, pitch, yaw deg/s; in single joint the joint's rate, deg/s,
  // is a seventh column (hand_rate[0] there), the six others 0.
  std::array<double, 7> hand{};

  void Event(double t_s, const char* kind, const std::string& text, double duration_s = -1) {
    nlohmann::json e = {{"t_s", t_s}, {"kind", kind}, {"text", text}};
    if (duration_s >= 0) e["duration_s"] = duration_s;
    t.events.push_back(e);
  }
  int AttemptAt(double t_s) const {
    int n = 1;
    for (const auto& a : attempts) {
      if (a["start_s"].get<double>() <= t_s + 1e-9) n = a["index"].get<int>();
    }
    return n;
  }
  // The unsigned distance to the mode's goal: Mode 1 point A to the BAR's
  // centre (where the grasp is), Modes 2-3 the probe's tip to the port.
  double Goal(const dcp_telemetry_t& m) const {
    if (m.mode != wire::DcpMode::kAcquisition) return std::abs(m.dock_distance_ft);
    Eigen::Matrix3d R_RP;
    for (int i = 0; i < 9; ++i) R_RP(i / 3, i % 3) = m.R_RP[i];
    const Eigen::Vector3d bar =
        Eigen::Vector3d(m.p_RoPo_R_ft[0], m.p_RoPo_R_ft[1], m.p_RoPo_R_ft[2]) +
        R_RP * config.payload.p_PoBar_P_ft;
    return (Eigen::Vector3d(m.p_RoA_R_ft[0], m.p_RoA_R_ft[1], m.p_RoA_R_ft[2]) - bar).norm();
  }
  void Telemetry(const dcp_telemetry_t& m, double t_s) {
    ++t.frames;
    if (m.mode != last_mode) {
      if (last_mode != 0)
        Event(t_s, "mode", "Mode " + std::to_string(last_mode) + " -> " + std::to_string(m.mode));
      last_mode = m.mode;
    }
    // (Collisions: the summary's own, in Finish: one set in the timeline,
    // the tables and summary.json.)
    if (m.held && !last_held) held_since = t_s;
    if (!m.held && last_held) Event(held_since, "hold", "arm held", t_s - held_since);
    last_held = m.held;
    if (t.frames % static_cast<long>(every) != 0) return;
    t.t_s.push_back(t_s);
    t.mode.push_back(m.mode);
    t.attempt.push_back(AttemptAt(t_s));
    t.p_ft.push_back({m.p_RoA_R_ft[0], m.p_RoA_R_ft[1], m.p_RoA_R_ft[2]});
    t.payload_ft.push_back({m.p_RoPo_R_ft[0], m.p_RoPo_R_ft[1], m.p_RoPo_R_ft[2]});
    t.joints_deg.push_back(std::vector<double>(m.slave_angles_deg, m.slave_angles_deg + 6));
    t.finger.push_back(m.slave_finger);
    t.goal_ft.push_back(Goal(m));
    t.dock_angle_deg.push_back(m.mode == wire::DcpMode::kAcquisition
                                   ? nlohmann::json(nullptr)
                                   : nlohmann::json(m.dock_angle_deg));
    t.inputs.push_back(std::vector<double>(hand.begin(), hand.end()));
  }
  void Finish(double t_s, const nlohmann::ordered_json& collisions) {
    // The summary's collisions (the detrimental ones: the finger resting on
    // the bar is the essential contact, docs/collision.md), as it counts them.
    for (const auto& c : collisions) {
      Event(c["start_s"].get<double>(), "collision",
            c["kind"].get<std::string>() + (c.value("open", false) ? " (to the end)" : ""),
            c["duration_s"].get<double>());
    }
    if (last_held) Event(held_since, "hold", "arm held (to the end)", t_s - held_since);
    for (const auto& a : attempts) {
      if (a["started_by"] == "start") continue;
      Event(a["start_s"].get<double>(), a["started_by"] == "reset" ? "reset" : "restore",
            a["started_by"].get<std::string>() + " (attempt " +
                std::to_string(a["index"].get<int>()) + ")");
    }
    std::stable_sort(t.events.begin(), t.events.end(),
                     [](const nlohmann::json& x, const nlohmann::json& y) {
                       return x["t_s"].get<double>() < y["t_s"].get<double>();
                     });
  }
  void Control(const session_control_t& m, std::int64_t log_us, double t_s) {
    if (m.command == session_control_t::FREEZE && !frozen) {
      frozen = true;
      frozen_us = log_us;
      frozen_at_s = t_s;
    } else if (m.command == session_control_t::RUN && frozen) {
      frozen = false;
      // Session time stood still: a point on the session's axis, its wall
      // length said (docs/sessions.md "Session time").
      const double d = (log_us - frozen_us) * 1e-6;
      Event(frozen_at_s, "freeze",
            "frozen " + HumanNumber(d, 1) + " s of wall time (session time stood still)");
    }
    if (m.command == session_control_t::FREEZE || m.command == session_control_t::RESTORE)
      froze_since_input = true;
  }
  void Input(const operator_input_t& m) {
    // An interval across a freeze is the freeze, not a stall: frozen now, or
    // frozen (and run again) since the last input.
    // (A step's frame is made while frozen: the interval from it to the next
    // one is frozen time too.)
    const bool across_freeze = frozen || froze_since_input || last_input_frozen;
    froze_since_input = false;
    last_input_frozen = frozen;
    if (last_input_send >= 0 && !across_freeze) {
      const double ms = (m.send_time_us - last_input_send) / 1000.0;
      t.intervals_ms.push_back(ms);
      if (ms > t.longest_stall_ms) {
        t.longest_stall_ms = ms;
        t.longest_stall_at_s = m.frame / config.session.frame_rate_hz;
      }
    }
    last_input_send = m.send_time_us;
  }
  void Status(const process_status_t& m, double t_s) {
    const auto it = status_pid.find(m.process);
    if (it != status_pid.end() && it->second != m.pid)
      Event(t_s, "restart", m.process + " restarted");
    status_pid[m.process] = m.pid;
  }
  void OperatorState(const operator_state_t& m) {
    if (m.source != operator_state_t::SOURCE_BY_HAND) return;
    t.by_hand = true;
    hand = {};
    if (m.control_mode == operator_state_t::CONTROL_SINGLE_JOINT)
      hand[6] = m.hand_rate[0];
    else
      for (int i = 0; i < kNumJoints; ++i) hand[i] = m.hand_rate[i];
  }
};

Traces ReadTraces(const std::string& dir, const LabConfig& config,
                  const nlohmann::ordered_json& summary) {
  session::SessionLog log(dir);
  TraceReader r(config, summary["attempts"]);
  const long frames = summary.value("telemetry_frames", 0L);
  r.every = static_cast<std::size_t>(std::max(1L, frames / 3000 + 1));
  const double rate = config.session.frame_rate_hz;
  double last_t = 0;
  log.Read({wire::channels::kDcpTelemetry, wire::channels::kControl, wire::channels::kOperatorInput,
            wire::channels::kEsgFrame, wire::channels::kStatus, wire::channels::kOperatorState},
           [&](const session::LogMessage& ev) {
             if (ev.base == wire::channels::kDcpTelemetry) {
               dcp_telemetry_t m{};
               if (!log.Decode(ev, &m)) return;
               last_t = m.input_frame / rate;
               r.Telemetry(m, last_t);
               r.t.to_dcp_ms.push_back((ev.log_us - m.input_send_time_us) / 1000.0);
             } else if (ev.base == wire::channels::kControl) {
               session_control_t m;
               if (log.Decode(ev, &m)) r.Control(m, ev.log_us, ev.session_time_s);
             } else if (ev.base == wire::channels::kOperatorInput) {
               operator_input_t m{};
               if (log.Decode(ev, &m)) r.Input(m);
             } else if (ev.base == wire::channels::kEsgFrame) {
               esg_frame_t m{};
               if (log.Decode(ev, &m))
                 r.t.to_esg_ms.push_back((ev.log_us - m.input_send_time_us) / 1000.0);
             } else if (ev.base == wire::channels::kStatus) {
               process_status_t m;
               if (log.Decode(ev, &m)) r.Status(m, ev.session_time_s);
             } else {
               operator_state_t m{};
               if (log.Decode(ev, &m)) r.OperatorState(m);
             }
           });
  r.Finish(last_t + 1.0 / rate, summary["collisions"]);
  return std::move(r.t);
}

// The session's losses, each kind apart (docs/sessions.md "Losses"): frames
// lost on a link, frames the processes refused, frames the record lost, and
// logged messages the summary left out as not the session's own.
std::string LossesSection(const nlohmann::ordered_json& s) {
  std::ostringstream h;
  h << "<h2>Losses and refusals</h2>\n";
  // Damage to the log itself first: what it held there is in no figure
  // below (docs/sessions.md "A damaged log").
  if (s.contains("log") && s["log"].is_object()) {
    const auto skipped = s["log"].value("skipped_bytes", std::int64_t{0});
    const auto unread = s["log"].value("unread_bytes", std::int64_t{0});
    if (skipped > 0)
      h << "<p class=\"bad\"><b>The log is damaged:</b> " << skipped << " bytes in "
        << s["log"].value("skipped_places", std::int64_t{0})
        << " place(s) are no event, read past; what they held is in no figure of this "
           "report.</p>\n";
    if (unread > 0)
      h << "<p class=\"bad\"><b>The log ends in " << unread
        << " bytes that are no whole event</b> (cut short, or damaged there): what they held "
           "is in no figure of this report.</p>\n";
  }
  h << "<table><tr><th>what</th><th>frames or messages</th></tr>";
  auto row = [&h](const std::string& what, const nlohmann::ordered_json& n) {
    h << "<tr><td>" << HtmlText(what) << "</td><td>"
      << (n.is_number() ? n.dump() : std::string("-")) << "</td></tr>";
  };
  const auto empty = nlohmann::ordered_json::object();
  auto part = [&empty](const nlohmann::ordered_json& j, const char* a,
                       const char* b) -> const nlohmann::ordered_json& {
    if (!j.contains(a) || !j[a].is_object() || !j[a].contains(b) || !j[a][b].is_object())
      return empty;
    return j[a][b];
  };
  for (const auto& [k, v] : part(s, "frames", "dropped").items()) {
    row((k.rfind("malformed", 0) == 0 ? "malformed, dropped: " : "lost on the link: ") + k, v);
  }
  for (const auto& [k, v] : part(s, "frames", "refused").items())
    row("refused by the processes: " + k, v);
  for (const auto& [ch, r] : part(s, "record", "by_channel").items()) {
    row("lost by the record: " + ch + " (of " +
            r.value("published", nlohmann::ordered_json()).dump() + " published)",
        r.value("lost", nlohmann::ordered_json()));
  }
  const nlohmann::ordered_json& network = part(s, "record", "network");
  if (network.contains("missed_by_channel") && network["missed_by_channel"].is_object()) {
    for (const auto& [ch, n] : network["missed_by_channel"].items())
      row("missed by the network's recorder (the record has them from the journals): " + ch, n);
  }
  for (const auto& [k, v] : part(s, "ignored", "by_reason").items()) {
    row("left out of this report (another session's, or not believed): " + k, v);
  }
  h << "</table>\n";
  return h.str();
}

std::string StatsRow(const std::string& name, const std::vector<double>& v) {
  if (v.empty()) return "<tr><td>" + HtmlText(name) + "</td><td colspan=5>none</td></tr>";
  double mean = 0;
  for (double x : v) mean += x;
  mean /= v.size();
  return "<tr><td>" + HtmlText(name) + "</td><td>" + std::to_string(v.size()) + "</td><td>" +
         F(mean, 2) + "</td><td>" + F(Pct(v, 0.5), 2) + "</td><td>" + F(Pct(v, 0.99), 2) +
         "</td><td>" + F(*std::max_element(v.begin(), v.end()), 2) + "</td></tr>";
}

}  // namespace

namespace {

std::string Cell(const nlohmann::ordered_json& v, const char* unit = "", int decimals = 3) {
  if (v.is_null()) return "-";
  if (v.is_number()) return HumanNumber(v.get<double>(), decimals) + unit;
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  if (v.is_string()) return HtmlText(v.get<std::string>());
  return HtmlText(v.dump());
}

// A time (session time, s; docs/sessions.md "Session time"): shown rounded
// for reading, the exact value -- the shortest text that reads back as the
// same double -- in the cell's title and data-s, so nothing is lost.
std::string TimeCell(const nlohmann::ordered_json& v, const char* unit = "", int decimals = 3) {
  if (!v.is_number()) return Cell(v, unit, decimals);
  const std::string exact = nlohmann::json(v.get<double>()).dump();
  return "<span data-s=\"" + exact + "\" title=\"" + exact + " s\">" + Cell(v, unit, decimals) +
         "</span>";
}

std::string Row(const std::string& th, const std::vector<std::string>& cells) {
  std::string r = "<tr><th>" + th + "</th>";
  for (const auto& c : cells) r += "<td>" + c + "</td>";
  return r + "</tr>";
}

nlohmann::ordered_json ReadManifest(const fs::path& root) {
  std::error_code ec;
  if (fs::exists(fs::symlink_status(root / "manifest.json", ec))) {
    try {
      return nlohmann::ordered_json::parse(
          session::ReadSessionFile(root.string(), "manifest.json", kMaxJsonBytes));
    } catch (const std::exception&) {
    }
  }
  return nlohmann::ordered_json::object();
}

std::string SessionSection(const nlohmann::ordered_json& m, const nlohmann::ordered_json& s) {
  std::ostringstream h;
  h << "<h2>Session</h2>\n<table>";
  auto field = [&](const char* th, const nlohmann::ordered_json& v) {
    if (!v.is_null()) h << Row(th, {Cell(v)});
  };
  field("session", s.value("session", nlohmann::ordered_json()));
  field("session id", m.value("session_id", nlohmann::ordered_json()));
  field("subject", m.value("subject", nlohmann::ordered_json()));
  field("note", m.value("note", nlohmann::ordered_json()));
  field("pilot", m.value("pilot", s.value("pilot", nlohmann::ordered_json())));
  field("kind", m.value("kind", nlohmann::ordered_json()));
  field("re-simulation of", m.value("resimulation_of", nlohmann::ordered_json()));
  field("started (UTC)", m.value("started_utc", nlohmann::ordered_json()));
  if (m.contains("software"))
    field("software", m["software"].value("version", nlohmann::ordered_json()));
  if (m.contains("config"))
    field("configuration",
          m["config"].value("source", m["config"].value("file", nlohmann::ordered_json())));
  if (m.contains("hosts")) {
    std::string hosts;
    for (const auto& [p, host] : m["hosts"].items())
      hosts += (hosts.empty() ? "" : ", ") + p + " on " + host.get<std::string>();
    field("hosts", hosts);
  }
  if (s.contains("duration_s")) h << Row("session time", {TimeCell(s["duration_s"], " s", 1)});
  if (s.contains("wall_duration_s"))
    h << Row("wall time", {TimeCell(s["wall_duration_s"], " s", 1)});
  h << "</table>\n";
  return h.str();
}

std::string TolerancesSection(const LabConfig& c) {
  std::ostringstream h;
  h << "<h2>The configuration's tolerances</h2>\n<table>";
  h << Row("D3Y (acquisition: the finger gap below)", {HumanNumber(c.dcp.d3y_ft, 4) + " ft"});
  h << Row("TPOB (acquisition: EFF HEX 1 face d to the BAR's face c within)",
           {HumanNumber(c.dcp.tpob_ft, 4) + " ft"});
  h << Row("docking distance (probe tip to port centre, at most)",
           {HumanNumber(c.dcp.dock_distance_ft, 4) + " ft"});
  h << Row("docking angle (probe axis to port axis, at most)",
           {HumanNumber(c.dcp.dock_angle_deg, 4) + " deg"});
  h << Row("frame rate", {HumanNumber(c.session.frame_rate_hz, 2) + " Hz"});
  h << "</table>\n";
  return h.str();
}

std::string AttemptsSection(const nlohmann::ordered_json& s) {
  std::ostringstream h;
  const auto& attempts = s["attempts"];
  h << "<h2>Attempts</h2>\n<p>The start, each reset and each restore begins an attempt. Times are "
       "session time (the "
       "operator's frames over the frame rate): they stand still in a freeze and read as flown at "
       "any speed.</p>\n";
  if (attempts.empty()) return h.str() + "<p>No DCP frame in the log: no attempt.</p>\n";
  h << "<table><tr><th>attempt</th><th>started by</th><th>start, s</th><th>duration, "
       "s</th><th>outcome</th>"
       "<th>acquisition, s</th><th>extraction, s</th><th>manoeuvring, s</th><th>docking, "
       "s</th><th>collisions</th>"
       "<th>arm held, s</th><th>docked at, ft</th><th>docked at, deg</th></tr>";
  for (const auto& a : attempts) {
    const auto& ph = a["phase_durations_s"];
    const auto& d = a["docking"];
    h << "<tr><td>" << a["index"] << "</td><td>" << Cell(a["started_by"])
      << (a.contains("restored") ? " " + Cell(a["restored"]) : "") << "</td><td>"
      << TimeCell(a["start_s"], "", 2) << "</td><td>" << TimeCell(a["duration_s"], "", 2)
      << "</td><td class=\"" << (a["outcome"] == "docked" ? "ok" : "bad") << "\">"
      << Cell(a["outcome"]) << "</td>";
    for (const char* p : {"acquisition", "extraction", "maneuvering", "docking"}) {
      h << "<td>"
        << (ph[p].is_null()
                ? std::string(a["started_in_mode"].get<int>() > 1 && std::string(p) == "acquisition"
                                  ? "before this attempt"
                                  : "not reached")
                : TimeCell(ph[p], "", 2))
        << "</td>";
    }
    h << "<td>" << a["collisions"]["events"] << "</td><td>"
      << TimeCell(a["holds"]["arm"]["duration_s"], "", 2) << "</td><td>"
      << (d.is_object() ? Cell(d["distance_ft"], "", 4) : "-") << "</td><td>"
      << (d.is_object() ? Cell(d["angle_deg"], "", 3) : "-") << "</td></tr>";
  }
  h << "</table>\n";
  const auto& t = s["totals"];
  h << "<p>In all: " << t["attempts"] << " attempts (" << t["resets"] << " resets, "
    << t["restores"] << " restores), " << t["attempts_docked"] << " docked, " << t["collisions"]
    << " collisions, " << t["restarts"] << " process restarts.</p>\n";
  return h.str();
}

// docs/sessions.md "Malfunctions": each change, with its time and frame.
std::string MalfunctionsSection(const nlohmann::ordered_json& s) {
  const auto& list = s["malfunctions"];
  if (!list.is_array() || list.empty()) return "";
  std::ostringstream h;
  auto texts = [](const nlohmann::ordered_json& a) {
    std::string out;
    for (const auto& t : a) out += (out.empty() ? "" : "; ") + HtmlText(t.get<std::string>());
    return out.empty() ? std::string("-") : out;
  };
  h << "<h2>Malfunctions</h2>\n<p>As the DCP took them (its logged states): each from the DCP "
       "frame given, at session time; a restore or a resumed process may change them too.</p>\n"
       "<table><tr><th>time, s</th><th>from DCP frame</th><th>by</th><th>injected</th>"
       "<th>repaired</th><th>in force after</th></tr>";
  for (const auto& m : list) {
    h << "<tr><td>" << TimeCell(m["time_s"], "", 2) << "</td><td>" << m["dcp_frame"] << "</td><td>"
      << Cell(m["why"]) << "</td><td" << (m["injected"].empty() ? "" : " class=\"bad\"") << ">"
      << texts(m["injected"]) << "</td><td>" << texts(m["repaired"])
      << (m["replaced"].empty() ? "" : " (replaced: " + texts(m["replaced"]) + ")") << "</td><td>"
      << texts(m["in_force"]) << "</td></tr>";
  }
  h << "</table>\n";
  return h.str();
}

// docs/sessions.md "Freeze, run, step, checkpoint": each command, who sent
// it, and what the processes that acted on it answered.
std::string ControlSection(const nlohmann::ordered_json& s) {
  const auto& list = s["control"];
  if (!list.is_array() || list.empty()) return "";
  std::ostringstream h;
  h << "<h2>Session control</h2>\n<p>Each command as sent, and each answer of the processes that "
       "acted on it (RMS_CONTROL_ANSWER): done, or refused with the reason.</p>\n"
       "<table><tr><th>time, s</th><th>from</th><th>command</th><th>answers</th></tr>";
  for (const auto& c : list) {
    std::string answers;
    if (c.contains("answers")) {
      for (const auto& a : c["answers"]) {
        const bool done = a["outcome"] == "done";
        answers += std::string(answers.empty() ? "" : "<br>") + "<span class=\"" +
                   (done ? "ok" : "bad") + "\">" + (done ? "done" : "REFUSED") + "</span> (" +
                   HtmlText(a["process"].get<std::string>()) +
                   "): " + HtmlText(a["text"].get<std::string>());
      }
    }
    h << "<tr><td>" << TimeCell(c["time_s"], "", 2) << "</td><td>" << Cell(c["process"])
      << "</td><td>" << Cell(c["command"])
      << (c.contains("name") ? " " + HtmlText(c["name"].get<std::string>()) : "") << "</td><td>"
      << (answers.empty() ? "none" : answers) << "</td></tr>";
  }
  h << "</table>\n";
  return h.str();
}

// docs/instructor.md "Marks": the instructor's marks and notes, from
// SESSION/instructor_marks.jsonl (untrusted: each line a JSON object, its
// text shown as text; at most 1000).
std::string MarksSection(const fs::path& root) {
  std::error_code ec;
  if (!fs::is_regular_file(fs::symlink_status(root / "instructor_marks.jsonl", ec))) return "";
  std::ifstream in(root / "instructor_marks.jsonl");
  std::vector<std::pair<double, std::string>> marks;  // session time, note
  std::string line;
  while (marks.size() < 1000 && std::getline(in, line)) {
    if (line.size() > 4096) continue;
    const auto m = nlohmann::ordered_json::parse(line, nullptr, false);
    if (!m.is_object() || !m.contains("session_s") || !m["session_s"].is_number() ||
        !m.contains("text") || !m["text"].is_string())
      continue;
    const double t = m["session_s"].get<double>();
    if (!(t >= 0 && t <= 1e7)) continue;
    marks.emplace_back(t, m["text"].get<std::string>().substr(0, 500));
  }
  if (marks.empty()) return "";
  std::stable_sort(marks.begin(), marks.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::ostringstream h;
  h << "<h2>The instructor's marks</h2>\n<table><tr><th>time, s</th><th>note</th></tr>";
  for (const auto& [t, text] : marks)
    h << "<tr><td>" << TimeCell(nlohmann::ordered_json(t), "", 1) << "</td><td>" << HtmlText(text)
      << "</td></tr>";
  h << "</table>\n";
  return h.str();
}

std::string ScorecardSection(const nlohmann::ordered_json& s) {
  const auto& attempts = s["attempts"];
  if (attempts.empty()) return "";
  std::ostringstream h;
  h << "<h2>The operator's scorecard</h2>\n<table><tr><th>attempt</th>";
  for (const auto& a : attempts) h << "<th>" << a["index"] << "</th>";
  h << "</tr>";
  auto line = [&](const std::string& th,
                  const std::function<std::string(const nlohmann::ordered_json&)>& f) {
    std::vector<std::string> cells;
    for (const auto& a : attempts) cells.push_back(f(a["scorecard"]));
    h << Row(th, cells);
  };
  line("task time (start to docked), s",
       [](const auto& c) { return TimeCell(c["task_time_s"], "", 2); });
  line("least clearance, point A to the payload's surface, ft", [](const auto& c) {
    return Cell(c["least_clearance_ft"]["end_effector_to_payload"], "", 3);
  });
  line("least clearance, payload to the bay's walls and floor (Mode 2), ft",
       [](const auto& c) { return Cell(c["least_clearance_ft"]["payload_to_bay"], "", 3); });
  line("least clearance, payload to the CAE's port face (Mode 3), ft",
       [](const auto& c) { return Cell(c["least_clearance_ft"]["payload_to_cae"], "", 3); });
  for (const auto& [k, label] :
       std::vector<std::pair<std::string, std::string>>{{"d3y", "D3Y"},
                                                        {"tpob", "TPOB"},
                                                        {"dock_distance", "the docking distance"},
                                                        {"dock_angle", "the docking angle"}}) {
    line("time within 10% of " + label + ", s",
         [k = k](const auto& c) { return TimeCell(c["near_tolerance_s"][k], "", 2); });
  }
  line("finger closures / that did not acquire", [](const auto& c) {
    return Cell(c["finger_closures"]) + " / " + Cell(c["closures_not_acquiring"]);
  });
  line("actions by device", [](const auto& c) {
    std::string out;
    for (const auto& [dev, n] : c["inputs"]["actions_by_device"].items())
      out += (out.empty() ? "" : "<br>") + HtmlText(dev) + ": " + n.dump();
    return out.empty() ? std::string("-") : out;
  });
  line("reversals (an axis commanded back the other way)",
       [](const auto& c) { return Cell(c["inputs"]["reversals"]); });
  line("time moving, s", [](const auto& c) { return TimeCell(c["inputs"]["moving_s"], "", 2); });
  line("share of it moving more than one axis at once", [](const auto& c) {
    return HumanNumber(100 * c["inputs"]["multi_axis_share"].template get<double>(), 1) + "%";
  });
  line("time slowed at a joint's rate limit, s",
       [](const auto& c) { return TimeCell(c["inputs"]["rate_limited_s"], "", 2); });
  h << "</table>\n<table><tr><th>collisions by kind (events, s)</th>";
  for (const auto& a : attempts) h << "<th>" << a["index"] << "</th>";
  h << "</tr>";
  std::set<std::string> kinds;
  for (const auto& a : attempts) {
    for (const auto& [k, v] : a["collisions"]["by_kind"].items()) kinds.insert(k);
  }
  for (const auto& k : kinds) {
    std::vector<std::string> cells;
    for (const auto& a : attempts) {
      const auto& b = a["collisions"]["by_kind"];
      cells.push_back(
          b.contains(k) ? b[k]["events"].dump() + ", " + TimeCell(b[k]["duration_s"], "", 2) : "-");
    }
    h << Row(HtmlText(k), cells);
  }
  if (kinds.empty()) h << "<tr><td colspan=\"99\">no collision</td></tr>";
  h << "</table>\n";
  return h.str();
}

std::string TimingSection(const nlohmann::ordered_json& s, const Traces& t) {
  std::ostringstream h;
  h << "<h2>Frame times and latency</h2>\n<table><tr><th>what</th><th>n</th><th>mean, "
       "ms</th><th>p50, ms</th>"
       "<th>p99, ms</th><th>max, ms</th></tr>";
  h << StatsRow("operator frame interval (freezes left out)", t.intervals_ms);
  h << StatsRow("operator input to DCP output (logged)", t.to_dcp_ms);
  h << StatsRow("operator input to ESG frame (logged)", t.to_esg_ms);
  h << "</table>\n";
  if (t.longest_stall_ms > 3000.0 / 30) {
    h << "<p class=\"bad\">The longest operator frame interval outside a freeze: "
      << HumanNumber(t.longest_stall_ms, 0) << " ms at " << TimeCell(t.longest_stall_at_s, "", 1)
      << " s: a stall (the station did not run for that long).</p>\n";
  }
  h << "<table><tr><th>process</th><th>frames lost on the way in</th><th>late</th><th>too late, "
       "dropped</th>"
       "<th>malformed</th><th>links: p50 / p99 / max, ms</th></tr>";
  if (s.contains("timing")) {
    for (const auto& [proc, v] : s["timing"].items()) {
      if (!v.is_object()) continue;
      std::string links;
      if (v.contains("latency")) {
        for (const auto& [link, l] : v["latency"].items()) {
          links += (links.empty() ? "" : "<br>") + HtmlText(link) + ": " +
                   Cell(l["p50_ms"], "", 2) + " / " + Cell(l["p99_ms"], "", 2) + " / " +
                   Cell(l["max_ms"], "", 2);
        }
      }
      h << "<tr><td>" << HtmlText(proc) << "</td><td>"
        << Cell(v.value("dropped_frames", nlohmann::ordered_json())) << "</td><td>"
        << Cell(v.value("late_frames", nlohmann::ordered_json())) << "</td><td>"
        << Cell(v.value("too_late_dropped", nlohmann::ordered_json())) << "</td><td>"
        << Cell(v.value("malformed", nlohmann::ordered_json())) << "</td><td>"
        << (links.empty() ? "-" : links) << "</td></tr>";
    }
  }
  h << "</table>\n";
  return h.str();
}

std::string Base64(const std::string& in) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  int val = 0, bits = -6;
  for (unsigned char c : in) {
    val = (val << 8) + c;
    bits += 8;
    while (bits >= 0) {
      out.push_back(k[(val >> bits) & 0x3F]);
      bits -= 6;
    }
  }
  if (bits > -6) out.push_back(k[((val << 8) >> (bits + 8)) & 0x3F]);
  while (out.size() % 4) out.push_back('=');
  return out;
}

// Up to 8 of the session's PNG frames, evenly spread, embedded (at most
// about 4 MB of them), and a link to its video.
std::string FramesSection(const fs::path& root, const fs::path& report_dir, double rate_hz) {
  std::ostringstream h;
  h << "<h2>Frames</h2>\n";
  std::vector<fs::path> pngs;
  if (fs::is_directory(root / "frames")) {
    for (const auto& e : fs::directory_iterator(root / "frames")) {
      if (e.path().extension() == ".png") pngs.push_back(e.path());
    }
  }
  std::sort(pngs.begin(), pngs.end());
  const fs::path video = root / "session.mp4";
  if (fs::exists(video)) {
    const std::string href = fs::relative(fs::absolute(video), fs::absolute(report_dir)).string();
    h << "<p>The session's video: <a href=\"" << HtmlText(href) << "\">" << HtmlText(href)
      << "</a>.</p>\n";
  } else {
    h << "<p>No video in the session folder (it was run with --no-video, or the renderer ran on "
         "another host).</p>\n";
  }
  if (pngs.empty()) return h.str() + "<p>No PNG frames (--png-every 0).</p>\n";
  const std::size_t n = std::min<std::size_t>(8, pngs.size());
  std::size_t bytes = 0;
  h << "<div class=\"thumbs\">";
  for (std::size_t i = 0; i < n; ++i) {
    const fs::path& p = pngs[n == 1 ? 0 : i * (pngs.size() - 1) / (n - 1)];
    std::string png;
    try {  // a frame is read only as a regular file of the folder (docs/security.md)
      png = ReadRegularFile(p.string(), "a PNG frame", kMaxPngBytes);
    } catch (const InputError& e) {
      h << "<p class=\"bad\">Left out: " << HtmlText(e.what()) << "</p>";
      continue;
    }
    bytes += png.size();
    if (bytes > 4u << 20) break;
    const std::string stem = p.stem().string();
    const long frame = std::strtol(stem.substr(stem.find('_') + 1).c_str(), nullptr, 10);
    h << "<figure><img alt=\"" << HtmlText(stem) << "\" src=\"data:image/png;base64," << Base64(png)
      << "\"><figcaption>frame " << frame << ", " << HumanNumber(frame / rate_hz, 1)
      << " s</figcaption></figure>";
  }
  h << "</div>\n";
  return h.str();
}

nlohmann::json Box(const std::vector<Eigen::Vector3d>& pts) {
  Eigen::Vector3d lo = pts[0], hi = pts[0];
  for (const auto& p : pts) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return {{"x", {lo.x(), hi.x()}}, {"y", {lo.y(), hi.y()}}, {"z", {lo.z(), hi.z()}}};
}

nlohmann::json Geometry(const LabConfig& c) {
  const ShuttleConfig& s = c.shuttle;
  nlohmann::json g;
  g["bay"] =
      Box({{0, -s.bay_width_ft / 2, -s.bay_depth_ft}, {s.bay_length_ft, s.bay_width_ft / 2, 0}});
  // The CAE, a hexagonal prism in C (x_C +-rc, y_C 0..across flats, z_C +-length/2).
  const double fl = c.cae.across_flats_ft, rc = fl / std::sqrt(3.0), hl = c.cae.length_ft / 2;
  std::vector<Eigen::Vector3d> corners;
  for (double x : {-rc, rc}) {
    for (double y : {0.0, fl}) {
      for (double z : {-hl, hl})
        corners.push_back(c.cae.p_RoCo_R_ft + c.cae.R_RC * Eigen::Vector3d(x, y, z));
    }
  }
  g["cae"] = Box(corners);
  const Eigen::Vector3d bar = c.payload.p_RoPo_R_ft + c.payload.R_RP * c.payload.p_PoBar_P_ft;
  g["receptacle_ft"] = {bar.x(), bar.y(), bar.z()};
  g["port_ft"] = {c.cae.p_RoCo_R_ft.x(), c.cae.p_RoCo_R_ft.y(), c.cae.p_RoCo_R_ft.z()};
  return g;
}

std::string ReadText(const std::string& path, const char* what) {
  std::ifstream f(path);
  if (!f) throw InputError(std::string("cannot read ") + what + " at '" + path + "'");
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

LabConfig SessionConfig(const fs::path& root) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(root / "config.toml", ec)))
    return LoadConfig(DefaultConfigPath());  // a session kept without its configuration
  return session::LoadSessionConfig(root.string());
}

const char* kStyle =
    "<style>body{font-family:sans-serif;max-width:1200px;margin:1em auto;color:#222}"
    "table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #bbb;padding:3px "
    "8px;text-align:left;"
    "vertical-align:top}th{background:#eee}.ok{color:#070}.bad{color:#a00}.thumbs{display:flex;"
    "flex-wrap:wrap}"
    "figure{margin:4px}figure img{width:240px}</style>\n";

}  // namespace

std::string ScriptJson(const nlohmann::json& j) {
  const std::string s = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    // Only inside JSON strings can these stand; as \u escapes they read back
    // the same and can neither end the script ("</script>"), open a comment
    // or a script-in-comment ("<!--<script>"), nor end a line in older
    // JavaScript (U+2028, U+2029: E2 80 A8, E2 80 A9).
    if (s[i] == '<') {
      out += "\\u003c";
    } else if (s[i] == '>') {
      out += "\\u003e";
    } else if (s[i] == '&') {
      out += "\\u0026";
    } else if (s.compare(i, 3, "\xE2\x80\xA8") == 0 || s.compare(i, 3, "\xE2\x80\xA9") == 0) {
      out += s[i + 2] == '\xA8' ? "\\u2028" : "\\u2029";
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

std::string ChartsScript(const std::string& name) {
  const std::string dir = std::string(RMSLAB_SOURCE_DIR) + "/tools/report/";
  return ReadText(dir + "chart_page.js", "the charts' page helpers") + "\n" +
         ReadText(dir + name, "the page's charts");
}

std::string MakeReport(const std::string& session_dir, const std::string& chart_js_path,
                       const std::function<void(const std::string&)>& progress,
                       const std::string& out_path) {
  const fs::path root(session_dir);
  auto say = [&](const std::string& s) {
    if (progress) progress(s);
  };
  say("report: the summary");
  const nlohmann::ordered_json s = session::Summarize(session_dir);
  const nlohmann::ordered_json manifest = ReadManifest(root);
  const std::string chart_js =
      ReadText(chart_js_path, "Chart.js (Debian package libjs-chart.js; scripts/install-deps)");
  const std::string charts = ChartsScript("report_charts.js");
  const LabConfig config = SessionConfig(root);
  say("report: reading the log");
  const Traces t = ReadTraces(session_dir, config, s);
  say("report: writing");

  nlohmann::json data;
  data["title"] = s.value("session", root.filename().string());
  data["series"] = {{"t_s", t.t_s},
                    {"mode", t.mode},
                    {"attempt", t.attempt},
                    {"p_ft", t.p_ft},
                    {"payload_ft", t.payload_ft},
                    {"joints_deg", t.joints_deg},
                    {"joint_names", kJointNames},
                    {"finger", t.finger},
                    {"distance_to_goal_ft", t.goal_ft},
                    {"dock_angle_deg", t.dock_angle_deg}};
  data["series"]["inputs"] =
      t.by_hand
          ? nlohmann::json{{"names", {"x", "y", "z", "roll", "pitch", "yaw", "single joint"}},
                           {"units", {"ft/s", "ft/s", "ft/s", "deg/s", "deg/s", "deg/s", "deg/s"}},
                           {"values", t.inputs}}
          : nlohmann::json(nullptr);
  data["geometry"] = Geometry(config);
  data["events"] = t.events;
  data["attempts"] = nlohmann::json::array();
  for (const auto& a : s["attempts"])
    data["attempts"].push_back(
        {{"index", a["index"]}, {"start_s", a["start_s"]}, {"end_s", a["end_s"]}});

  std::ostringstream h;
  const std::string name = data["title"].get<std::string>();
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>rmslab session "
    << HtmlText(name) << "</title>\n"
    << kStyle << "<script>\n"
    << chart_js << "\n</script>\n</head><body>\n";
  h << "<h1>rmslab session " << HtmlText(name) << "</h1>\n";
  h << "<p>Made by <code>scripts/lab report</code> from the session folder alone: its LCM log, its "
       "processes' "
       "statistics and its manifest. One self-contained file: the plots are drawn by Chart.js, "
       "embedded.</p>\n";
  h << SessionSection(manifest, s) << TolerancesSection(config) << AttemptsSection(s)
    << MalfunctionsSection(s) << ControlSection(s) << MarksSection(root) << ScorecardSection(s);
  h << "<h2>Plots</h2>\n<div id=\"rms-charts\"></div>\n";
  h << "<script>\nwindow.RMS_REPORT = " << ScriptJson(data) << ";\n</script>\n<script>\n"
    << charts << "\n</script>\n";
  h << FramesSection(root, out_path.empty() ? root : fs::path(out_path).parent_path(),
                     config.session.frame_rate_hz);
  h << LossesSection(s) << TimingSection(s, t);
  h << "</body></html>\n";
  return h.str();
}

}  // namespace rms::report
