#pragma once
// Designs judged by flying them (docs/studies.md "Designs judged by flying
// them"): N closed-loop flights of one design by virtual subjects, each a
// draw of a person's dispersions -- a reaction time, a rate gain, a tremor's
// seed -- from one seed, on this machine's cores. Deterministic: the same
// seed gives the same flights, whatever the number of threads.
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
  double tremor_deg = 0.05;
};

struct FlightRun {
  int run = 0;             // 0..N-1
  std::uint64_t seed = 0;  // the run's own (from the sweep's seed and the run)
  double reaction_s = 0;   // drawn
  int latency_frames = 1;  // the reaction time in frames (at least one)
  double rate_gain = 1;    // drawn
  ClosedLoopResult result;
};

// The run's own seed: SplitMix64 of the seed and the run's index.
std::uint64_t RunSeed(std::uint64_t seed, int run);
// The virtual subject of run `run`.
FlightRun DrawSubject(const LabConfig& config, const Dispersions& d, std::uint64_t seed, int run);
// N flights, `jobs` at once; each at most max_s of session time.
std::vector<FlightRun> FlyRuns(const LabConfig& config, const Dispersions& d, std::uint64_t seed,
                               int runs, double max_s, int jobs);

}  // namespace rms::sim
