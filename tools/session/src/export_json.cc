// ExportJsonLines (export_csv.h): the session's log as JSON lines for MCAP.
#include <ostream>

#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_state_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/lcm_json.h"
#include "rms/operator_input_t.hpp"
#include "rms/operator_state_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/session/export_csv.h"
#include "rms/session/session_log.h"
#include "rms/session_control_t.hpp"
#include "rms/window_keys_t.hpp"
#include "rms/wire/channels.h"

namespace rms::session {

namespace {

template <class Msg>
bool Line(SessionLog& log, const LogMessage& ev, const char* type, std::ostream& out) {
  Msg m{};
  if (!log.Decode(ev, &m)) return false;
  nlohmann::ordered_json j;
  j["channel"] = ev.channel;
  j["type"] = type;
  j["log_time_ns"] = ev.log_us * 1000;
  if constexpr (requires { m.send_time_us; }) {
    if (m.send_time_us > 0) j["publish_time_ns"] = m.send_time_us * 1000;
  }
  j["message"] = lcm_json::ToJson(m);
  out << j.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << '\n';
  return true;
}

}  // namespace

long ExportJsonLines(const std::string& session_dir, std::ostream& out, long* malformed) {
  SessionLog log(session_dir);
  long n = 0;
  log.Read({}, [&](const LogMessage& ev) {
    bool ok = false;
    const std::string_view b = ev.base;
    if (b == wire::channels::kOperatorInput)
      ok = Line<operator_input_t>(log, ev, "rms.operator_input_t", out);
    else if (b == wire::channels::kOperatorState)
      ok = Line<operator_state_t>(log, ev, "rms.operator_state_t", out);
    else if (b == wire::channels::kDcpFrame)
      ok = Line<dcp_frame_t>(log, ev, "rms.dcp_frame_t", out);
    else if (b == wire::channels::kDcpTelemetry)
      ok = Line<dcp_telemetry_t>(log, ev, "rms.dcp_telemetry_t", out);
    else if (b == wire::channels::kDcpState)
      ok = Line<dcp_state_t>(log, ev, "rms.dcp_state_t", out);
    else if (b == wire::channels::kEsgFrame)
      ok = Line<esg_frame_t>(log, ev, "rms.esg_frame_t", out);
    else if (b == wire::channels::kStatus)
      ok = Line<process_status_t>(log, ev, "rms.process_status_t", out);
    else if (b == wire::channels::kControl)
      ok = Line<session_control_t>(log, ev, "rms.session_control_t", out);
    else if (b == wire::channels::kWindowKeys)
      ok = Line<window_keys_t>(log, ev, "rms.window_keys_t", out);
    else
      return;
    n += ok;
  });
  if (malformed) *malformed = log.malformed();
  return n;
}

}  // namespace rms::session
