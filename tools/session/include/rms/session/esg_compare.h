#pragma once
// A replay's ESG frames against the recorded session's (docs/sessions.md
// "Replay").
#include <nlohmann/json.hpp>
#include <string>

namespace rms::session {

// A replay's ESG frames against the recorded ones, matched by the DCP frame
// they were made from: {"recorded", "replayed", "identical", "missing",
// "first_difference"}.
nlohmann::ordered_json CompareEsgFrames(const std::string& original_dir,
                                        const std::string& replay_dir);

}  // namespace rms::session
