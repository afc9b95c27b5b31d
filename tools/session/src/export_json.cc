// ExportJsonLines (export_csv.h): the session's log as JSON lines for MCAP.
#include <cmath>
#include <ostream>
#include <type_traits>

#include "rms/control_answer_t.hpp"
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

// The message's session time (docs/sessions.md "Session time"): a frame
// that answers an operator frame (the DCP's, its telemetry, the scene's),
// or the operator's state of a frame, at that frame's; anything else at
// the operator's last frame before it.
template <class Msg>
double SessionTimeS(const LogMessage& ev, const Msg& m, double rate_hz) {
  if constexpr (std::is_same_v<Msg, dcp_frame_t> || std::is_same_v<Msg, dcp_telemetry_t> ||
                std::is_same_v<Msg, esg_frame_t>)
    return static_cast<double>(m.input_frame) / rate_hz;
  else if constexpr (std::is_same_v<Msg, operator_state_t> || std::is_same_v<Msg, operator_input_t>)
    return static_cast<double>(m.frame) / rate_hz;
  else
    return ev.session_time_s;
}

// The MCAP's log time is session time, in ns from the session's first frame
// (so a plot's axis is the session as flown: standing still in a freeze);
// its publish time the wall clock's send time, ns since 1970.
template <class Msg>
bool Line(SessionLog& log, const LogMessage& ev, const char* type, std::ostream& out) {
  Msg m{};
  if (!log.Decode(ev, &m)) return false;
  nlohmann::ordered_json j;
  j["channel"] = ev.channel;
  j["type"] = type;
  j["log_time_ns"] =
      static_cast<std::int64_t>(std::llround(SessionTimeS(ev, m, log.frame_rate_hz()) * 1e9));
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
    else if (b == wire::channels::kControlAnswer)
      ok = Line<control_answer_t>(log, ev, "rms.control_answer_t", out);
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
