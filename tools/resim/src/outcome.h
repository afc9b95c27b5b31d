#pragma once
// A session's outcome as a sweep's table shows it (docs/sessions.md
// "Sweeps"), from its summary.json: whether and when it acquired, cleared the
// bay and docked, its phase times, collisions and holds; and the changes of
// the outcome and of the operator's scorecard between two sessions.
#include <nlohmann/json.hpp>

namespace rms::resim {

// {"acquired", "docked", "final_mode", "reached_s": {acquired, clear_of_bay,
// docked}, "phase_durations_s": {...}, "collisions", "held_frames",
// "docking": {distance_ft, angle_deg} or null} of the summary's result
// attempt (its attempts[result_attempt - 1]).
nlohmann::ordered_json Outcome(const nlohmann::json& summary);

// Every figure of the outcome and of the result attempt's scorecard that
// differs: [{"field": "reached_s.docked", "recorded": x, "now": y}], x or y
// null where one has none.
nlohmann::ordered_json ScorecardChanges(const nlohmann::json& recorded_summary,
                                        const nlohmann::json& now_summary);

}  // namespace rms::resim
