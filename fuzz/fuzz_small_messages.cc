// The other messages every process reads: RMS_DCP_TELEMETRY (SafeDecode and
// TelemetryProblem, as operator_station), RMS_STATUS (process_status_t, as
// operator_station and rms_monitor), RMS_CONTROL (session_control_t, as
// every process), RMS_OPERATOR_STATE (operator_state_t, as esg_renderer) and
// RMS_WINDOW_KEYS (window_keys_t, as operator_station). The first byte picks
// the message type.
#include "rms/dcp_telemetry_t.hpp"
#include "rms/operator_state_t.hpp"
#include "rms/operator_station/telemetry_check.h"
#include "rms/process_status_t.hpp"
#include "rms/session_control_t.hpp"
#include "rms/window_keys_t.hpp"
#include "rms/wire/message_io.h"

#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const int n = static_cast<int>(size - 1);
  switch (data[0] % 5) {
    case 0: {
      rms::dcp_telemetry_t m{};
      if (rms::wire::SafeDecode(data + 1, n, &m) == rms::wire::DecodeError::kNone)
        (void)rms::operator_station::TelemetryProblem(m);
      break;
    }
    case 1: {
      rms::process_status_t m;
      if (rms::wire::SafeDecode(data + 1, n, &m) == rms::wire::DecodeError::kNone) {
        std::uint64_t sum = 0;  // read every field, as a monitor does
        for (int i = 0; i < m.num_counters; ++i)
          sum += m.counter_names[i].size() + static_cast<std::uint64_t>(m.counter_values[i]);
        (void)sum;
      }
      break;
    }
    case 2: {
      rms::session_control_t m;
      (void)rms::wire::SafeDecode(data + 1, n, &m);
      break;
    }
    case 3: {
      rms::operator_state_t m{};
      (void)rms::wire::SafeDecode(data + 1, n, &m);
      break;
    }
    default: {
      rms::window_keys_t m;
      if (rms::wire::SafeDecode(data + 1, n, &m) == rms::wire::DecodeError::kNone) {
        long sum = 0;  // every key, as the station reads them
        for (int i = 0; i < m.num_held; ++i) sum += m.held[i];
        for (int i = 0; i < m.num_pressed; ++i) sum += m.pressed[i];
        (void)sum;
      }
      break;
    }
  }
  return 0;
}
