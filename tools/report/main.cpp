// rms_report: a session's report as one self-contained HTML file.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <fstream>
#include <functional>
#include <iostream>

#include "rms/base/command_line.h"
#include "rms/base/text.h"
#include "rms/report/report.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab rms_report: one self-contained HTML report of a session (phases, collisions, "
      "docking, "
      "timing, plots)"};
  std::string session, out, chart_js = rms::report::DefaultChartJsPath();
  app.add_option("session", session, "Session folder")->required()->check(CLI::ExistingDirectory);
  app.add_option("--out", out, "The HTML file (default SESSION/report.html)");
  app.add_option("--chart-js", chart_js, "Chart.js to embed")->capture_default_str();
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  try {
    if (out.empty()) out = session + "/report.html";
    std::function<void(const std::string&)> progress;  // only to a person at a terminal
    if (isatty(STDERR_FILENO))
      progress = [](const std::string& line) { std::cerr << rms::TerminalText(line) << "\n"; };
    const std::string html = rms::report::MakeReport(session, chart_js, progress, out);
    rms::WriteWholeFile(out, html, rms::LinksForOutput(out, session));
    std::cout << rms::TerminalText(out) << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "rms_report: " << rms::TerminalText(e.what()) << "\n";
    return 2;
  }
}
