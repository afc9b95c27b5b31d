// rms_compare: sessions compared, as one HTML page and one CSV
// (docs/sessions.md "Compare").
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>

#include "rms/base/check.h"
#include "rms/base/command_line.h"
#include "rms/base/text.h"
#include "rms/report/compare.h"
#include "rms/report/report.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab rms_compare: the scorecards of several sessions side by side and each subject's "
      "learning "
      "curve, as compare.html and compare.csv"};
  std::vector<std::string> sessions;
  std::string out = "compare", chart_js = rms::report::DefaultChartJsPath();
  app.add_option("sessions", sessions, "Session folders")
      ->required()
      ->check(CLI::ExistingDirectory);
  app.add_option("--out", out, "The folder for compare.html and compare.csv")
      ->capture_default_str();
  app.add_option("--chart-js", chart_js, "Chart.js to embed")->capture_default_str();
  bool all_trials = false;
  app.add_flag("--all-trials", all_trials,
               "Put on the learning curves too the sessions whose result began with a restore, "
               "a reset or a branch (flagged either way)");
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  try {
    const rms::report::Comparison c = rms::report::CompareSessions(sessions, chart_js, all_trials);
    std::filesystem::create_directories(out);
    rms::WriteWholeFile(out + "/compare.html", c.html);
    rms::WriteWholeFile(out + "/compare.csv", c.csv);
    std::cout << rms::TerminalText(out + "/compare.html\n" + out + "/compare.csv\n");
    return 0;
  } catch (const rms::InputError& e) {  // a folder that is no session, a bad manifest
    std::cerr << "rms_compare: " << rms::TerminalText(e.what()) << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "rms_compare: " << rms::TerminalText(e.what()) << "\n";
    return 1;
  }
}
