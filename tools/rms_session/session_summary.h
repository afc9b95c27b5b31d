#pragma once
// A lab session's summary.json (docs/sessions.md): frames published,
// rendered and dropped per link, the mode, latency, and what the LCM log holds.
// Built from the session folder alone: the LCM log (lcmlog) and each
// process's final counters (stats/*.json).
#include <string>

#include <nlohmann/json.hpp>

namespace rms::session {

// Reads SESSION/lcmlog and SESSION/stats/*.json. Throws rms::InputError when
// the log cannot be read.
nlohmann::ordered_json Summarize(const std::string& session_dir);

}  // namespace rms::session
