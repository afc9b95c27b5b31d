#include "rms/report/compare.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "rms/base/check.h"
#include "rms/base/text.h"
#include "rms/report/report.h"
#include "rms/session/manifest.h"
#include "rms/session/session_folder.h"
#include "rms/session/session_summary.h"

namespace fs = std::filesystem;

namespace rms::report {

namespace {

struct Session {
  std::string dir, name, subject, note, kind, started_utc, parent;
  std::int64_t started_us = 0;
  bool branch = false;          // scripts/lab demo --from: it began from another's instant
  bool restored_start = false;  // scripts/lab demo --restore: it began from a checkpoint
  nlohmann::ordered_json summary;
};

Session Load(const std::string& dir) {
  if (!fs::exists(fs::path(dir) / "lcmlog"))
    throw InputError(dir + ": not a session folder (no lcmlog)");
  Session s;
  s.dir = dir;
  s.name = fs::absolute(dir).lexically_normal().filename().string();
  if (s.name.empty())
    s.name = fs::absolute(dir).lexically_normal().parent_path().filename().string();
  std::error_code ec;
  if (fs::exists(fs::symlink_status(fs::path(dir) / "manifest.json", ec))) {
    try {
      const auto m =
          nlohmann::json::parse(session::ReadSessionFile(dir, "manifest.json", kMaxJsonBytes));
      s.subject = m.value("subject", "");
      s.note = m.value("note", "");
      s.kind = m.value("kind", "live");
      s.started_utc = m.value("started_utc", "");
      s.started_us = m.value("started_us", std::int64_t{0});
      s.parent = m.value("resimulation_of", "");
      // A re-simulation's began as its recorded session's did.
      const std::string began = session::BeganFrom(m);
      s.branch = began == "branch";
      s.restored_start = began == "restore";
    } catch (const nlohmann::json::parse_error& e) {
      throw InputError(dir + "/manifest.json: not valid JSON (at byte " + std::to_string(e.byte) +
                       "): not a session's manifest");
    } catch (const std::exception& e) {
      throw InputError(dir + "/manifest.json: not a session's manifest");
    }
  }
  s.summary = session::Summarize(dir);
  return s;
}

std::string Num(const nlohmann::ordered_json& v, int decimals = 3) {
  return v.is_number() ? HumanNumber(v.get<double>(), decimals) : std::string();
}

// The figures of one attempt that the page and the CSV show (the CSV's
// columns, in Csv's kColumns order).
// How an attempt began (docs/sessions.md "Compare"): "start" (a fresh
// flight from the session's own start), "reset", "restore", or "branch" (the
// first attempt of a session branched from another's instant). Only a
// fresh start is a trial for a learning curve.
std::string StartedFrom(const Session& s, const nlohmann::ordered_json& a) {
  std::string by = a.value("started_by", "start");
  if (by == "start" && s.branch) return "branch";
  if (by == "start" && s.restored_start) return "restore";
  return by;
}
bool FreshStart(const nlohmann::ordered_json& figures) {
  return figures.is_object() && figures.value("started_from", "") == "start";
}

nlohmann::ordered_json Figures(const Session& s, const nlohmann::ordered_json& a) {
  const auto& sc = a["scorecard"];
  const auto& d = a["docking"];
  std::int64_t actions = 0;
  for (const auto& [dev, n] : sc["inputs"]["actions_by_device"].items())
    actions += n.get<std::int64_t>();
  return {{"index", a["index"]},
          {"started_by", a["started_by"]},
          {"started_from", StartedFrom(s, a)},
          {"outcome", a["outcome"]},
          {"task_time_s", sc["task_time_s"]},
          {"acquisition_s", a["phase_durations_s"]["acquisition"]},
          {"extraction_s", a["phase_durations_s"]["extraction"]},
          {"maneuvering_s", a["phase_durations_s"]["maneuvering"]},
          {"docking_s", a["phase_durations_s"]["docking"]},
          {"collisions", a["collisions"]["events"]},
          {"held_s", a["holds"]["arm"]["duration_s"]},
          {"dock_distance_ft", d.is_object() ? d["distance_ft"] : nlohmann::ordered_json(nullptr)},
          {"dock_angle_deg", d.is_object() ? d["angle_deg"] : nlohmann::ordered_json(nullptr)},
          {"least_ee_payload_ft", sc["least_clearance_ft"]["end_effector_to_payload"]},
          {"least_payload_bay_ft", sc["least_clearance_ft"]["payload_to_bay"]},
          {"least_payload_cae_ft", sc["least_clearance_ft"]["payload_to_cae"]},
          {"near_d3y_s", sc["near_tolerance_s"]["d3y"]},
          {"near_tpob_s", sc["near_tolerance_s"]["tpob"]},
          {"near_dock_distance_s", sc["near_tolerance_s"]["dock_distance"]},
          {"near_dock_angle_s", sc["near_tolerance_s"]["dock_angle"]},
          {"actions", actions},
          {"reversals", sc["inputs"]["reversals"]},
          {"multi_axis_share", sc["inputs"]["multi_axis_share"]},
          {"rate_limited_s", sc["inputs"]["rate_limited_s"]},
          {"finger_closures", sc["finger_closures"]},
          {"closures_not_acquiring", sc["closures_not_acquiring"]}};
}

// The session's figures: its result attempt's (the last that docked, else the last).
nlohmann::ordered_json Best(const Session& s) {
  const auto& attempts = s.summary["attempts"];
  if (attempts.empty()) return nullptr;
  const int result = s.summary.value("result_attempt", static_cast<int>(attempts.size()));
  return Figures(
      s, attempts[static_cast<std::size_t>(std::clamp<int>(result, 1, attempts.size()) - 1)]);
}

std::string Csv(const std::vector<Session>& sessions) {
  std::ostringstream c;
  static const char* const kColumns[] = {"index",
                                         "started_by",
                                         "started_from",
                                         "outcome",
                                         "task_time_s",
                                         "acquisition_s",
                                         "extraction_s",
                                         "maneuvering_s",
                                         "docking_s",
                                         "collisions",
                                         "held_s",
                                         "dock_distance_ft",
                                         "dock_angle_deg",
                                         "least_ee_payload_ft",
                                         "least_payload_bay_ft",
                                         "least_payload_cae_ft",
                                         "near_d3y_s",
                                         "near_tpob_s",
                                         "near_dock_distance_s",
                                         "near_dock_angle_s",
                                         "actions",
                                         "reversals",
                                         "multi_axis_share",
                                         "rate_limited_s",
                                         "finger_closures",
                                         "closures_not_acquiring"};
  c << "session,subject,note,kind,started_utc,resimulation_of,attempt_count,fresh_trial";
  for (const char* k : kColumns) c << "," << (std::string(k) == "index" ? "attempt" : k);
  c << "\n";
  for (const Session& s : sessions) {
    for (const auto& a : s.summary["attempts"]) {
      const auto fig = Figures(s, a);
      c << CsvField(s.name) << "," << CsvField(s.subject) << "," << CsvField(s.note) << ","
        << s.kind << "," << s.started_utc << "," << CsvField(s.parent) << ","
        << s.summary["attempts"].size() << "," << (FreshStart(fig) ? 1 : 0);
      for (const char* k : kColumns) {
        const auto& v = fig[k];
        c << ","
          << (v.is_string()   ? CsvField(v.get<std::string>())
              : v.is_number() ? Num(v, 6)
                              : std::string());
      }
      c << "\n";
    }
  }
  return c.str();
}

std::string Table(const std::vector<Session>& sessions) {
  std::ostringstream h;
  h << "<h2>Sessions side by side</h2>\n<p>Each session's result: its last attempt that docked, or "
       "else its last "
       "attempt. Times are session "
       "time.</p>\n<table><tr><th>session</th><th>subject</th><th>note</th><th>kind</th>"
       "<th>started (UTC)</th><th>attempts</th><th>outcome</th><th>task time, "
       "s</th><th>acquisition, s</th>"
       "<th>extraction, s</th><th>manoeuvring, s</th><th>docking, s</th><th>collisions</th><th>arm "
       "held, s</th>"
       "<th>docked at, ft</th><th>docked at, deg</th><th>actions</th><th>reversals</th><th>more "
       "than one axis</th>"
       "<th>closures not acquiring</th></tr>";
  for (const Session& s : sessions) {
    const auto b = Best(s);
    h << "<tr><td>" << HtmlText(s.name) << "</td><td>" << HtmlText(s.subject) << "</td><td>"
      << HtmlText(s.note) << "</td><td>" << HtmlText(s.kind)
      << (s.parent.empty() ? "" : " of " + HtmlText(fs::path(s.parent).filename().string()))
      << "</td><td>" << HtmlText(s.started_utc) << "</td><td>" << s.summary["attempts"].size()
      << "</td>";
    if (b.is_null()) {
      h << "<td colspan=\"14\">no DCP frame in the log</td></tr>";
      continue;
    }
    const std::string from = b["started_from"].get<std::string>();
    h << "<td>" << HtmlText(b["outcome"].get<std::string>())
      << (from == "start" ? "" : " <b>(from a " + HtmlText(from) + ")</b>") << "</td>";
    for (const char* k :
         {"task_time_s", "acquisition_s", "extraction_s", "maneuvering_s", "docking_s"}) {
      h << "<td>" << (b[k].is_null() ? "-" : Num(b[k], 2)) << "</td>";
    }
    h << "<td>" << b["collisions"] << "</td><td>" << Num(b["held_s"], 2) << "</td><td>"
      << (b["dock_distance_ft"].is_null() ? "-" : Num(b["dock_distance_ft"], 4)) << "</td><td>"
      << (b["dock_angle_deg"].is_null() ? "-" : Num(b["dock_angle_deg"], 3)) << "</td><td>"
      << b["actions"] << "</td><td>" << b["reversals"] << "</td><td>"
      << HumanNumber(100 * b["multi_axis_share"].get<double>(), 1) << "%</td><td>"
      << b["closures_not_acquiring"] << "</td></tr>";
  }
  h << "</table>\n";
  return h.str();
}

std::string JoinNames(const nlohmann::ordered_json& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n.get<std::string>();
  return out;
}

}  // namespace

Comparison CompareSessions(const std::vector<std::string>& dirs, const std::string& chart_js_path,
                           bool all_trials) {
  if (dirs.empty()) throw InputError("no session to compare");
  std::vector<Session> sessions;
  for (const auto& d : dirs) sessions.push_back(Load(d));
  std::stable_sort(sessions.begin(), sessions.end(),
                   [](const Session& a, const Session& b) { return a.started_us < b.started_us; });
  nlohmann::ordered_json data;
  data["sessions"] = nlohmann::ordered_json::array();
  nlohmann::ordered_json subjects = nlohmann::ordered_json::object();
  nlohmann::ordered_json left_off = nlohmann::ordered_json::array();
  nlohmann::ordered_json no_attempt = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < sessions.size(); ++i) {
    const Session& s = sessions[i];
    nlohmann::ordered_json attempts = nlohmann::ordered_json::array();
    for (const auto& a : s.summary["attempts"]) attempts.push_back(Figures(s, a));
    data["sessions"].push_back({{"name", s.name},
                                {"subject", s.subject},
                                {"note", s.note},
                                {"started_utc", s.started_utc},
                                {"kind", s.kind},
                                {"attempts", attempts},
                                {"best", Best(s)}});
    // A learning curve is the subject's own trials: not other designs'
    // re-simulations, nor a result that began with a restore, a reset or a
    // branch (unless asked for: all_trials).
    if (s.kind == "re-simulation") continue;
    if (Best(s).is_null()) {
      no_attempt.push_back(s.name);
      continue;
    }
    if (!all_trials && !FreshStart(Best(s))) {
      left_off.push_back(s.name);
      continue;
    }
    subjects[s.subject.empty() ? "(no subject)" : s.subject].push_back(i);
  }
  data["subjects"] = subjects;
  data["left_off"] = left_off;
  data["no_attempt"] = no_attempt;
  std::ifstream js(chart_js_path);
  if (!js)
    throw InputError("cannot read Chart.js at '" + chart_js_path +
                     "' (libjs-chart.js; scripts/install-deps)");
  std::stringstream chart_js;
  chart_js << js.rdbuf();
  const std::string charts = ChartsScript("compare_charts.js");
  const std::string json = ScriptJson(data);
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>rmslab: "
    << sessions.size()
    << " sessions compared</title>\n<style>body{font-family:sans-serif;max-width:1300px;margin:1em "
       "auto;color:#222}"
       "table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #bbb;padding:3px "
       "6px;text-align:left}"
       "th{background:#eee}</style>\n<script>\n"
    << chart_js.str() << "\n</script>\n</head><body>\n<h1>" << sessions.size()
    << " sessions compared</h1>\n"
    << "<p>Made by <code>scripts/lab compare</code> from the session folders alone; the figures "
       "are each session's "
       "summary (docs/sessions.md). compare.csv beside this page has a row an attempt.</p>\n"
    << Table(sessions) << "<h2>Learning curves</h2>\n"
    << (left_off.empty()
            ? std::string()
            : "<p>Left off the learning curves (a trial is a fresh start; rms_compare "
              "--all-trials puts them on): " +
                  HtmlText(JoinNames(left_off)) +
                  ": each one's result began with a restore, a reset or a branch.</p>\n")
    << (no_attempt.empty()
            ? std::string()
            : "<p class=\"bad\">No attempt in the summary of " + HtmlText(JoinNames(no_attempt)) +
                  " (its log holds no flight: empty, cut short or damaged; rms_session summary "
                  "says what it read): not on the learning curves.</p>\n")
    << "<div id=\"rms-charts\"></div>\n<script>\nwindow.RMS_COMPARE = " << json
    << ";\n</script>\n<script>\n"
    << charts << "\n</script>\n</body></html>\n";
  return {h.str(), Csv(sessions)};
}

}  // namespace rms::report
