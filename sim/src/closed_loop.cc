#include "rms/sim/closed_loop.h"

#include <deque>
#include <optional>

#include "rms/dynamics_proc/dynamic_collision_program.h"
#include "rms/dynamics_proc/dynamics_proc.h"
#include "rms/wire/input_block.h"

namespace rms::sim {

ClosedLoopResult FlyAutopilot(const LabConfig& config,
                              const operator_station::AutopilotOptions& options, int max_frames,
                              int latency_frames, std::vector<wire::OperatorInputs>* inputs) {
  ClosedLoopResult r;
  operator_station::Autopilot pilot(config, options);
  dynamics_proc::DynamicCollisionProgram program(config);
  std::deque<dcp_telemetry_t> in_flight;
  std::optional<dcp_telemetry_t> seen;
  for (int f = 0; f < max_frames; ++f) {
    const wire::OperatorInputs in = pilot.Step(seen ? &*seen : nullptr);
    const auto words = wire::EncodeInputs(in, config.inputs, &r.dcp);
    const wire::OperatorInputs decoded = wire::DecodeInputs(words, config.inputs, &r.dcp);
    if (inputs) inputs->push_back(decoded);
    wire::DcpFrameData out = program.Step(decoded);
    out.frame = f;
    out.input_frame = f;
    dcp_telemetry_t tm = dynamics_proc::MakeTelemetry(program.status(), out);
    if (tm.mode >= 1 && tm.mode <= 3 && r.modes_entered[tm.mode] == 0 && f > 0)
      r.modes_entered[tm.mode] = f;
    if (tm.docked && !r.docked) {
      r.docked = true;
      r.dock_distance_ft = tm.dock_distance_ft;
      r.dock_angle_deg = tm.dock_angle_deg;
    }
    r.held_frames += tm.held;
    r.last = tm;
    in_flight.push_back(tm);
    while (static_cast<int>(in_flight.size()) > latency_frames) {
      seen = in_flight.front();
      in_flight.pop_front();
    }
    if (latency_frames == 0) seen = tm;
    r.frames = f + 1;
    if (pilot.failed()) {
      r.failure = pilot.failure();
      break;
    }
    if (pilot.docked() && r.docked) break;
  }
  if (!r.docked && r.failure.empty()) r.failure = "frame limit";
  r.time_s = r.frames / config.session.frame_rate_hz;
  r.autopilot = pilot.counters();
  return r;
}

}  // namespace rms::sim
