#pragma once
// What re-simulation reads of a session's log (docs/sessions.md
// "Re-simulation"): the operator frames, the DCP's frames and telemetry it
// made from them, the states it logged; and the plan that replays them in
// order, from the state the log allows the re-simulation to start from.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_state_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/session/session_log.h"

namespace rms::resim {

struct RecordedInput {
  std::int64_t timestamp_us = 0;
  std::vector<std::uint8_t> bytes;
};

// An RMS_DCP_STATE as logged, with the number of the DCP's (believed)
// frames logged before it: its place among them.
struct LoggedState {
  std::size_t before = 0;
  dcp_state_t m;
};

struct Recording {
  std::string suffix;
  std::map<std::int64_t, RecordedInput> inputs;       // by operator frame
  std::vector<dcp_frame_t> dcp_frames;                // in log order
  std::map<std::int64_t, dcp_telemetry_t> telemetry;  // by DCP frame
  std::vector<LoggedState> states;                    // in log order
};

// The channels re-simulation needs, read from the log (the DCP's increasing
// run of frames only, as the summary believes them); throws InputError when
// there is no DCP frame.
Recording ReadRecording(session::SessionLog& log);

// What the re-simulation does, step by step: a logged state to take (or,
// PERIODIC, to check against), then an operator frame to answer.
struct Step {
  const dcp_state_t* state = nullptr;
  std::int64_t input_frame = -1;  // -1: a state only
  bool first = false;  // the state the re-simulation starts from (taken, whatever its reason)
};

struct Plan {
  std::vector<Step> steps;
  std::size_t first = 0;  // the index of the first recorded DCP frame re-simulated
  std::string note;       // what the log lacks, when it does not start at the session's start
};

// The operator frame each DCP frame answered, in DCP frame order, with the
// logged states in their places, and DCP frames the recorder lost filled in
// where that is unambiguous; throws InputError where the log cannot be
// re-simulated exactly.
Plan MakePlan(const Recording& r);

}  // namespace rms::resim
