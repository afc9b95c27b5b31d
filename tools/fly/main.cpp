// rms_fly: one design flown from the start by N virtual subjects -- the
// autopilot with a reaction time, a rate gain and a tremor drawn for each
// run from one seed -- in closed loop with the real DCP, no network; a JSON
// line a run on stdout (docs/studies.md "Designs judged by flying them").
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <spdlog/spdlog.h>
#include <thread>

#include "rms/base/check.h"
#include "rms/base/command_line.h"
#include "rms/base/config.h"
#include "rms/base/config_settings.h"
#include "rms/base/folder_file.h"
#include "rms/base/text.h"
#include "rms/sim/virtual_subjects.h"

namespace {

nlohmann::json RunJson(const rms::sim::FlightRun& f, const rms::LabConfig& config) {
  const rms::sim::ClosedLoopResult& r = f.result;
  const double rate = config.session.frame_rate_hz;
  const auto at = [&](int frame) -> nlohmann::json {
    return frame > 0 ? nlohmann::json(frame / rate) : nlohmann::json(nullptr);
  };
  nlohmann::json j = {{"run", f.run},
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
                      {"held_frames", r.held_frames}};
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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab rms_fly: a design flown closed loop from the start by N virtual subjects (the "
      "autopilot with a reaction time, a rate gain and a tremor drawn for each run from one seed), "
      "no network; a JSON line a run (docs/studies.md)"};
  std::string config_path, reaction = "0.2,0.5", gain = "0.8,1.2";
  std::vector<std::string> sets;
  int runs = 20, jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::uint64_t seed = 1;
  double tremor = 0.01, max_s = 300;
  app.add_option("--config", config_path, "The configuration (docs/config.md)")->required();
  app.add_option("--set", sets, "KEY=VALUE: a design's key over it, as rms_resim --set");
  app.add_option("--runs", runs, "Flights")->capture_default_str()->check(CLI::Range(1, 100000));
  app.add_option("--seed", seed, "The seed every run's draws come from")->capture_default_str();
  app.add_option("--reaction-s", reaction, "Reaction time, s: LO,HI (uniform) or one value")
      ->capture_default_str();
  app.add_option("--rate-gain", gain, "The subject's rates over the autopilot's: LO,HI or one")
      ->capture_default_str();
  app.add_option("--tremor-deg", tremor,
                 "Joint command tremor, deg: its standard deviation (a Gauss-Markov wander, 1 s "
                 "correlation time)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 5.0));
  app.add_option("--max-s", max_s, "Session time a flight may take, s")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 3600.0));
  app.add_option("--jobs", jobs, "Flights at once (threads)")->check(CLI::Range(1, 256));
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  spdlog::set_level(spdlog::level::off);  // the autopilot's narration: each run's line says it
  try {
    std::vector<rms::ConfigSetting> settings;
    for (const std::string& s : sets) settings.push_back(rms::ParseConfigSetting(s));
    const std::string text =
        rms::ApplyConfigSettings(rms::ReadRegularFile(config_path, "configuration",
                                                      rms::kMaxConfigBytes, rms::Links::kFollow),
                                 config_path, settings);
    const rms::LabConfig config =
        rms::ParseConfig(text, settings.empty() ? config_path : config_path + " with --set");
    rms::sim::Dispersions d;
    std::tie(d.reaction_lo_s, d.reaction_hi_s) = Range(reaction, "--reaction-s");
    std::tie(d.gain_lo, d.gain_hi) = Range(gain, "--rate-gain");
    d.tremor_deg = tremor;
    if (!std::isfinite(tremor) || !std::isfinite(max_s))
      throw rms::InputError("--tremor-deg and --max-s must be numbers");
    if (!(0 <= d.reaction_lo_s && d.reaction_lo_s <= d.reaction_hi_s && d.reaction_hi_s <= 5))
      throw rms::InputError("--reaction-s " + reaction + ": 0 <= LO <= HI <= 5 s");
    if (!(0.1 <= d.gain_lo && d.gain_lo <= d.gain_hi && d.gain_hi <= 5))
      throw rms::InputError("--rate-gain " + gain + ": 0.1 <= LO <= HI <= 5");
    for (const auto& f : rms::sim::FlyRuns(config, d, seed, runs, max_s, jobs))
      std::cout << RunJson(f, config).dump() << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "rms_fly: " << rms::TerminalText(e.what()) << "\n";
    return 2;
  }
}
