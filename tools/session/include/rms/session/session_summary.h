#pragma once
// A lab session's summary.json (docs/sessions.md): frames published,
// rendered and dropped per link, the mode, latency, and what the LCM log holds.
// Built from the session folder alone: the LCM log (lcmlog) and each
// process's final counters (stats/*.json). The session's manifest is
// rms/session/manifest.h; a look at a live address, address_probe.h; a
// replay's frames against the recorded ones, esg_compare.h.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rms/base/config.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"

namespace rms::session {

// Reads SESSION/lcmlog and SESSION/stats/*.json. Throws rms::InputError when
// the log cannot be read.
nlohmann::ordered_json Summarize(const std::string& session_dir);

// A DCP's run held in memory (a re-simulated design: docs/sessions.md
// "Sweeps"): its frames and telemetry in the order it published them (as a
// log of it would hold them: repeats and all), and where it published an
// RMS_DCP_STATE RESTORE among them.
struct DcpRun {
  std::vector<dcp_frame_t> frames;
  std::vector<dcp_telemetry_t> telemetry;
  std::vector<std::size_t> restores_before;  // telemetry messages published before each restore
};
// The mission's part of summary.json -- final_mode, modes_seen, acquired,
// docked, attempts, totals, result_attempt, phase_durations_s, docking,
// held_frames -- as Summarize makes it from a log holding this run and
// nothing else (a re-simulation's log, whose session has no restarts), by
// the same code (the DCP frames believed, the telemetry they confirm, the
// attempt log), without writing and reading a log. `config`: the run's.
nlohmann::ordered_json SummarizeDcpRun(const LabConfig& config, const DcpRun& run);

// The indices of the longest run of strictly increasing values in v, in
// order (patience sorting, O(n log n)): the DCP's frames a reader of a log
// believes (the DCP numbers its frames upward; a frame off the run is a
// forgery: docs/security.md "What the summary trusts"). Of a value repeated
// where the run takes it, the first copy's index: what a reader placed after
// the first copy stays after it.
std::vector<std::size_t> LongestIncreasingRun(const std::vector<std::int64_t>& v);

// A logged channel's name without the session's channel suffix
// ("RMS_DCP_FRAME_BAY2" -> "RMS_DCP_FRAME"); other names unchanged.
std::string BaseChannel(const std::string& channel);

}  // namespace rms::session
