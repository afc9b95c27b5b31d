#include "rms/dcp_model/dcp_telemetry.h"

namespace rms::dcp_model {

dcp_telemetry_t MakeTelemetry(const DcpStatus& st, const wire::DcpFrameData& out) {
  dcp_telemetry_t t{};
  t.frame = out.frame;
  t.send_time_us = out.send_time_us;
  t.input_frame = out.input_frame;
  t.input_send_time_us = out.input_send_time_us;
  t.mode = static_cast<std::int8_t>(st.mode);
  t.acquired = st.acquired;
  t.docked = st.docked;
  t.released = st.released;
  t.held = st.held;
  t.finger_held = st.finger_held;
  t.collisions = static_cast<std::int32_t>(st.collisions);
  t.slave_collisions = static_cast<std::int32_t>(st.slave_collisions);
  for (int i = 0; i < wire::kNumAcquisitionConditions; ++i) {
    t.acquisition_conditions[i] = st.acquisition[i];
    t.acquisition_margin_ft[i] = st.acquisition_margin_ft[i];
  }
  t.finger_gap_ft = st.finger_gap_ft;
  t.palm_to_bar_ft = st.palm_to_bar_ft;
  t.bay_clearance_ft = st.bay_clearance_ft;
  t.probe_in_envelope = st.probe_in_envelope;
  t.envelope_margin_ft = st.envelope_margin_ft;
  t.dock_distance_ft = st.dock_distance_ft;
  t.dock_angle_deg = st.dock_angle_deg;
  for (int k = 0; k < 3; ++k) {
    t.plane_valid[k] = (st.plane_valid >> k) & 1;
    for (int j = 0; j < 3; ++j) t.plane_n[3 * k + j] = st.planes[k].n_R[j];
    t.plane_d_ft[k] = st.planes[k].d_ft;
  }
  for (int i = 0; i < kNumJoints; ++i) {
    t.master_angles_deg[i] = st.master.angles_deg[i];
    t.slave_angles_deg[i] = st.slave.angles_deg[i];
  }
  t.master_shoulder_height_ft = st.master.shoulder_height_ft;
  t.slave_shoulder_height_ft = st.slave.shoulder_height_ft;
  t.master_finger = st.master.finger;
  t.slave_finger = st.slave.finger;
  for (int i = 0; i < 3; ++i) {
    t.p_RoA_R_ft[i] = st.X_RS2.translation()[i];
    t.p_RoPo_R_ft[i] = st.X_RP.translation()[i];
    for (int j = 0; j < 3; ++j) {
      t.R_RS2[3 * i + j] = st.X_RS2.linear()(i, j);
      t.R_RP[3 * i + j] = st.X_RP.linear()(i, j);
    }
  }
  return t;
}

}  // namespace rms::dcp_model
