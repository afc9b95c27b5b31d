// rms_fly: one design flown from the start by N virtual subjects -- the
// autopilot, or the scripted operator at an offline station, each run with
// a reaction time, a rate gain and a noise seed drawn from one seed -- in
// closed loop with the real DCP, no network; a JSON line a run on stdout
// (docs/studies.md "Designs judged by flying them").
//   rms_fly --config FILE [--set KEY=VALUE]... [--subject autopilot|scripted] [--runs N] ...
//   rms_fly --cells FILE|- [--jobs N]   a sweep's cells (scripts/sweep-cell --fly-cells): lines
//       "INDEX<TAB>KEY<TAB>ARG<TAB>ARG...", each ARG one of the options above, KEY the
//       SHA-256 of the ARGs joined by tabs; a line "INDEX<TAB>{"flights": [...]}" each (or
//       {"error": "..."}); exit 0, 1 when a cell had an error, 2 when a line was no cell
//   rms_fly --software-id   what a sweep's cells name in --software: the version and the
//       binary's SHA-256
#include <sodium.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <spdlog/spdlog.h>
#include <sstream>
#include <thread>

#include "rms/base/check.h"
#include "rms/base/command_line.h"
#include "rms/base/config.h"
#include "rms/base/config_settings.h"
#include "rms/base/folder_file.h"
#include "rms/base/text.h"
#include "rms/base/version.h"
#include "rms/sim/virtual_subjects.h"

namespace {

std::string Sha256Hex(const void* data, std::size_t size) {
  RMS_CHECK(sodium_init() >= 0);
  unsigned char digest[crypto_hash_sha256_BYTES];
  crypto_hash_sha256(digest, static_cast<const unsigned char*>(data), size);
  char hex[2 * crypto_hash_sha256_BYTES + 1];
  sodium_bin2hex(hex, sizeof hex, digest, sizeof digest);
  return hex;
}

// The version and this binary's SHA-256: a tree rebuilt with changes not
// committed has the same version, not the same binary (docs/studies.md
// "Where it flies": a cell's result is cached under it).
std::string SoftwareId() {
  static const std::string id = [] {
    const std::string self =
        rms::ReadRegularFile("/proc/self/exe", "this program", 1ULL << 30, rms::Links::kFollow);
    return rms::VersionString() + " " + Sha256Hex(self.data(), self.size());
  }();
  return id;
}

nlohmann::json RunJson(const rms::sim::FlightRun& f, const rms::LabConfig& config) {
  const rms::sim::ClosedLoopResult& r = f.result;
  const double rate = config.session.frame_rate_hz;
  const auto at = [&](int frame) -> nlohmann::json {
    return frame > 0 ? nlohmann::json(frame / rate) : nlohmann::json(nullptr);
  };
  nlohmann::json j = {{"subject", rms::sim::SubjectKindName(f.subject)},
                      {"run", f.run},
                      {"seed", f.seed},
                      {"reaction_s", f.reaction_s},
                      {"latency_frames", f.latency_frames},
                      {"rate_gain", f.rate_gain},
                      {"docked", r.docked},
                      {"failure", r.failure},
                      {"time_s", r.time_s},
                      {"acquired_s", at(r.modes_entered[2])},
                      {"cleared_s", at(r.modes_entered[3])},
                      {"docked_s", at(r.docked_frame)},
                      {"collision_events", r.collision_events},
                      {"held_frames", r.held_frames},
                      {"key_actions", f.key_actions >= 0 ? nlohmann::json(f.key_actions)
                                                         : nlohmann::json(nullptr)}};
  if (r.docked) {
    j["dock_distance_ft"] = r.dock_distance_ft;
    j["dock_angle_deg"] = r.dock_angle_deg;
    j["distance_margin_ft"] = config.dcp.dock_distance_ft - r.dock_distance_ft;
    j["angle_margin_deg"] = config.dcp.dock_angle_deg - r.dock_angle_deg;
  }
  return j;
}

std::pair<double, double> Range(const std::string& text, const char* what) {
  const auto comma = text.find(',');
  if (comma != std::string::npos && text.find(',', comma + 1) != std::string::npos)
    throw rms::InputError(std::string(what) + " '" + text + "': LO,HI (two numbers) or one number");
  try {
    if (comma == std::string::npos) {
      const double v = std::stod(text);
      return {v, v};
    }
    return {std::stod(text.substr(0, comma)), std::stod(text.substr(comma + 1))};
  } catch (const std::exception&) {
    throw rms::InputError(std::string(what) + " '" + text + "': LO,HI (two numbers) or one number");
  }
}

// One design's flights, as the options give them.
struct FlyArgs {
  std::string config_path, reaction = "0.2,0.5", gain = "0.8,1.2", subject = "autopilot";
  std::vector<std::string> sets;
  int runs = 20, first_run = 0;
  std::uint64_t seed = 1;
  double tremor = 0.01, reaction_sd = 0.05, max_s = 300;
  std::string config_sha256, software;  // a sweep's cell: what it was made with, checked
};

void AddFlyOptions(CLI::App& app, FlyArgs& a) {
  app.add_option("--config", a.config_path, "The configuration (docs/config.md)");
  app.add_option("--set", a.sets, "KEY=VALUE: a design's key over it, as rms_resim --set");
  app.add_option("--subject", a.subject,
                 "Who flies: autopilot, or scripted (the scripted operator: the status screen and "
                 "the keys alone, at an offline station)")
      ->capture_default_str();
  app.add_option("--runs", a.runs, "Flights")->capture_default_str()->check(CLI::Range(1, 100000));
  app.add_option("--first-run", a.first_run,
                 "The first run's number: runs FIRST.. FIRST+N-1, each drawn as in a sweep of them "
                 "all (a sweep's cell)")
      ->capture_default_str()
      ->check(CLI::Range(0, 10000000));
  app.add_option("--seed", a.seed, "The seed every run's draws come from")->capture_default_str();
  app.add_option("--reaction-s", a.reaction, "Reaction time, s: LO,HI (uniform) or one value")
      ->capture_default_str();
  app.add_option("--rate-gain", a.gain,
                 "The autopilot: its rates times this; the scripted operator: its timed taps held "
                 "this times the time they need. LO,HI (uniform) or one value")
      ->capture_default_str();
  app.add_option("--tremor-deg", a.tremor,
                 "The autopilot's joint command tremor, deg: its standard deviation (a "
                 "Gauss-Markov wander, 1 s correlation time)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 5.0));
  app.add_option("--reaction-sd-s", a.reaction_sd,
                 "The scripted operator's: each reaction drawn about the run's, this standard "
                 "deviation, s")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 2.0));
  app.add_option("--max-s", a.max_s, "Session time a flight may take, s")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 3600.0));
  app.add_option("--config-sha256", a.config_sha256,
                 "Refuse to fly unless the configuration's SHA-256 is this (a sweep's cell)");
  app.add_option("--software", a.software,
                 "Refuse to fly unless this is the program's --software-id (a sweep's cell)");
}

// The flights, a JSON object a run. Throws rms::InputError on a bad option
// or design.
std::vector<nlohmann::json> Fly(const FlyArgs& a, int jobs) {
  if (a.config_path.empty()) throw rms::InputError("--config is required");
  std::vector<rms::ConfigSetting> settings;
  for (const std::string& s : a.sets) settings.push_back(rms::ParseConfigSetting(s));
  if (!a.software.empty() && a.software != SoftwareId())
    throw rms::InputError("this rms_fly (" + SoftwareId() +
                          ") is not the one the sweep was made with (" + a.software +
                          "): build the same tree, or make the sweep again");
  const std::string file = rms::ReadRegularFile(a.config_path, "configuration",
                                                rms::kMaxConfigBytes, rms::Links::kFollow);
  if (!a.config_sha256.empty() && Sha256Hex(file.data(), file.size()) != a.config_sha256)
    throw rms::InputError("the configuration " + a.config_path +
                          " changed since the sweep was made (its SHA-256 is not the sweep's)");
  const std::string text = rms::ApplyConfigSettings(file, a.config_path, settings);
  const rms::LabConfig config =
      rms::ParseConfig(text, settings.empty() ? a.config_path : a.config_path + " with --set");
  rms::sim::Dispersions d;
  std::tie(d.reaction_lo_s, d.reaction_hi_s) = Range(a.reaction, "--reaction-s");
  std::tie(d.gain_lo, d.gain_hi) = Range(a.gain, "--rate-gain");
  d.tremor_deg = a.tremor;
  d.reaction_sd_s = a.reaction_sd;
  if (!std::isfinite(a.tremor) || !std::isfinite(a.max_s) || !std::isfinite(a.reaction_sd))
    throw rms::InputError("--tremor-deg, --reaction-sd-s and --max-s must be numbers");
  if (!(0 <= d.reaction_lo_s && d.reaction_lo_s <= d.reaction_hi_s && d.reaction_hi_s <= 5))
    throw rms::InputError("--reaction-s " + a.reaction + ": 0 <= LO <= HI <= 5 s");
  if (!(0.1 <= d.gain_lo && d.gain_lo <= d.gain_hi && d.gain_hi <= 5))
    throw rms::InputError("--rate-gain " + a.gain + ": 0.1 <= LO <= HI <= 5");
  const rms::sim::SubjectKind kind = rms::sim::SubjectKindFrom(a.subject);
  std::vector<nlohmann::json> out;
  for (const auto& f :
       rms::sim::FlyRuns(config, d, a.seed, a.runs, a.max_s, jobs, kind, a.first_run))
    out.push_back(RunJson(f, config));
  return out;
}

// One cell's line: "INDEX<TAB>KEY<TAB>ARG..." -> "INDEX<TAB>{"flights": [...]}";
// "" for a line that is no cell (no INDEX of digits, no KEY).
std::string RunCell(const std::string& line, int jobs, bool* ok) {
  std::vector<std::string> fields;
  std::stringstream ss(line);
  for (std::string f; std::getline(ss, f, '\t');) fields.push_back(f);
  *ok = false;
  if (fields.size() < 2 || fields[0].empty() || fields[0].size() > 15 ||
      fields[0].find_first_not_of("0123456789") != std::string::npos)
    return "";
  const std::string index = fields[0];
  nlohmann::json result;
  try {
    // The key is the cell's options' hash: what is cached under it is what
    // they fly (a cells.tsv edited by hand cannot put one design's flights
    // under another's key).
    std::string joined;
    for (std::size_t i = 2; i < fields.size(); ++i) {
      if (i > 2) joined += '\t';
      joined += fields[i];
    }
    if (fields[1] != Sha256Hex(joined.data(), joined.size()))
      throw rms::InputError("the cell's key is not its options' SHA-256 (a cells.tsv edited?)");
    CLI::App app{"a cell"};
    app.set_help_flag();  // (--help is no cell's option)
    FlyArgs a;
    AddFlyOptions(app, a);
    std::vector<std::string> args(fields.begin() + 2, fields.end());
    std::reverse(args.begin(), args.end());  // CLI11 takes them last first
    app.parse(args);
    result = {{"flights", Fly(a, jobs)}};
    *ok = true;
  } catch (const CLI::ParseError& e) {
    result = {{"error", std::string("a cell's options: ") + e.what()}};
  } catch (const std::exception& e) {
    result = {{"error", rms::TerminalText(e.what())}};
  }
  return index + "\t" + result.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

int RunCells(std::istream& in, int jobs) {
  int failed = 0, not_cells = 0, n = 0;
  for (std::string line; std::getline(in, line);) {
    ++n;
    if (line.empty()) continue;
    bool ok = false;
    const std::string out = RunCell(line, jobs, &ok);
    if (out.empty()) {
      std::cerr << "rms_fly: --cells: line " << n
                << " is no cell (INDEX<TAB>KEY<TAB>ARG..., INDEX digits)\n";
      ++not_cells;
      continue;
    }
    std::cout << out << std::endl;  // each line as it is done (a sweep reads them as they come)
    failed += !ok;
  }
  return not_cells ? 2 : failed ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab rms_fly: a design flown closed loop from the start by N virtual subjects (the "
      "autopilot, or the scripted operator at an offline station, with a reaction time, a rate "
      "gain and a noise seed drawn for each run from one seed), no network; a JSON line a run "
      "(docs/studies.md)"};
  app.set_version_flag("--version", rms::VersionString());
  FlyArgs a;
  AddFlyOptions(app, a);
  std::string cells;
  int jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  app.add_option("--jobs", jobs, "Flights at once (threads)")->check(CLI::Range(1, 256));
  bool software_id = false;
  app.add_flag("--software-id", software_id,
               "Print the version and this binary's SHA-256 (what a sweep's cells are made with)");
  app.add_option("--cells", cells,
                 "A sweep's cells, FILE or - (standard input): a line \"INDEX<TAB>KEY<TAB>ARG...\" "
                 "each, its options; a result line each (scripts/sweep-cell --fly-cells)");
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  spdlog::set_level(spdlog::level::off);  // the pilots' narration: each run's line says it
  if (software_id) {
    std::cout << SoftwareId() << "\n";
    return 0;
  }
  if (app.count("--cells") > 0) {
    for (const char* o : {"--config", "--set", "--subject", "--runs", "--first-run", "--seed",
                          "--reaction-s", "--rate-gain", "--tremor-deg", "--reaction-sd-s",
                          "--max-s", "--config-sha256", "--software"}) {
      if (app.count(o) > 0) {
        std::cerr << "rms_fly: --cells: each cell's options are in its line (not " << o
                  << " beside it)\n";
        return 2;
      }
    }
    if (cells == "-") return RunCells(std::cin, jobs);
    std::ifstream in(cells);
    if (!in) {
      std::cerr << "rms_fly: --cells " << cells << ": cannot be read\n";
      return 2;
    }
    return RunCells(in, jobs);
  }
  try {
    for (const auto& j : Fly(a, jobs)) std::cout << j.dump() << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "rms_fly: " << rms::TerminalText(e.what()) << "\n";
    return 2;
  }
}
