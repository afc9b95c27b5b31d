#include "rms/operator_station/telemetry_check.h"

#include <cmath>
#include <initializer_list>

#include "rms/wire/collision_bits.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/frame_numbers.h"

namespace rms::operator_station {

std::optional<Counter> TelemetryProblem(const dcp_telemetry_t& m) {
  using wire::kMaxFrameNumber, wire::kMaxSendTimeUs;  // docs/protocol.md "Frame numbers"
  if (m.frame < 0 || m.input_frame < 0 || m.frame >= kMaxFrameNumber ||
      m.input_frame >= kMaxFrameNumber)
    return Counter::kDroppedTelemetryFrame;
  if (m.send_time_us < 0 || m.send_time_us >= kMaxSendTimeUs || m.input_send_time_us < 0 ||
      m.input_send_time_us >= kMaxSendTimeUs)
    return Counter::kDroppedTelemetryTime;
  if (m.mode < wire::DcpMode::kAcquisition || m.mode > wire::DcpMode::kManoeuvring)
    return Counter::kDroppedTelemetryMode;
  const std::uint32_t defined = (1u << wire::collision_bits::kCount) - 1;
  if ((static_cast<std::uint32_t>(m.collisions) & ~defined) ||
      (static_cast<std::uint32_t>(m.slave_collisions) & ~defined))
    return Counter::kDroppedTelemetryCollisionBits;
  bool finite = true;
  auto all = [&](const double* v, int n) {
    for (int i = 0; i < n; ++i) finite = finite && std::isfinite(v[i]);
  };
  all(m.acquisition_margin_ft, 6);
  for (double x : {m.finger_gap_ft, m.palm_to_bar_ft, m.bay_clearance_ft, m.envelope_margin_ft,
                   m.dock_distance_ft, m.dock_angle_deg, m.master_shoulder_height_ft,
                   m.slave_shoulder_height_ft, m.master_finger, m.slave_finger})
    finite = finite && std::isfinite(x);
  all(m.plane_n, 9);
  all(m.plane_d_ft, 3);
  all(m.master_angles_deg, 6);
  all(m.slave_angles_deg, 6);
  all(m.p_RoA_R_ft, 3);
  all(m.R_RS2, 9);
  all(m.p_RoPo_R_ft, 3);
  all(m.R_RP, 9);
  if (!finite) return Counter::kDroppedTelemetryNonFinite;
  return std::nullopt;
}

}  // namespace rms::operator_station
