#pragma once
// Designs judged by flying them (docs/studies.md "Designs judged by flying
// them"): N closed-loop flights of one design by virtual subjects, each a
// draw of a person's dispersions -- a reaction time, a rate gain, a noise
// seed -- from one seed, on this machine's cores. Two kinds of subject: the
// autopilot (the rate gain scales its rates, the noise is a tremor of its
// joint commands) and the scripted operator at an offline station (it reads
// only the status screen and types only keys; the rate gain scales how long
// it holds a timed tap, the noise draws each reaction about the run's).
// Run k of either kind draws the same reaction time and gain: the two
// kinds are paired. Deterministic: the same seed gives the same flights,
// whatever the number of threads.
#include <cstdint>
#include <string>
#include <vector>

#include "rms/base/config.h"
#include "rms/sim/closed_loop.h"

namespace rms::sim {

// The dispersions a run's virtual subject is drawn from: reaction time and
// rate gain uniform within their ranges, the tremor fixed (its noise seeded
// per run).
struct Dispersions {
  double reaction_lo_s = 0.2, reaction_hi_s = 0.5;
  double gain_lo = 0.8, gain_hi = 1.2;
  double tremor_deg = 0.05;     // the autopilot's
  double reaction_sd_s = 0.05;  // the scripted operator's, each reaction
};

enum class SubjectKind { kAutopilot, kScripted };
// "autopilot", "scripted"; SubjectKindFrom throws rms::InputError on another.
const char* SubjectKindName(SubjectKind k);
SubjectKind SubjectKindFrom(const std::string& name);

struct FlightRun {
  int run = 0;             // 0..N-1
  std::uint64_t seed = 0;  // the run's own (from the sweep's seed and the run)
  double reaction_s = 0;   // drawn
  int latency_frames = 1;  // the reaction time in frames (at least one)
  double rate_gain = 1;    // drawn
  SubjectKind subject = SubjectKind::kAutopilot;
  long key_actions = -1;  // the scripted operator's keys (-1: the autopilot)
  ClosedLoopResult result;
};

// The run's own seed: SplitMix64 of the seed and the run's index.
std::uint64_t RunSeed(std::uint64_t seed, int run);
// The virtual subject of run `run`.
FlightRun DrawSubject(const LabConfig& config, const Dispersions& d, std::uint64_t seed, int run);
// N flights by `subject`, `jobs` at once; each at most max_s of session
// time. The scripted operator flies with the default bindings
// (config/bindings.toml): the keys it knows.
// The runs are numbered from first_run (a sweep's cell: runs first_run..
// first_run+runs-1, each drawn as in one sweep of them all).
std::vector<FlightRun> FlyRuns(const LabConfig& config, const Dispersions& d, std::uint64_t seed,
                               int runs, double max_s, int jobs,
                               SubjectKind subject = SubjectKind::kAutopilot, int first_run = 0);

}  // namespace rms::sim
