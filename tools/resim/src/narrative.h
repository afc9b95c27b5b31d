#pragma once
// How another design fared on the recorded inputs (docs/sessions.md
// "Re-simulation against another design"): when each session acquired,
// cleared the bay and docked, where the end effector went apart, and why,
// in sentences, from the DCP's own tests at the moments that mattered.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "rms/base/config.h"
#include "rms/dcp_telemetry_t.hpp"

namespace rms::resim {

// recorded / now: the telemetry in increasing order of DCP frame, one a
// frame (as SortByFrame leaves it), as recorded and as the other design
// (`config_now`) made it. comparison.json's "recorded", "resimulated",
// "point_A" and "explanation".
nlohmann::ordered_json DesignComparison(const std::vector<dcp_telemetry_t>& recorded,
                                        const std::vector<dcp_telemetry_t>& now,
                                        const LabConfig& config_now, double rate_hz);

}  // namespace rms::resim
