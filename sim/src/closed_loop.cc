#include "rms/sim/closed_loop.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <deque>
#include <optional>
#include <random>

#include "rms/dcp_model/dcp_telemetry.h"
#include "rms/dcp_model/dynamic_collision_program.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/input_block.h"

#include "flight_log.h"

namespace rms::sim {

void ObserveFrame(const dcp_telemetry_t& tm, int frame, bool* colliding, ClosedLoopResult* r) {
  if (tm.mode >= wire::DcpMode::kAcquisition && tm.mode <= wire::DcpMode::kManoeuvring &&
      r->modes_entered[tm.mode] == 0 && frame > 0)
    r->modes_entered[tm.mode] = frame;
  if (tm.collisions != 0 && !*colliding) ++r->collision_events;
  *colliding = tm.collisions != 0;
  if (tm.docked && !r->docked) {
    r->docked = true;
    r->docked_frame = frame;
    r->dock_distance_ft = tm.dock_distance_ft;
    r->dock_angle_deg = tm.dock_angle_deg;
  }
  r->held_frames += tm.held;
  r->last = tm;
}

std::string TimeUpFailure(const ClosedLoopResult& r, double max_s) {
  char why[96];
  std::snprintf(why, sizeof why, "%s by %.0f s",
                r.modes_entered[2] == 0   ? "no acquisition"
                : r.modes_entered[3] == 0 ? "not out of the bay"
                                          : "not docked",
                max_s);
  return why;
}

namespace {

operator_station::AutopilotOptions Scaled(operator_station::AutopilotOptions o, double gain) {
  for (double* v :
       {&o.joint_rate_deg_s, &o.finger_rate_per_s, &o.descend_speed_ft_s, &o.lift_speed_ft_s,
        &o.transfer_speed_ft_s, &o.turn_rate_deg_s, &o.dock_speed_ft_s})
    *v *= gain;
  return o;
}

ClosedLoopResult Fly(const LabConfig& config, const VirtualSubject& subject, int max_frames,
                     std::vector<wire::OperatorInputs>* inputs) {
  ClosedLoopResult r;
  const int latency_frames = subject.latency_frames;
  operator_station::Autopilot pilot(config, Scaled(subject.autopilot, subject.rate_gain));
  std::mt19937_64 rng(subject.seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  // The tremor: a first-order Gauss-Markov wander of each joint's command
  // (correlation time kTremorTau_s), standard deviation tremor_deg.
  constexpr double kTremorTau_s = 1.0;
  const double a = std::exp(-1.0 / (kTremorTau_s * config.session.frame_rate_hz));
  const double kick = subject.tremor_deg * std::sqrt(1.0 - a * a);
  std::array<double, 6> wander{};
  bool colliding = false;
  dcp_model::DynamicCollisionProgram program(config);
  std::deque<dcp_telemetry_t> in_flight;
  std::optional<dcp_telemetry_t> seen;
  for (int f = 0; f < max_frames; ++f) {
    wire::OperatorInputs in = pilot.Step(seen ? &*seen : nullptr);
    if (subject.tremor_deg > 0) {
      for (int j = 0; j < 6; ++j) {
        wander[j] = a * wander[j] + kick * unit(rng);
        in.value[j] += wander[j];
      }
    }
    const auto words = wire::EncodeInputs(in, config.inputs, &r.dcp);
    const wire::OperatorInputs decoded = wire::DecodeInputs(words, config.inputs, &r.dcp);
    if (inputs) inputs->push_back(decoded);
    wire::DcpFrameData out = program.Step(decoded);
    out.frame = f;
    out.input_frame = f;
    dcp_telemetry_t tm = dcp_model::MakeTelemetry(program.status(), out);
    ObserveFrame(tm, f, &colliding, &r);
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

}  // namespace

ClosedLoopResult FlyVirtualSubject(const LabConfig& config, const VirtualSubject& subject,
                                   int max_frames) {
  return Fly(config, subject, max_frames, nullptr);
}

ClosedLoopResult FlyAutopilot(const LabConfig& config,
                              const operator_station::AutopilotOptions& options, int max_frames,
                              int latency_frames, std::vector<wire::OperatorInputs>* inputs) {
  VirtualSubject s;
  s.autopilot = options;
  s.latency_frames = latency_frames;
  return Fly(config, s, max_frames, inputs);
}

}  // namespace rms::sim
