#pragma once
// A session's LCM log as CSV (docs/sessions.md "Export"): one file a channel
// (operator_input, dcp_frame, esg_frame, dcp_telemetry, status, control),
// every message decoded into engineering units, the unit in each column's
// header ("shoulder_yaw [deg]"), one row a message (status: one a counter).
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace rms::session {

// Returns each file written with its rows, and the count of malformed
// messages skipped. Throws rms::InputError for an unreadable session.
std::vector<std::pair<std::string, long>> ExportCsv(const std::string& session_dir, const std::string& out_dir,
                                                    const std::function<void(const std::string&)>& progress = {});

}  // namespace rms::session
