// rms_resim: re-simulates a session's Dynamic Collision Program on its
// recorded operator inputs (docs/sessions.md "Re-simulation").
//   rms_resim SESSION                      exit 0 only if identical, word for word
//   rms_resim SESSION --config FILE [--out DIR]   the same inputs, another design
//   rms_resim SESSION --set KEY=VALUE... [--discard] [--result-json]   a sweep's cell
//   rms_resim --cells FILE|- [--jobs N]   a sweep's batch of cells, a result line each
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "rms/base/check.h"
#include "rms/base/command_line.h"
#include "rms/base/config.h"
#include "rms/base/text.h"
#include "rms/base/version.h"
#include "rms/resim/resim.h"
#include "rms/session/session_folder.h"
#include "rms/session/session_summary.h"

namespace {

// What the re-simulation found, as lines for a person; the exit code: 0
// identical (or another design, expected to differ), 1 a difference.
int Report(const rms::resim::ResimResult& r, bool other_design) {
  std::printf(
      "re-simulated %ld DCP frames in %.2f s (%.0f frames/s); %ld of %ld recorded frames "
      "identical%s\n",
      r.frames, r.seconds, r.frames / std::max(r.seconds, 1e-9), r.identical, r.compared,
      r.first_difference.empty() ? ", word for word" : "");
  if (!r.branch_note.empty()) std::printf("%s\n", r.branch_note.c_str());
  std::printf(
      "timing: %.4f s in all (%.4f s reading the log%s, %.4f s running the DCP%s); the session "
      "lasted %.1f s of wall time: "
      "%.0fx real time in all, %.0fx for the DCP's run\n",
      r.seconds, r.read_seconds, r.read_in_two ? " in two parts at once" : "", r.run_seconds,
      r.in_halves ? " in two halves at once" : "", r.recorded_seconds,
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
  if (!r.out_dir.empty())
    std::printf("new session: %s (summary.json, comparison.md)\n", r.out_dir.c_str());
  if (other_design) {
    for (const auto& s : r.comparison["explanation"])
      std::printf("  %s\n", s.get<std::string>().c_str());
    return 0;  // another design is expected to differ
  }
  return r.first_difference.empty() ? 0 : 1;
}

// The session's own design re-simulated, as one JSON object
// (--verdict-json; docs/sessions.md "Does it re-simulate"): what a session's
// summary says of it. `why` when it could not be re-simulated at all.
nlohmann::ordered_json Verdict(const rms::resim::ResimResult* r, const std::string& why,
                               const std::string& session) {
  nlohmann::ordered_json v;
  v["format"] = "rmslab-resimulation-1";
  // The log it judged, by its SHA-256: a summary of a log that changed
  // since does not show this verdict as the log's (docs/sessions.md "Does
  // it re-simulate").
  try {
    v["log_sha256"] = rms::session::SessionFileSha256(session, "lcmlog");
  } catch (const std::exception&) {
    v["log_sha256"] = nullptr;
  }
  if (!r) {
    v["verdict"] = "cannot be re-simulated";
    v["exact"] = false;
    v["why"] = why;
    v["exit_code"] = 2;
    return v;
  }
  const bool same = r->first_difference.empty() && r->identical == r->compared;
  v["verdict"] = same ? "identical" : "differs";
  // Exact: every frame the DCP made checked (none lost from the log, none
  // left unchecked after such a loss, none before its first state, and the
  // log not cut short or damaged: what it held past that was not checked).
  v["exact"] =
      same && r->unchecked.empty() && r->skipped == 0 && r->log_note.empty() && r->filled_in == 0;
  v["frames_compared"] = r->compared;
  v["frames_identical"] = r->identical;
  v["frames_unchecked"] = r->unchecked_frames;
  v["frames_skipped_at_start"] = r->skipped;
  v["frames_filled_in"] = r->filled_in;
  v["unchecked"] = r->unchecked;
  v["first_difference"] = r->first_difference.empty() ? nlohmann::ordered_json(nullptr)
                                                      : nlohmann::ordered_json(r->first_difference);
  v["states_checked"] = r->states_checked;
  v["note"] = r->note;
  v["log_note"] = r->log_note;
  v["seconds"] = r->seconds;
  v["exit_code"] = same ? 0 : 1;
  return v;
}

// Another design's new session says whether it re-simulates, as every
// session does (docs/sessions.md "Does it re-simulate"): re-simulated
// itself, its resimulation.json written and its summary made again with it.
std::string CheckNewSession(const std::string& dir, int threads) {
  rms::resim::ResimOptions own;
  own.session = dir;
  own.threads = threads;
  nlohmann::ordered_json v;
  try {
    const rms::resim::ResimResult r = rms::resim::Resimulate(own);
    v = Verdict(&r, "", dir);
  } catch (const std::exception& e) {
    v = Verdict(nullptr, e.what(), dir);
  }
  const std::filesystem::path root(dir);
  rms::WriteWholeFile((root / "resimulation.json").string(), v.dump(2) + "\n");
  rms::WriteWholeFile((root / "summary.json").string(),
                      rms::session::Summarize(dir).dump(2) + "\n");
  return v.value("verdict", "?");
}

// A usage error, as rms::ParseCommandLine reports one (exit 2).
int Usage(const char* what) {
  std::fprintf(stderr, "%s\nRun with --help for more information.\n", what);
  return rms::kUsageExitCode;
}

// The command line's values.
struct Args {
  rms::resim::ResimOptions opt;
  bool quiet = false, result_json = false, check_only = false, verbose = false;
  std::vector<std::string> sets;
  std::string cells, verdict_json, checkpoint_out, threads = "auto";
  int jobs = 1;
};

void AddOptions(CLI::App& app, Args& a) {
  app.set_version_flag("--version", rms::VersionString());
  app.add_option("session", a.opt.session, "Session folder (required but with --cells)")
      ->check(CLI::ExistingDirectory);
  app.add_option("--cells", a.cells,
                 "A sweep's batch: each line of FILE ('-': standard input) "
                 "INDEX<TAB>KEY<TAB>SESSION<TAB>KEY=VALUE..., re-simulated as --set ... "
                 "--discard --result-json would; a line 'INDEX<TAB>JSON' each on stdout")
      ->type_name("FILE");
  app.add_option("--jobs", a.jobs,
                 "With --cells: cells at once, each on its own thread (a sweep on this machine "
                 "gives its cores)")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  app.add_option("--config", a.opt.config_path, "Another configuration (a different design)")
      ->check(CLI::ExistingFile);
  app.add_option("--out", a.opt.out_dir,
                 "With --config: the new session folder (default SESSION-resim)");
  app.add_option("--set", a.sets,
                 "KEY=VALUE: a configuration key set over the session's config (or --config's), "
                 "e.g. dcp.tpob_ft=0.4; repeatable (another design)")
      ->type_name("KEY=VALUE");
  app.add_flag("--discard", a.opt.discard,
               "Another design: no session written, its result made in memory (what remains is "
               "the output; no --out)");
  app.add_flag("--result-json", a.result_json,
               "Another design: print only its result, one JSON line on stdout (a sweep's cell: "
               "outcome, recorded outcome, scorecard changes, first divergence)");
  app.add_flag("--check", a.check_only,
               "Only check the design (the configuration with its --set keys) and exit: 0 if "
               "it is valid");
  app.add_option("--verdict-json", a.verdict_json,
                 "The session's own design: also write what it came to here, as JSON, whatever "
                 "it came to (identical, differs, cannot be re-simulated: docs/sessions.md \"Does "
                 "it re-simulate\"); scripts/lab writes SESSION/resimulation.json so")
      ->type_name("FILE");
  app.add_option(
         "--until", a.opt.until_frame,
         "Only up to this DCP frame, word for word (the session's own design); with "
         "--checkpoint-out, the DCP's state there: a branch point (scripts/lab demo --from)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--checkpoint-out", a.checkpoint_out,
                 "With --until: write the DCP's state after that frame here, as a checkpoint "
                 "(only when the frames up to it are identical)");
  app.add_option("--threads", a.threads,
                 "The session's own design: its log read and its DCP run in two shares at once, "
                 "one on another core: auto (when that core comes in time), 1 (one thread) or 2 "
                 "(always two); the same result each way (docs/sessions.md \"Re-simulation\"); "
                 "--verbose runs on one")
      ->check(CLI::IsMember({"auto", "1", "2"}))
      ->capture_default_str();
  app.add_flag("--quiet", a.quiet, "No progress lines (they go only to a terminal anyway)");
  app.add_flag("--verbose", a.verbose,
               "Also the DCP's own log lines (mode changes, collisions) as it re-flies");
}

// --cells: a sweep's batch, each cell's result a line.
int RunCellBatch(const CLI::App& app, const Args& a) {
  const rms::resim::ResimOptions& opt = a.opt;
  if (!opt.session.empty() || !a.sets.empty() || !opt.config_path.empty() || a.check_only ||
      !opt.out_dir.empty() || opt.discard || a.result_json || opt.until_frame >= 0 ||
      !a.checkpoint_out.empty() || app.count("--threads") > 0)
    return Usage(
        "--cells: the sessions and keys are in its lines, each cell's result is its line "
        "(no SESSION, --set, --config, --out, --discard, --result-json, --check, --until, "
        "--checkpoint-out or --threads beside it)");
  if (a.cells.empty()) return Usage("--cells: a FILE, or - for standard input");
  spdlog::set_default_logger(spdlog::stderr_color_mt("rms_resim"));
  if (a.cells == "-") return rms::resim::RunCells(std::cin, a.jobs);
  std::ifstream in(a.cells);
  if (!in || std::filesystem::is_directory(a.cells)) {
    std::fprintf(stderr, "rms_resim: --cells %s: cannot be read\n", a.cells.c_str());
    return 2;
  }
  return rms::resim::RunCells(in, a.jobs);
}

// The options that go together with others, refused with the reason.
void CheckCombinations(const Args& a) {
  const bool other = rms::resim::OtherDesign(a.opt);
  if (a.result_json && !other)
    throw rms::InputError("--result-json needs another design (--config or --set)");
  if (a.opt.discard && !other)
    throw rms::InputError("--discard needs another design (--config or --set)");
  if (a.opt.discard && !a.opt.out_dir.empty())
    throw rms::InputError("--discard writes no session: --out has no place beside it");
  if (!a.checkpoint_out.empty() && a.opt.until_frame < 0)
    throw rms::InputError("--checkpoint-out needs --until FRAME");
  if (!a.verdict_json.empty() && (other || a.opt.until_frame >= 0))
    throw rms::InputError(
        "--verdict-json is for the session's own design, to its end (no "
        "--config, --set or --until)");
}

// One session re-simulated: what it came to, written where asked; the exit code.
int RunSession(const Args& a) {
  const rms::resim::ResimOptions& opt = a.opt;
  const rms::resim::ResimResult r = rms::resim::Resimulate(opt);
  const bool other = rms::resim::OtherDesign(opt);
  const std::string new_session_verdict =
      other && !r.out_dir.empty() ? CheckNewSession(r.out_dir, opt.threads) : "";
  if (!a.verdict_json.empty())
    rms::WriteWholeFile(a.verdict_json, Verdict(&r, "", opt.session).dump(2) + "\n",
                        rms::LinksForOutput(a.verdict_json, opt.session));
  if (!a.checkpoint_out.empty()) {
    if (!r.first_difference.empty()) {
      throw rms::InputError("the session does not re-simulate word for word up to DCP frame " +
                            std::to_string(opt.until_frame) + " (" + r.first_difference +
                            "): a branch from there could not reproduce it; no checkpoint written");
    }
    rms::WriteWholeFile(a.checkpoint_out, r.checkpoint_text,
                        rms::LinksForOutput(a.checkpoint_out, opt.session));
  }
  if (a.result_json) {
    std::printf("%s\n", rms::resim::JsonLine(r.cell).c_str());
    return 0;
  }
  const int rc = Report(r, other);
  if (!new_session_verdict.empty())
    std::printf("the new session re-simulates: %s\n", new_session_verdict.c_str());
  return rc;
}

// A session that could not be re-simulated: said, and written where asked.
int Refused(const Args& a, const std::exception& e) {
  const rms::resim::ResimOptions& opt = a.opt;
  std::fprintf(stderr, "rms_resim: %s\n", rms::TerminalText(e.what()).c_str());
  if (!a.verdict_json.empty() && !rms::resim::OtherDesign(opt) && opt.until_frame < 0) {
    try {
      rms::WriteWholeFile(a.verdict_json, Verdict(nullptr, e.what(), opt.session).dump(2) + "\n",
                          rms::LinksForOutput(a.verdict_json, opt.session));
    } catch (const std::exception& w) {
      std::fprintf(stderr, "rms_resim: %s\n", w.what());
    }
  }
  // A sweep's cell says why it has no result, on its one line.
  if (a.result_json)
    std::printf("%s\n", rms::resim::JsonLine(nlohmann::json{{"error", e.what()}}).c_str());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab rms_resim: run the DCP again on a session's recorded operator inputs, as fast as it "
      "can. With the session's own configuration, exits 0 only if every output is identical, "
      "word for word; with --config, writes a new session with the outcome and a comparison."};
  Args a;
  AddOptions(app, a);
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  rms::resim::ResimOptions& opt = a.opt;
  opt.threads = a.threads == "auto" ? 0 : std::stoi(a.threads);
  // The DCP's own lines in the order one run makes them (two halves would
  // interleave theirs, and a half not kept would have said its own).
  if (a.verbose) opt.threads = 1;
  // The re-flown DCP's log lines only when asked for: the result is the output.
  spdlog::set_level(a.verbose ? spdlog::level::info : spdlog::level::warn);
  // With --result-json stdout is the result alone: log lines go to stderr.
  if (a.result_json) spdlog::set_default_logger(spdlog::stderr_color_mt("rms_resim"));
  if (!a.quiet && isatty(STDERR_FILENO)) {  // progress only to a person at a terminal
    opt.progress = [](double f, const std::string& line) {
      std::fprintf(stderr, "resim: %3.0f%% %s\n", 100 * f, line.c_str());
    };
  }
  if (app.count("--cells") > 0) return RunCellBatch(app, a);
  if (opt.session.empty()) return Usage("session is required (or --cells)");
  if (app.count("--jobs") > 0) return Usage("--jobs: only with --cells (cells at once)");
  try {
    for (const std::string& s : a.sets) opt.settings.push_back(rms::ParseConfigSetting(s));
    if (a.check_only) {
      rms::ParseConfig(rms::resim::EffectiveConfigText(opt), rms::resim::ConfigSource(opt));
      return 0;
    }
    CheckCombinations(a);
    return RunSession(a);
  } catch (const std::exception& e) {
    return Refused(a, e);
  }
}
