#include "attempts.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "rms/wire/collision_bits.h"
#include "rms/wire/dcp_mode.h"

namespace rms::session {

namespace {

constexpr double kNear =
    0.10;  // "near a tolerance": within 10 % of it, either side (docs/sessions.md "Scorecard")

Eigen::Vector3d V(const double* p) { return {p[0], p[1], p[2]}; }

// The payload's body, a cylinder along y_P (docs/scene.md), its extent
// from its centre along the unit vector n.
double Extent(const Eigen::Vector3d& n, const Eigen::Vector3d& axis, double r, double hl) {
  const double c = std::min(1.0, std::abs(n.dot(axis)));
  return r * std::sqrt(1.0 - c * c) + hl * c;
}

bool Near(double value, double limit) {
  return limit > 0 && std::abs(value - limit) <= kNear * limit;
}

nlohmann::ordered_json OrNull(double v) {
  return v < 0 ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(v);
}

}  // namespace

void AttemptLog::Begin(const dcp_telemetry_t& m, const std::string& by, double t_s) {
  Attempt a;
  a.index = static_cast<int>(attempts_.size()) + 1;
  a.started_by = by;
  a.start_mode = m.mode;
  a.start_s = a.last_s = t_s;
  a.start_frame = m.frame;
  a.collisions.assign(wire::collision_bits::kCount, Run{});
  if (!attempts_.empty()) {  // the devices' counts carry on
    a.device_names = attempts_.back().device_names;
    a.device_actions_start = a.device_actions_now = attempts_.back().device_actions_now;
  }
  attempts_.push_back(std::move(a));
}

void AttemptLog::Clearances(const dcp_telemetry_t& m, Attempt* a) const {
  const PayloadConfig& p = config_.payload;
  const double r = p.diameter_ft / 2, hl = p.length_ft / 2;
  const Eigen::Vector3d c = V(m.p_RoPo_R_ft);
  const Eigen::Vector3d axis(m.R_RP[1], m.R_RP[4], m.R_RP[7]);  // y_P in R
  auto least = [](double* best, double d) {
    d = std::max(0.0, d);
    if (*best < 0 || d < *best) *best = d;
  };
  if (m.mode == wire::DcpMode::kAcquisition) {
    // Point A to the payload's surface.
    const Eigen::Vector3d q = V(m.p_RoA_R_ft) - c;
    const double along = std::abs(q.dot(axis)) - hl;
    const double radial = (q - q.dot(axis) * axis).norm() - r;
    least(&a->least_ee_payload_ft, std::hypot(std::max(along, 0.0), std::max(radial, 0.0)));
  } else if (m.mode == wire::DcpMode::kExtraction) {
    // The payload to the bay's floor, walls and bulkheads (x 0..L, y +-w/2, z -D..0 in R).
    const ShuttleConfig& s = config_.shuttle;
    const struct {
      Eigen::Vector3d p0, n;
    } planes[] = {{{0, 0, -s.bay_depth_ft}, {0, 0, 1}},
                  {{0, -s.bay_width_ft / 2, 0}, {0, 1, 0}},
                  {{0, s.bay_width_ft / 2, 0}, {0, -1, 0}},
                  {{0, 0, 0}, {1, 0, 0}},
                  {{s.bay_length_ft, 0, 0}, {-1, 0, 0}}};
    if (c.z() - Extent({0, 0, 1}, axis, r, hl) < 0) {  // some of it still below the sills
      for (const auto& pl : planes)
        least(&a->least_payload_bay_ft, pl.n.dot(c - pl.p0) - Extent(pl.n, axis, r, hl));
    }
  } else if (m.mode == wire::DcpMode::kManoeuvring) {
    // The payload's body to the CAE's port face (face c, y_C = 0, facing -y_C).
    const Eigen::Vector3d n = -config_.cae.R_RC.col(1);
    least(&a->least_payload_cae_ft, n.dot(c - config_.cae.p_RoCo_R_ft) - Extent(n, axis, r, hl));
  }
}

void AttemptLog::ObserveFrame(const dcp_telemetry_t& m, bool reset, double t_s) {
  if (attempts_.empty())
    Begin(m, "start", t_s);
  else if (reset && !last_reset_)
    Begin(m, "reset", t_s);
  else if (!pending_restore_.empty()) {
    Begin(m, "restore", t_s);
    attempts_.back().restored = pending_restore_;
  }
  pending_restore_.clear();
  last_reset_ = reset;
  Attempt& a = attempts_.back();
  a.last_s = t_s;
  a.last_frame = m.frame;
  ++a.frames;
  if (m.mode == wire::DcpMode::kExtraction && a.t_acquired < 0 &&
      a.start_mode == wire::DcpMode::kAcquisition)
    a.t_acquired = t_s;
  if (m.mode == wire::DcpMode::kManoeuvring && a.t_clear < 0 &&
      a.start_mode <= wire::DcpMode::kExtraction)
    a.t_clear = t_s;
  if (m.mode == wire::DcpMode::kManoeuvring && m.probe_in_envelope && a.t_envelope < 0)
    a.t_envelope = t_s;
  if (m.docked && a.t_docked < 0) {
    a.t_docked = t_s;
    if (a.t_envelope < 0) a.t_envelope = t_s;
    a.docking = {{"frame", m.frame},
                 {"time_s", t_s},
                 {"distance_ft", m.dock_distance_ft},
                 {"angle_deg", m.dock_angle_deg},
                 {"within_tolerance", m.dock_distance_ft <= config_.dcp.dock_distance_ft &&
                                          m.dock_angle_deg <= config_.dcp.dock_angle_deg}};
  }
  if (m.mode == wire::DcpMode::kManoeuvring &&
      (a.best_dock_distance_ft < 0 || m.dock_distance_ft < a.best_dock_distance_ft)) {
    a.best_dock_distance_ft = m.dock_distance_ft;
    a.best_dock_angle_deg = m.dock_angle_deg;
  }
  // Detrimental collisions only: the finger resting on the bar is the essential contact.
  const auto bits =
      wire::DetrimentalCollisions(static_cast<std::uint32_t>(m.collisions), m.finger_held, m.held,
                                  m.master_finger > m.slave_finger);
  for (int b = 0; b < wire::collision_bits::kCount; ++b) {
    if (!(bits & (1u << b))) continue;
    ++a.collisions[b].frames;
    if (!(a.last_bits & (1u << b))) ++a.collisions[b].events;
  }
  a.last_bits = bits;
  if (m.held) a.held.events += !a.last_held, ++a.held.frames;
  if (m.finger_held) a.finger_held.events += !a.last_finger_held, ++a.finger_held.frames;
  a.last_held = m.held;
  a.last_finger_held = m.finger_held;
  Clearances(m, &a);
  if (m.mode == wire::DcpMode::kAcquisition) {
    a.near_d3y += Near(m.finger_gap_ft, config_.dcp.d3y_ft);
    a.near_tpob += Near(std::abs(m.palm_to_bar_ft), config_.dcp.tpob_ft);
  } else if (m.mode == wire::DcpMode::kManoeuvring && !m.docked) {
    a.near_dock_distance += Near(m.dock_distance_ft, config_.dcp.dock_distance_ft);
    a.near_dock_angle += Near(m.dock_angle_deg, config_.dcp.dock_angle_deg);
  }
  // A finger closure (the lever past half way) in Mode 1, and whether it
  // acquired before the finger opened again.
  if (m.mode == wire::DcpMode::kAcquisition && !a.finger_closing && m.master_finger >= 0.5) {
    a.finger_closing = true;
    ++a.closures;
  } else if (a.finger_closing && m.mode == wire::DcpMode::kExtraction) {
    ++a.closures_acquired;
    a.finger_closing = false;
  } else if (a.finger_closing && m.master_finger < 0.5) {
    a.finger_closing = false;
  }
}

void AttemptLog::ObserveOperator(const operator_state_t& m) {
  if (attempts_.empty() || m.source != operator_state_t::SOURCE_BY_HAND) return;
  Attempt& a = attempts_.back();
  int moving = 0;
  for (int i = 0; i < 6; ++i) {
    const int sign = m.hand_rate[i] > 1e-9 ? 1 : m.hand_rate[i] < -1e-9 ? -1 : 0;
    if (sign == 0) continue;
    ++moving;
    if (a.last_sign[i] != 0 && sign != a.last_sign[i]) ++a.reversals;
    a.last_sign[i] = sign;
  }
  a.moving_frames += moving > 0;
  a.multi_axis_frames += moving > 1;
  a.rate_limited_frames += m.rate_limited;
  const std::size_t n = std::min<std::size_t>(m.device_names.size(), m.device_actions.size());
  a.device_names.assign(m.device_names.begin(), m.device_names.begin() + n);
  a.device_actions_now.assign(m.device_actions.begin(), m.device_actions.begin() + n);
  a.device_actions_start.resize(n, 0);
}

nlohmann::ordered_json AttemptLog::AttemptJson(const Attempt& a) const {
  const double rate = config_.session.frame_rate_hz;
  const std::size_t i = static_cast<std::size_t>(a.index - 1);
  const double end_s = i + 1 < attempts_.size() ? attempts_[i + 1].start_s : a.last_s + 1.0 / rate;
  auto span = [](double from, double to) {
    return from < 0 || to < 0 ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(to - from);
  };
  const double acq_from = a.start_mode == wire::DcpMode::kAcquisition ? a.start_s : -1;
  const double ext_from = a.start_mode == wire::DcpMode::kExtraction ? a.start_s : a.t_acquired;
  const double man_from = a.start_mode == wire::DcpMode::kManoeuvring ? a.start_s : a.t_clear;
  nlohmann::ordered_json j;
  j["index"] = a.index;
  j["started_by"] = a.started_by;
  if (!a.restored.empty()) j["restored"] = a.restored;
  j["started_in_mode"] = a.start_mode;
  j["start_s"] = a.start_s;
  j["end_s"] = end_s;
  j["duration_s"] = end_s - a.start_s;
  j["frames"] = a.frames;
  j["first_frame"] = a.start_frame;
  j["last_frame"] = a.last_frame;
  j["outcome"] = a.t_docked >= 0                              ? "docked"
                 : a.t_clear >= 0                             ? "cleared the bay"
                 : a.t_acquired >= 0                          ? "acquired"
                 : a.start_mode > wire::DcpMode::kAcquisition ? "not docked"
                                                              : "not acquired";
  j["reached_s"] = {{"acquired", OrNull(a.t_acquired)},
                    {"clear_of_bay", OrNull(a.t_clear)},
                    {"in_envelope", OrNull(a.t_envelope)},
                    {"docked", OrNull(a.t_docked)}};
  j["phase_durations_s"] = {{"acquisition", span(acq_from, a.t_acquired)},
                            {"extraction", span(ext_from, a.t_clear)},
                            {"maneuvering", span(man_from, a.t_envelope)},
                            {"docking", span(a.t_envelope, a.t_docked)}};
  j["docking"] = a.docking;
  j["closest_to_docking"] = a.best_dock_distance_ft < 0
                                ? nlohmann::ordered_json(nullptr)
                                : nlohmann::ordered_json{{"distance_ft", a.best_dock_distance_ft},
                                                         {"angle_deg", a.best_dock_angle_deg}};
  nlohmann::ordered_json col = nlohmann::ordered_json::object();
  std::int64_t col_events = 0;
  for (int b = 0; b < wire::collision_bits::kCount; ++b) {
    const Run& r = a.collisions[b];
    col_events += r.events;
    if (r.events)
      col[wire::CollisionName(b)] = {
          {"events", r.events}, {"frames", r.frames}, {"duration_s", r.frames / rate}};
  }
  j["collisions"] = {{"events", col_events}, {"by_kind", col}};
  j["holds"] = {{"arm",
                 {{"events", a.held.events},
                  {"frames", a.held.frames},
                  {"duration_s", a.held.frames / rate}}},
                {"finger",
                 {{"events", a.finger_held.events},
                  {"frames", a.finger_held.frames},
                  {"duration_s", a.finger_held.frames / rate}}}};
  nlohmann::ordered_json devices = nlohmann::ordered_json::object();
  for (std::size_t d = 0; d < a.device_names.size() && d < a.device_actions_now.size(); ++d) {
    devices[a.device_names[d]] =
        a.device_actions_now[d] -
        (d < a.device_actions_start.size() ? a.device_actions_start[d] : 0);
  }
  j["scorecard"] = {
      {"task_time_s", a.t_docked < 0 ? nlohmann::ordered_json(nullptr)
                                     : nlohmann::ordered_json(a.t_docked - a.start_s)},
      {"least_clearance_ft",
       {{"end_effector_to_payload", OrNull(a.least_ee_payload_ft)},
        {"payload_to_bay", OrNull(a.least_payload_bay_ft)},
        {"payload_to_cae", OrNull(a.least_payload_cae_ft)}}},
      {"near_tolerance_s",
       {{"d3y", a.near_d3y / rate},
        {"tpob", a.near_tpob / rate},
        {"dock_distance", a.near_dock_distance / rate},
        {"dock_angle", a.near_dock_angle / rate}}},
      {"inputs",
       {{"actions_by_device", devices},
        {"reversals", a.reversals},
        {"moving_s", a.moving_frames / rate},
        {"multi_axis_share",
         a.moving_frames ? static_cast<double>(a.multi_axis_frames) / a.moving_frames : 0.0},
        {"rate_limited_s", a.rate_limited_frames / rate}}},
      {"finger_closures", a.closures},
      {"closures_not_acquiring", a.closures - a.closures_acquired}};
  return j;
}

nlohmann::ordered_json AttemptLog::Json() const {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const Attempt& a : attempts_) list.push_back(AttemptJson(a));
  nlohmann::ordered_json t;
  t["attempts"] = attempts_.size();
  std::int64_t resets = 0, restores = 0, docked = 0, collisions = 0;
  double duration = 0;
  for (const auto& a : list) {
    resets += a["started_by"] == "reset";
    restores += a["started_by"] == "restore";
    docked += a["outcome"] == "docked";
    collisions += a["collisions"]["events"].get<std::int64_t>();
    duration += a["duration_s"].get<double>();
  }
  t["resets"] = resets;
  t["restores"] = restores;
  t["restarts"] = restarts_;
  t["attempts_docked"] = docked;
  t["collisions"] = collisions;
  t["duration_s"] = duration;
  return {{"attempts", list}, {"totals", t}};
}

}  // namespace rms::session
