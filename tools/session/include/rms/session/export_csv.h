#pragma once
// A session's LCM log as CSV (docs/sessions.md "Export"): one file a channel
// (operator_input, dcp_frame, esg_frame, dcp_telemetry, status, control),
// every message decoded into engineering units, the unit in each column's
// header ("shoulder_yaw [deg]"), one row a message (status: one a counter).
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

namespace rms::session {

// What the export read of the log, beside what it wrote.
struct ExportRead {
  long events = 0;                // the session's own messages read
  std::int64_t unread_bytes = 0;  // at the log's end, no whole event: not exported
  std::int64_t skipped_bytes =
      0;  // inside it, no event: read past (docs/sessions.md "A damaged log")
};

// Returns each file written with its rows, and the count of malformed
// messages skipped. Throws rms::InputError for an unreadable session.
std::vector<std::pair<std::string, long>> ExportCsv(
    const std::string& session_dir, const std::string& out_dir,
    const std::function<void(const std::string&)>& progress = {}, ExportRead* read = nullptr);

}  // namespace rms::session

namespace rms::session {

// The session's own messages as JSON lines, for the MCAP writer
// (tools/mcap/write_mcap.mjs; docs/sessions.md "Export"): one object a
// message, {"channel", "type" ("rms.T", its schema's title), "log_time_ns",
// "publish_time_ns" (the sender's send time, where the message has one),
// "message"}, every field by name (lcm_json.h, generated from the .lcm
// files). Returns the messages written; malformed ones are counted in
// *malformed and left out.
long ExportJsonLines(const std::string& session_dir, std::ostream& out, long* malformed);

}  // namespace rms::session
