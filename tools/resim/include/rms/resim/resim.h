#pragma once
// Re-simulation (docs/sessions.md "Re-simulation"): the Dynamic Collision
// Program run again on a session's recorded operator inputs, as fast as it
// can (no network, no wall clock: the DCP's own node over a log-backed
// transport). With the session's configuration its outputs must be the
// recorded ones, word for word; with another configuration it writes a new
// session folder showing how the same inputs fare with that design, and a
// comparison of the two.
#include <functional>
#include <istream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rms/base/config_settings.h"

namespace rms::resim {

// A recorded session's log, plan and summary, read once: several designs
// re-simulated on it in one process (rms_resim --cells, a sweep's batch of
// cells; docs/sessions.md "Sweeps") share it instead of each reading the log.
class RecordedSession;
// Throws rms::InputError for a folder that is no session or a log that
// cannot be re-simulated.
std::shared_ptr<const RecordedSession> ReadRecordedSession(const std::string& session);

struct ResimOptions {
  std::string session;      // the recorded session folder
  std::string config_path;  // another configuration ("" = the session's own config.toml)
  std::string out_dir;      // where the new session goes (with a config; default SESSION-resim)
  // Keys set over the configuration (the session's own, or config_path's):
  // another design (docs/sessions.md "Sweeps").
  std::vector<ConfigSetting> settings;
  // Another design: no session written; its cell made in memory
  // (session::SummarizeDcpRun: docs/sessions.md "Re-simulation").
  bool discard = false;
  // The session's own design, only up to this DCP frame (-1: all): the
  // branch point of scripts/lab demo --from (docs/sessions.md "Branching");
  // ResimResult::checkpoint_text is the DCP's state after it.
  long until_frame = -1;
  // Another design only: the session as read before (ReadRecordedSession
  // of the same folder), or null to read it now.
  std::shared_ptr<const RecordedSession> recorded;
  // The session's own design to its end is read and run in two shares at
  // once, one on another core (docs/sessions.md "Re-simulation"): 0, when
  // that core comes in time (else this thread does its share); 1, on one
  // thread; 2, always on two (waiting for the other core). The same result
  // each way.
  int threads = 0;
  // Progress (0..1) with a line to show; called every few percent.
  std::function<void(double, const std::string&)> progress;
};

struct ResimResult {
  long frames = 0;     // DCP frames re-simulated
  long compared = 0;   // recorded DCP frames compared
  long identical = 0;  // ... identical word for word (and their telemetry field for field)
  std::string first_difference;      // where they first differ ("" if nowhere)
  long first_difference_frame = -1;  // ... its DCP frame (-1 if nowhere, or a state differs)
  long first_decision_frame = -1;    // the first DCP frame whose words differ (-1 if none)
  std::string first_decision;        // ... which word ("control_word", "arm_words[3]", "missing")
  long skipped = 0;  // recorded DCP frames not re-simulated (the log lacks the state before them)
  std::string note;  // ... said in words ("" if none)
  // Recorded DCP frames not checked because frames before them were lost
  // from every source (a crash): how many, and each stretch (lost_from,
  // lost_to, why, unchecked_from, unchecked_to, unchecked_frames,
  // resumed_at); said in `note` too.
  long unchecked_frames = 0;
  // DCP frames the log lacks, made again from their logged inputs (Plan::
  // filled_in): re-simulated, but not checked; said in `note` too.
  long filled_in = 0;
  nlohmann::ordered_json unchecked = nlohmann::ordered_json::array();
  std::string log_note;     // the log ends in, or holds, bytes that are no event ("" if not)
  long states_taken = 0;    // logged RMS_DCP_STATE taken (start, restores, resumes)
  long states_checked = 0;  // periodic RMS_DCP_STATE the re-simulated state was checked against
  std::string state_difference;       // the first of those that differed ("" if none)
  double seconds = 0.0;               // wall time of the re-simulation, all of it
  double read_seconds = 0.0;          // of which reading and decoding the session's log
  bool read_in_two = false;           // ... in two parts at once (SessionLog::ReadInTwo)
  double run_seconds = 0.0;           // of which the DCP over its LCM interface, frame by frame
  bool in_halves = false;             // ... in two halves at once (ResimOptions::threads)
  double recorded_seconds = 0.0;      // the session's own duration (first to last input frame)
  std::string out_dir;                // the new session (with another configuration)
  nlohmann::ordered_json comparison;  // with another configuration: comparison.json
  // Another design: the sweep's cell (docs/sessions.md "Sweeps"): outcome,
  // recorded outcome, scorecard changes, first divergence.
  nlohmann::ordered_json cell;
  std::string checkpoint_text;  // with until_frame: the DCP's state after it (a checkpoint)
  // A branch (its manifest's "branch"): its recorded session's prefix
  // re-simulated first, and the state there against the branch's first state.
  long prefix_frames = 0, prefix_identical = 0;
  std::string branch_note;  // said in words when it agrees ("" when not a branch, or
                            // first_difference says why not)
};

// The effective configuration's TOML text: the session's own config.toml or
// options.config_path, with options.settings applied. Throws rms::InputError
// for a file that cannot be read or a setting that does not fit it.
std::string EffectiveConfigText(const ResimOptions& options);
// Where it came from, as a person reads it: "FILE --set KEY=VALUE ...".
std::string ConfigSource(const ResimOptions& options);
// True with another configuration or any setting.
bool OtherDesign(const ResimOptions& options);

// Throws rms::InputError for a folder that is no session, a log that cannot
// be re-simulated (DCP frames missing from it with their inputs ambiguous,
// a restored checkpoint file gone), or a bad configuration.
ResimResult Resimulate(const ResimOptions& options);

// A sweep's batch of cells (rms_resim --cells; docs/sessions.md "Sweeps"):
// each line of `in`, "INDEX<TAB>KEY<TAB>SESSION<TAB>KEY=VALUE..." (a line
// of the sweep's cells.tsv; KEY, the cache key, is not used here),
// re-simulated in memory as --discard does, `jobs` cells at once on their
// own threads (the session's own design, ResimOptions::threads, is no cell).
// Each result line, "INDEX<TAB>JSON" ({"error": ...} when it has none), is
// written whole on stdout as soon as it is made, so lines come in the order
// the cells end; a cell runs as soon as its line is read and a thread is
// free. A session's log is read once for its designs that follow one
// another (a sweep's lines are session by session), and freed with the last
// of them: only the sessions of the cells running are held. When fewer
// threads than `jobs` can be started, it says so and runs on those.
// Returns 0 when every cell had its result, 1 when a
// cell had an error line (so GNU parallel --retries tries the batch on
// another host), 2 when a line was no cell (said on stderr).
int RunCells(std::istream& in, int jobs);

// JSON as one line of text; a string that is no UTF-8 (a path's bytes) has
// U+FFFD in its place instead of throwing.
template <class Json>
std::string JsonLine(const Json& j) {
  return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

}  // namespace rms::resim
