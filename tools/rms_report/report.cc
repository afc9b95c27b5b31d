#include "report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <sstream>

#include "rms/channels.h"
#include "rms/check.h"
#include "rms/collision_bits.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/message_io.h"
#include "rms/operator_input_t.hpp"
#include "sender_check.h"
#include "session_summary.h"

namespace fs = std::filesystem;

namespace rms::report {

std::string DefaultChartJsPath() { return "/usr/share/javascript/chart.js/chart.min.js"; }

namespace {

std::string Html(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '&': o += "&amp;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

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

// At most n points of (x, y), evenly picked, as Chart.js data.
nlohmann::json Series(const std::vector<std::pair<double, double>>& xy, std::size_t n = 1500) {
  nlohmann::json a = nlohmann::json::array();
  const std::size_t step = std::max<std::size_t>(1, xy.size() / n);
  for (std::size_t i = 0; i < xy.size(); i += step) a.push_back({{"x", xy[i].first}, {"y", xy[i].second}});
  if (!xy.empty() && (xy.size() - 1) % step != 0) a.push_back({{"x", xy.back().first}, {"y", xy.back().second}});
  return a;
}

struct Traces {
  std::vector<std::pair<double, double>> mode, palm_to_bar, dock_distance, dock_angle, input_to_dcp_ms,
      input_to_esg_ms, frame_interval_ms;
  std::vector<double> intervals_ms, to_dcp_ms, to_esg_ms;
};

Traces ReadTraces(const fs::path& log_path) {
  Traces t;
  lcm::LogFile log(log_path.string(), "r");
  if (!log.good()) throw InputError("cannot read the session's LCM log '" + log_path.string() + "'");
  std::int64_t t0 = -1, last_input_send = -1;
  session::SenderCheck check(log_path.parent_path().string());  // the session's own messages only
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    if (t0 < 0) t0 = ev->timestamp;
    const double ts = (ev->timestamp - t0) * 1e-6;
    const std::string base = session::BaseChannel(ev->channel);
    if (check.Ignore(base, ev->data, ev->datalen)) continue;
    if (base == channels::kOperatorInput) {
      operator_input_t m{};
      if (SafeDecode(ev->data, ev->datalen, 1024, &m) != DecodeError::kNone) continue;
      if (last_input_send >= 0) {
        const double ms = (m.send_time_us - last_input_send) / 1000.0;
        t.intervals_ms.push_back(ms);
        t.frame_interval_ms.emplace_back(ts, ms);
      }
      last_input_send = m.send_time_us;
    } else if (base == channels::kDcpTelemetry) {
      dcp_telemetry_t m{};
      if (SafeDecode(ev->data, ev->datalen, 4096, &m) != DecodeError::kNone) continue;
      t.mode.emplace_back(ts, m.mode);
      if (m.mode == 1) t.palm_to_bar.emplace_back(ts, m.palm_to_bar_ft);
      else t.dock_distance.emplace_back(ts, m.dock_distance_ft);
      if (m.mode == 3) t.dock_angle.emplace_back(ts, m.dock_angle_deg);
      const double ms = (ev->timestamp - m.input_send_time_us) / 1000.0;
      t.to_dcp_ms.push_back(ms);
      t.input_to_dcp_ms.emplace_back(ts, ms);
    } else if (base == channels::kEsgFrame) {
      esg_frame_t m{};
      if (SafeDecode(ev->data, ev->datalen, 4096, &m) != DecodeError::kNone) continue;
      const double ms = (ev->timestamp - m.input_send_time_us) / 1000.0;
      t.to_esg_ms.push_back(ms);
      t.input_to_esg_ms.emplace_back(ts, ms);
    }
  }
  return t;
}

// The session's losses, each kind apart (docs/sessions.md "Losses"): frames
// lost on a link, frames the processes refused, frames the record lost, and
// logged messages the summary left out as not the session's own.
std::string LossesSection(const nlohmann::ordered_json& s) {
  std::ostringstream h;
  h << "<h2>Losses and refusals</h2>\n<table><tr><th>what</th><th>frames or messages</th></tr>";
  auto row = [&h](const std::string& what, const nlohmann::ordered_json& n) {
    h << "<tr><td>" << Html(what) << "</td><td>" << (n.is_number() ? n.dump() : std::string("-")) << "</td></tr>";
  };
  const auto empty = nlohmann::ordered_json::object();
  auto part = [&empty](const nlohmann::ordered_json& j, const char* a, const char* b) -> const nlohmann::ordered_json& {
    if (!j.contains(a) || !j[a].is_object() || !j[a].contains(b) || !j[a][b].is_object()) return empty;
    return j[a][b];
  };
  for (const auto& [k, v] : part(s, "frames", "dropped").items()) {
    row((k.rfind("malformed", 0) == 0 ? "malformed, dropped: " : "lost on the link: ") + k, v);
  }
  for (const auto& [k, v] : part(s, "frames", "refused").items()) row("refused by the processes: " + k, v);
  for (const auto& [ch, r] : part(s, "record", "by_channel").items()) {
    row("lost by the record: " + ch + " (of " + r.value("published", nlohmann::ordered_json()).dump() + " published)",
        r.value("lost", nlohmann::ordered_json()));
  }
  for (const auto& [k, v] : part(s, "ignored", "by_reason").items()) {
    row("left out of this report (another session's, or not believed): " + k, v);
  }
  h << "</table>\n";
  return h.str();
}

std::string StatsRow(const std::string& name, const std::vector<double>& v) {
  if (v.empty()) return "<tr><td>" + Html(name) + "</td><td colspan=5>none</td></tr>";
  double mean = 0;
  for (double x : v) mean += x;
  mean /= v.size();
  return "<tr><td>" + Html(name) + "</td><td>" + std::to_string(v.size()) + "</td><td>" + F(mean, 2) + "</td><td>" +
         F(Pct(v, 0.5), 2) + "</td><td>" + F(Pct(v, 0.99), 2) + "</td><td>" + F(*std::max_element(v.begin(), v.end()), 2) +
         "</td></tr>";
}

}  // namespace

std::string MakeReport(const std::string& session_dir, const std::string& chart_js_path,
                       const std::function<void(const std::string&)>& progress) {
  const fs::path root(session_dir);
  auto say = [&](const std::string& s) {
    if (progress) progress(s);
  };
  say("report: 10% summary");
  const nlohmann::ordered_json s = session::Summarize(session_dir);
  nlohmann::json manifest = nlohmann::json::object();
  if (std::ifstream mf(root / "manifest.json"); mf) {
    try {
      manifest = nlohmann::json::parse(mf);
    } catch (const std::exception&) {
    }
  }
  std::ifstream js(chart_js_path);
  if (!js) {
    throw InputError("cannot read Chart.js at '" + chart_js_path + "' (Debian package libjs-chart.js; scripts/install-deps)");
  }
  std::stringstream chart_js;
  chart_js << js.rdbuf();
  say("report: 30% reading the log");
  const Traces t = ReadTraces(root / "lcmlog");
  say("report: 70% writing");

  std::ostringstream h;
  const std::string name = s.value("session", root.filename().string());
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>rmslab session " << Html(name)
    << "</title>\n<style>body{font-family:sans-serif;max-width:1100px;margin:1em auto;color:#222}"
       "table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #bbb;padding:3px 8px;text-align:left}"
       "th{background:#eee}.ok{color:#070}.bad{color:#a00}.chart{height:300px;margin:1em 0}</style>\n"
       "<script>\n"
    << chart_js.str() << "\n</script>\n</head><body>\n";
  h << "<h1>rmslab session " << Html(name) << "</h1>\n";
  h << "<p>Built by <code>scripts/lab report</code> from the session folder alone: its LCM log, its processes' "
       "statistics and its manifest. Self-contained: the plots are drawn by Chart.js, embedded.</p>\n";

  // Outcome.
  const bool docked = s.value("docked", false);
  h << "<h2>Outcome</h2>\n<table>";
  h << "<tr><th>pilot</th><td>" << Html(s.value("pilot", std::string("?"))) << "</td></tr>";
  h << "<tr><th>final mode</th><td>" << s.value("final_mode", 0) << "</td></tr>";
  h << "<tr><th>acquired</th><td>" << (s.value("acquired", false) ? "yes" : "no") << "</td></tr>";
  h << "<tr><th>docked</th><td class=\"" << (docked ? "ok" : "bad") << "\">" << (docked ? "yes" : "no") << "</td></tr>";
  if (s.contains("docking") && s["docking"].is_object()) {
    const auto& d = s["docking"];
    h << "<tr><th>docking miss distance</th><td>" << F(d["distance_ft"].get<double>(), 4)
      << " ft (the probe's tip to the port's centre)</td></tr>";
    h << "<tr><th>docking angle</th><td>" << F(d["angle_deg"].get<double>(), 4) << " deg (probe axis to port axis)</td></tr>";
    if (d.contains("within_tolerance")) {
      h << "<tr><th>within the report's tolerances</th><td>" << (d["within_tolerance"].get<bool>() ? "yes" : "no")
        << "</td></tr>";
    }
  }
  h << "<tr><th>duration</th><td>" << F(s.value("duration_s", 0.0), 1) << " s of wall time</td></tr>";
  h << "</table>\n";

  // Phases.
  h << "<h2>Phase durations</h2>\n<p>Session time (frames over the frame rate), of the last attempt.</p>\n<table><tr>"
       "<th>phase</th><th>s</th></tr>";
  if (s.contains("phase_durations_s")) {
    for (const auto& [phase, v] : s["phase_durations_s"].items()) {
      h << "<tr><td>" << Html(phase) << "</td><td>" << (v.is_number() ? F(v.get<double>(), 2) : std::string("not reached"))
        << "</td></tr>";
    }
  }
  h << "</table>\n";

  // Collisions.
  h << "<h2>Collisions</h2>\n<table><tr><th>kind</th><th>events</th><th>frames</th><th>s</th></tr>";
  long total = 0;
  if (s.contains("collisions_by_kind")) {
    for (const auto& [kind, c] : s["collisions_by_kind"].items()) {
      if (c["events"].get<double>() == 0) continue;
      total += static_cast<long>(c["events"].get<double>());
      h << "<tr><td>" << Html(kind) << "</td><td>" << c["events"] << "</td><td>" << c["frames"] << "</td><td>"
        << F(c["duration_s"].get<double>(), 2) << "</td></tr>";
    }
  }
  if (total == 0) h << "<tr><td colspan=4>none</td></tr>";
  h << "</table>\n";
  if (s.contains("collisions") && !s["collisions"].empty()) {
    h << "<table><tr><th>kind</th><th>start, s</th><th>duration, s</th><th>frames</th></tr>";
    for (const auto& c : s["collisions"]) {
      h << "<tr><td>" << Html(c["kind"].get<std::string>()) << "</td><td>" << F(c["start_s"].get<double>(), 2)
        << "</td><td>" << F(c["duration_s"].get<double>(), 2) << "</td><td>" << c["frames"] << "</td></tr>";
    }
    h << "</table>\n";
  }
  h << "<p>Frames in which the DCP held the slave arm: " << s.value("held_frames", 0) << ".</p>\n";

  h << LossesSection(s);

  // Timing.
  h << "<h2>Frame times and latency</h2>\n<table><tr><th>what</th><th>n</th><th>mean, ms</th><th>p50, ms</th>"
       "<th>p99, ms</th><th>max, ms</th></tr>";
  h << StatsRow("operator frame interval", t.intervals_ms);
  h << StatsRow("operator input to DCP output (logged)", t.to_dcp_ms);
  h << StatsRow("operator input to ESG frame (logged)", t.to_esg_ms);
  h << "</table>\n<table><tr><th>link (process statistics)</th><th>n</th><th>p50, ms</th><th>p99, ms</th><th>max, ms</th></tr>";
  if (s.contains("latency")) {
    for (const auto& [link, l] : s["latency"].items()) {
      h << "<tr><td>" << Html(link) << "</td><td>" << l["count"] << "</td><td>" << F(l["p50_ms"].get<double>(), 2)
        << "</td><td>" << F(l["p99_ms"].get<double>(), 2) << "</td><td>" << F(l["max_ms"].get<double>(), 2) << "</td></tr>";
    }
  }
  h << "</table>\n";
  if (s.contains("timing")) h << "<pre>" << Html(s["timing"].dump(2)) << "</pre>\n";

  // Plots.
  h << "<h2>Plots</h2>\n";
  const char* charts[] = {"mode", "goal", "latency", "frames"};
  const char* titles[] = {"Mode timeline", "Distance to the goal", "Latency", "Frame intervals"};
  for (int i = 0; i < 4; ++i) {
    h << "<h3>" << titles[i] << "</h3><div class=\"chart\"><canvas id=\"chart-" << charts[i] << "\"></canvas></div>\n";
  }
  nlohmann::json data;
  data["mode"] = Series(t.mode);
  data["palm_to_bar"] = Series(t.palm_to_bar);
  data["dock_distance"] = Series(t.dock_distance);
  data["dock_angle"] = Series(t.dock_angle);
  data["to_dcp"] = Series(t.input_to_dcp_ms);
  data["to_esg"] = Series(t.input_to_esg_ms);
  data["interval"] = Series(t.frame_interval_ms);
  h << "<script>\nconst D = " << data.dump() << ";\n" << R"JS(
const made = [];
function chart(id, datasets, ytitle, opts) {
  const y = Object.assign({ title: { display: true, text: ytitle } }, (opts || {}).y || {});
  const o = { parsing: false, animation: false, responsive: true, maintainAspectRatio: false,
    elements: { point: { radius: 0 } },
    scales: { x: { type: 'linear', title: { display: true, text: 'time, s (from the log start)' } }, y: y } };
  made.push(new Chart(document.getElementById(id), { type: 'line', data: { datasets: datasets }, options: o }));
}
try {
  chart('chart-mode', [{ label: 'mode (1 acquisition, 2 extraction, 3 manoeuvring and docking)', data: D.mode,
                         stepped: true, borderColor: '#1f5fa8' }], 'mode', { y: { min: 0.5, max: 3.5, ticks: { stepSize: 1 } } });
  chart('chart-goal', [{ label: 'Mode 1: palm to the BAR, ft', data: D.palm_to_bar, borderColor: '#a05a00' },
                       { label: 'Modes 2-3: probe tip to the port, ft', data: D.dock_distance, borderColor: '#1f8a3a' }],
        'distance, ft');
  chart('chart-latency', [{ label: 'operator input to DCP output, ms', data: D.to_dcp, borderColor: '#7a3fa0' },
                          { label: 'operator input to ESG frame, ms', data: D.to_esg, borderColor: '#c03030' }], 'ms');
  chart('chart-frames', [{ label: 'operator frame interval, ms', data: D.interval, borderColor: '#333' }], 'ms');
  document.body.dataset.chartsRendered = String(made.length);
} catch (e) {
  document.body.dataset.chartsError = String(e);
}
</script>
)JS";
  h << "<h2>Session</h2>\n<pre>" << Html(manifest.dump(2)) << "</pre>\n</body></html>\n";
  say("report: 100%");
  return h.str();
}

}  // namespace rms::report
