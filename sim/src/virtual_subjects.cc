#include "rms/sim/virtual_subjects.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
#include <random>
#include <thread>

#include "rms/base/check.h"
#include "rms/operator_station/bindings.h"
#include "rms/sim/offline_station.h"

#include "flight_log.h"

namespace rms::sim {

std::uint64_t RunSeed(std::uint64_t seed, int run) {
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ULL * static_cast<std::uint64_t>(run + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

FlightRun DrawSubject(const LabConfig& config, const Dispersions& d, std::uint64_t seed, int run) {
  FlightRun f;
  f.run = run;
  f.seed = RunSeed(seed, run);
  std::mt19937_64 rng(f.seed);
  f.reaction_s = std::uniform_real_distribution<double>(d.reaction_lo_s, d.reaction_hi_s)(rng);
  f.rate_gain = std::uniform_real_distribution<double>(d.gain_lo, d.gain_hi)(rng);
  f.latency_frames =
      std::max(1, static_cast<int>(std::lround(f.reaction_s * config.session.frame_rate_hz)));
  return f;
}

const char* SubjectKindName(SubjectKind k) {
  return k == SubjectKind::kScripted ? "scripted" : "autopilot";
}

SubjectKind SubjectKindFrom(const std::string& name) {
  for (const SubjectKind k : {SubjectKind::kAutopilot, SubjectKind::kScripted})
    if (name == SubjectKindName(k)) return k;
  throw InputError("subject '" + name + "': autopilot or scripted");
}

namespace {

void FlyAutopilotRun(const LabConfig& config, const Dispersions& d, double max_s, FlightRun* f) {
  VirtualSubject s;
  s.autopilot.cameras = false;
  s.autopilot.timeout_s = max_s;
  s.latency_frames = f->latency_frames;
  s.rate_gain = f->rate_gain;
  s.tremor_deg = d.tremor_deg;
  s.seed = f->seed;
  f->result = FlyVirtualSubject(config, s,
                                static_cast<int>(std::ceil(max_s * config.session.frame_rate_hz)));
  // Out of frames: say where it had got to, as the scripted operator's
  // flights do (the autopilot's own timeout names its phase).
  if (!f->result.docked && f->result.failure == "frame limit")
    f->result.failure = TimeUpFailure(f->result, max_s);
}

void FlyScriptedRun(const LabConfig& config, const operator_station::Bindings& bindings,
                    const Dispersions& d, double max_s, FlightRun* f) {
  ScriptedOperatorOptions o;
  o.reaction_s = f->reaction_s;
  o.tap_gain = f->rate_gain;
  o.reaction_sd_s = d.reaction_sd_s;
  o.seed = f->seed | 1;  // never 0: 0 is "no noise"
  ScriptedFlight flight = FlyScriptedSubject(config, bindings, o, max_s);
  f->key_actions = flight.key_actions;
  f->result = std::move(flight.result);
}

}  // namespace

std::vector<FlightRun> FlyRuns(const LabConfig& config, const Dispersions& d, std::uint64_t seed,
                               int runs, double max_s, int jobs, SubjectKind subject,
                               int first_run) {
  std::vector<FlightRun> out(static_cast<std::size_t>(std::max(0, runs)));
  std::optional<operator_station::Bindings> bindings;
  if (subject == SubjectKind::kScripted)
    bindings = operator_station::LoadBindings(operator_station::DefaultBindingsPath());
  std::atomic<int> next{0};
  auto work = [&] {
    for (int i = next++; i < runs; i = next++) {
      FlightRun f = DrawSubject(config, d, seed, first_run + i);
      f.subject = subject;
      if (subject == SubjectKind::kScripted)
        FlyScriptedRun(config, *bindings, d, max_s, &f);
      else
        FlyAutopilotRun(config, d, max_s, &f);
      out[static_cast<std::size_t>(i)] = std::move(f);
    }
  };
  std::vector<std::thread> threads;
  for (int j = 1; j < std::max(1, jobs); ++j) threads.emplace_back(work);
  work();
  for (auto& t : threads) t.join();
  return out;
}

}  // namespace rms::sim
