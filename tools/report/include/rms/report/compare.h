#pragma once
// Sessions compared (docs/sessions.md "Compare"): the scorecard of each
// session side by side, and the learning curve of each subject across the
// sessions it flew, as one self-contained HTML page (compare.html, plots by
// Chart.js) and one CSV (compare.csv: a row an attempt). Re-simulations
// under another design (scripts/lab resim --config) are sessions of their
// own, listed apart from the subject's learning curve.
#include <string>
#include <vector>

namespace rms::report {

struct Comparison {
  std::string html, csv;
};

// Throws rms::InputError naming a folder that is no session. A learning
// curve holds a subject's fresh trials: a session whose result began with a
// restore, a reset or a branch is flagged and left off it, unless all_trials.
Comparison CompareSessions(const std::vector<std::string>& session_dirs,
                           const std::string& chart_js_path, bool all_trials = false);

}  // namespace rms::report
