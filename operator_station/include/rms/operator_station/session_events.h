#pragma once
// The session's events as the operator must see them (docs/operator.md
// "The status screen"): acquired, clear of the bay, docked, each collision's
// start and end, the arm held and released, the finger on the bar, a reset.
// Observed in the DCP's telemetry and logged, so they show in the status
// screen's events pane and in the station's log.
#include <optional>

#include "rms/dcp_telemetry_t.hpp"

namespace rms::operator_station {

class TelemetryEvents {
 public:
  // Logs what changed since the last telemetry observed.
  void Observe(const dcp_telemetry_t& t);
  // After a reset or a restore: the next telemetry starts afresh (its state
  // is announced, not compared with what came before).
  void Forget() { last_.reset(); }
  long events() const { return events_; }

 private:
  std::optional<dcp_telemetry_t> last_;
  long events_ = 0;
};

}  // namespace rms::operator_station
