#pragma once
// The session report (docs/sessions.md "Report"): one self-contained HTML
// file -- outcome, phase durations, collisions by kind with their times,
// the docking miss distance and angle, frame-time and latency statistics,
// and plots (mode timeline, distance to the goal, latency, frame intervals)
// drawn in the browser by Chart.js (Debian's libjs-chart.js), embedded.
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

namespace rms::report {

std::string DefaultChartJsPath();
// Throws rms::InputError for an unreadable session or a missing Chart.js.
// out_path: where the report goes (links to the session's video are made
// relative to it).
std::string MakeReport(const std::string& session_dir, const std::string& chart_js_path,
                       const std::function<void(const std::string&)>& progress = {},
                       const std::string& out_path = "");
// JSON to embed in a <script> (the report's and the comparison's data):
// < > & U+2028 U+2029 written as \u escapes, so no string in it can end the
// script, open a comment in it, or end a line.
std::string ScriptJson(const nlohmann::json& j);
// A page's chart script from the source tree (report_charts.js,
// compare_charts.js), after the helpers they share (chart_page.js): the text
// to embed in one <script>. Throws rms::InputError when one cannot be read.
std::string ChartsScript(const std::string& name);

}  // namespace rms::report
