#pragma once
// A session's summary (summary.json) in a few lines for a person:
// `rms_session summary SESSION --brief`, which scripts/lab prints at the end
// of every session (docs/sessions.md "The summary").
#include <nlohmann/json.hpp>
#include <ostream>

namespace rms::session {

void PrintBrief(const nlohmann::ordered_json& summary, std::ostream& os);

}  // namespace rms::session
