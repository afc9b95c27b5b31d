// rms_resim: re-simulates a session's Dynamic Collision Program on its
// recorded operator inputs (docs/sessions.md "Re-simulation").
//   rms_resim SESSION                      exit 0 only if identical, word for word
//   rms_resim SESSION --config FILE [--out DIR]   the same inputs, another design
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <spdlog/spdlog.h>

#include "rms/base/command_line.h"
#include "rms/resim/resim.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab rms_resim: run the DCP again on a session's recorded operator inputs, as fast as it "
      "can. "
      "With the session's own configuration, exits 0 only if every output is identical, word for "
      "word; "
      "with --config, writes a new session with the outcome and a comparison."};
  rms::resim::ResimOptions opt;
  bool quiet = false;
  app.add_option("session", opt.session, "Session folder")
      ->required()
      ->check(CLI::ExistingDirectory);
  app.add_option("--config", opt.config_path, "Another configuration (a different design)")
      ->check(CLI::ExistingFile);
  app.add_option("--out", opt.out_dir,
                 "With --config: the new session folder (default SESSION-resim)");
  app.add_flag("--quiet", quiet, "No progress lines (they go only to a terminal anyway)");
  bool verbose = false;
  app.add_flag("--verbose", verbose,
               "Also the DCP's own log lines (mode changes, collisions) as it re-flies");
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  // The re-flown DCP's log lines only when asked for: the result is the output.
  spdlog::set_level(verbose ? spdlog::level::info : spdlog::level::warn);
  if (!quiet && isatty(STDERR_FILENO)) {  // progress only to a person at a terminal
    opt.progress = [](double f, const std::string& line) {
      std::fprintf(stderr, "resim: %3.0f%% %s\n", 100 * f, line.c_str());
    };
  }
  try {
    const rms::resim::ResimResult r = rms::resim::Resimulate(opt);
    std::printf(
        "re-simulated %ld DCP frames in %.2f s (%.0f frames/s); %ld of %ld recorded frames "
        "identical%s\n",
        r.frames, r.seconds, r.frames / std::max(r.seconds, 1e-9), r.identical, r.compared,
        r.first_difference.empty() ? ", word for word" : "");
    std::printf(
        "timing: %.4f s in all (%.4f s reading the log, %.4f s running the DCP); the session "
        "lasted %.1f s of wall time: "
        "%.0fx real time in all, %.0fx for the DCP's run\n",
        r.seconds, r.read_seconds, r.run_seconds, r.recorded_seconds,
        r.recorded_seconds / std::max(r.seconds, 1e-9),
        r.recorded_seconds / std::max(r.run_seconds, 1e-9));
    if (r.states_checked > 0 && r.state_difference.empty()) {
      std::printf("the DCP's whole state agreed with the %ld states it logged along the way\n",
                  r.states_checked);
    }
    if (!r.note.empty()) std::printf("note: %s\n", r.note.c_str());
    if (!r.log_note.empty()) std::printf("note: %s\n", r.log_note.c_str());
    if (!r.first_difference.empty())
      std::printf("first difference: %s\n", r.first_difference.c_str());
    if (!r.out_dir.empty()) {
      std::printf("new session: %s (summary.json, comparison.md)\n", r.out_dir.c_str());
      for (const auto& s : r.comparison["explanation"])
        std::printf("  %s\n", s.get<std::string>().c_str());
      return 0;  // another design is expected to differ
    }
    return r.first_difference.empty() ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rms_resim: %s\n", e.what());
    return 2;
  }
}
