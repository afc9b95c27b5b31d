#pragma once
// Checkpoint files (docs/sessions.md "Freeze, run, step, checkpoint"): the
// DCP's state at a frame and the operator inputs it had just processed, so a
// session can restart from that moment. Written by dynamics_proc; read by
// dynamics_proc (the state) and operator_station (the inputs, to carry on
// from where the arm is). JSON, doubles exact.
#include <cstdint>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "rms/input_block.h"

namespace rms {

struct Checkpoint {
  std::int64_t dcp_frame = -1;    // the last DCP frame before the save
  std::int64_t input_frame = -1;  // the operator frame it answered
  std::int64_t saved_us = 0;      // wall clock at the save
  std::string config;             // the configuration file the session ran
  OperatorInputs inputs;          // the operator inputs of that frame
  nlohmann::json dcp;             // DynamicCollisionProgram::SaveState()
};

// Throw rms::InputError naming the file and what is wrong.
void WriteCheckpoint(const std::string& path, const Checkpoint& c);
Checkpoint ReadCheckpoint(const std::string& path);
// The same from the file's text (path names it in errors).
Checkpoint ParseCheckpoint(std::string_view text, const std::string& path);

}  // namespace rms
