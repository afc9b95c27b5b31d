#pragma once
// What a closed-loop flight's telemetry says, frame by frame, into its
// ClosedLoopResult: the frame each mode was entered, collisions, holds,
// docking and its margins. One home for the autopilot's loop
// (closed_loop.cc) and the offline station (offline_station.cc).
#include <string>

#include "rms/dcp_telemetry_t.hpp"
#include "rms/sim/closed_loop.h"

namespace rms::sim {

// colliding: whether the frame before collided (a collision event is a run
// of colliding frames); updated.
void ObserveFrame(const dcp_telemetry_t& tm, int frame, bool* colliding, ClosedLoopResult* r);

// Why a flight that ran out of its max_s of session time stopped, by where
// it had got to: "no acquisition by 300 s", "not out of the bay by 300 s",
// "not docked by 300 s".
std::string TimeUpFailure(const ClosedLoopResult& r, double max_s);

}  // namespace rms::sim
