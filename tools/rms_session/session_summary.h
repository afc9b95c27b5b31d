#pragma once
// A lab session's summary.json (docs/sessions.md): frames published,
// rendered and dropped per link, the mode, latency, and what the LCM log holds.
// Built from the session folder alone: the LCM log (lcmlog) and each
// process's final counters (stats/*.json).
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace rms::session {

// Reads SESSION/lcmlog and SESSION/stats/*.json. Throws rms::InputError when
// the log cannot be read.
nlohmann::ordered_json Summarize(const std::string& session_dir);

// A logged channel's name without the session's channel suffix
// ("RMS_DCP_FRAME_BAY2" -> "RMS_DCP_FRAME"); other names unchanged.
std::string BaseChannel(const std::string& channel);

// SESSION/manifest.json (docs/sessions.md "The manifest"): the software
// (this build's version), the configuration (file and hash), the pilot, the
// LCM URL and channel suffix, which process ran on which host, the lab host,
// and the start time.
nlohmann::ordered_json MakeManifest(const std::string& session_dir, const std::string& pilot, const std::string& url,
                                    const std::string& suffix, const std::string& config_sha256,
                                    const std::string& timeline, const std::string& restore,
                                    const std::vector<std::string>& hosts, const std::string& command);

// A replay's ESG frames against the recorded ones, matched by the DCP frame
// they were made from: {"recorded", "replayed", "identical", "missing",
// "first_difference"}.
nlohmann::ordered_json CompareEsgFrames(const std::string& original_dir, const std::string& replay_dir);

}  // namespace rms::session
