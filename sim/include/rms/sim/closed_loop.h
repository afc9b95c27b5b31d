#pragma once
// The autopilot in the loop with the real Dynamic Collision Program, in one
// process and without a network: each frame the autopilot's inputs go
// through the input block's words (as on the wire) to the DCP, and the DCP's
// telemetry comes back after `latency_frames` frames (one, as over LCM where
// the station reads the telemetry before it sends the next block).
// Deterministic; for tests and for checking a configuration before a session.
#include <cstdint>
#include <string>
#include <vector>

#include "rms/base/config.h"
#include "rms/base/counters.h"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/operator_station/autopilot.h"

namespace rms::sim {

struct ClosedLoopResult {
  bool docked = false;
  std::string failure;  // the autopilot's, or "frame limit"
  int frames = 0;
  double time_s = 0.0;
  dcp_telemetry_t last{};       // the last telemetry
  double dock_distance_ft = 0;  // at the frame docking was declared
  double dock_angle_deg = 0;
  int modes_entered[4] = {0, 0, 0,
                          0};  // frame each mode was first seen (0: never, mode 1 at start)
  int held_frames = 0;         // frames the DCP held the slave arm (a collision)
  int collision_events = 0;    // runs of frames whose command collided (their starts)
  int docked_frame = -1;       // the frame docking was declared (-1: never)
  Counters autopilot;          // the autopilot's counters
  Counters dcp;                // what the DCP counted (clamped inputs...)
};

// A virtual subject (docs/studies.md "Designs judged by flying them"): the
// autopilot flying with a person's dispersions -- it sees the telemetry
// `latency_frames` frames late (a reaction time), moves at `rate_gain`
// times its rates, and its joint commands carry a tremor of `tremor_deg`
// (standard deviation, each frame, each joint; a seeded generator).
struct VirtualSubject {
  operator_station::AutopilotOptions autopilot;
  int latency_frames = 1;
  double rate_gain = 1.0;
  double tremor_deg = 0.0;
  std::uint64_t seed = 0;
};
ClosedLoopResult FlyVirtualSubject(const LabConfig& config, const VirtualSubject& subject,
                                   int max_frames);

// inputs: when given, receives each frame's operator inputs as the DCP
// decoded them (for benchmarks that replay the flight).
ClosedLoopResult FlyAutopilot(const LabConfig& config,
                              const operator_station::AutopilotOptions& options, int max_frames,
                              int latency_frames = 1,
                              std::vector<wire::OperatorInputs>* inputs = nullptr);

}  // namespace rms::sim
