#pragma once
// The checks a receiver of RMS_DCP_TELEMETRY applies after SafeDecode
// (docs/protocol.md "Malformed messages"): a message that decodes but holds
// NaN or infinity, a mode outside 1..3, collision bits outside the defined
// ones or a negative frame number is dropped and counted under the counter
// returned (dropped.telemetry_REASON), never acted on.
#include <optional>

#include "rms/base/counters.h"
#include "rms/dcp_telemetry_t.hpp"

namespace rms::operator_station {

// Nothing when the telemetry is usable; else the counter of its problem:
// dropped.telemetry_non_finite, _mode, _collision_bits, _frame, _time
// (frame numbers negative or beyond 2^48, send times not in [0, 2^62) us).
std::optional<Counter> TelemetryProblem(const dcp_telemetry_t& m);

}  // namespace rms::operator_station
