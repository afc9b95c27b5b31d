#pragma once
// Re-simulation (docs/sessions.md "Re-simulation"): the Dynamic Collision
// Program run again on a session's recorded operator inputs, as fast as it
// can (no network, no wall clock: the DCP's own node over a log-backed
// transport). With the session's configuration its outputs must be the
// recorded ones, word for word; with another configuration it writes a new
// session folder showing how the same inputs fare with that design, and a
// comparison of the two.
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

namespace rms::resim {

struct ResimOptions {
  std::string session;      // the recorded session folder
  std::string config_path;  // another configuration ("" = the session's own config.toml)
  std::string out_dir;      // where the new session goes (with a config; default SESSION-resim)
  // Progress (0..1) with a line to show; called every few percent.
  std::function<void(double, const std::string&)> progress;
};

struct ResimResult {
  long frames = 0;     // DCP frames re-simulated
  long compared = 0;   // recorded DCP frames compared
  long identical = 0;  // ... identical word for word (and their telemetry field for field)
  std::string first_difference;  // where they first differ ("" if nowhere)
  long skipped = 0;  // recorded DCP frames not re-simulated (the log lacks the state before them)
  std::string note;  // ... said in words ("" if none)
  std::string log_note;     // the log's end is no whole event ("" if it is)
  long states_taken = 0;    // logged RMS_DCP_STATE taken (start, restores, resumes)
  long states_checked = 0;  // periodic RMS_DCP_STATE the re-simulated state was checked against
  std::string state_difference;       // the first of those that differed ("" if none)
  double seconds = 0.0;               // wall time of the re-simulation, all of it
  double read_seconds = 0.0;          // of which reading and decoding the session's log
  double run_seconds = 0.0;           // of which the DCP over its LCM interface, frame by frame
  double recorded_seconds = 0.0;      // the session's own duration (first to last input frame)
  std::string out_dir;                // the new session (with another configuration)
  nlohmann::ordered_json comparison;  // with another configuration: comparison.json
};

// Throws rms::InputError for a folder that is no session, a log that cannot
// be re-simulated (DCP frames missing from it with their inputs ambiguous,
// a restored checkpoint file gone), or a bad configuration.
ResimResult Resimulate(const ResimOptions& options);

}  // namespace rms::resim
