#include "rms/operator_station/session_events.h"

#include <spdlog/spdlog.h>

#include "rms/wire/collision_bits.h"
#include "rms/wire/dcp_mode.h"

namespace rms::operator_station {

void TelemetryEvents::Observe(const dcp_telemetry_t& t) {
  if (!last_) {
    last_ = t;
    ++events_;
    spdlog::info("DCP: Mode {}{}{}", static_cast<int>(t.mode),
                 t.acquired ? ", the payload held" : "", t.docked ? ", docked" : "");
    return;
  }
  const dcp_telemetry_t& p = *last_;
  auto event = [&](const std::string& what) {
    ++events_;
    spdlog::info("{}", what);
  };
  if (t.mode != p.mode) {
    if (t.mode == wire::DcpMode::kExtraction && p.mode == wire::DcpMode::kAcquisition) {
      event("ACQUIRED: the payload is held (Mode 2, extraction): lift it clear of the bay");
    } else if (t.mode == wire::DcpMode::kManoeuvring && p.mode == wire::DcpMode::kExtraction) {
      event("CLEAR of the cargo bay (Mode 3): bring the probe to the CAE's port");
    } else if (t.mode == wire::DcpMode::kAcquisition) {
      event("RESET: Mode 1, the payload back in the cargo bay");
    } else {
      event(fmt::format("Mode {} -> {}", static_cast<int>(p.mode), static_cast<int>(t.mode)));
    }
  }
  if (t.docked && !p.docked) {
    event(fmt::format("DOCKED: distance {:.3f} ft, angle {:.2f} deg", t.dock_distance_ft,
                      t.dock_angle_deg));
  }
  const auto now = static_cast<std::uint32_t>(t.collisions),
             before = static_cast<std::uint32_t>(p.collisions);
  for (int b = 0; b < wire::collision_bits::kCount; ++b) {
    const std::uint32_t bit = 1u << b;
    if ((now & bit) && !(before & bit))
      event(fmt::format("COLLISION {} begins", wire::CollisionName(b)));
    if (!(now & bit) && (before & bit))
      event(fmt::format("collision {} ends", wire::CollisionName(b)));
  }
  if (t.held && !p.held)
    event("HELD: the DCP holds the arm (the command collides): move away from the contact");
  if (!t.held && p.held) event("the arm follows again");
  if (t.finger_held && !p.finger_held) event("the finger stops on the bar");
  last_ = t;
}

}  // namespace rms::operator_station
