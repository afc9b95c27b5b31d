#pragma once
// A session's attempts and the operator's scorecard for each
// (docs/sessions.md "Attempts", "Scorecard"), from the log alone: the start,
// each reset and each restore begins an attempt; each attempt has its phase
// durations, collisions and holds, outcome, docking figures, least
// clearances, time near each tolerance, and the operator's inputs.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rms/base/config.h"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/operator_state_t.hpp"

namespace rms::session {

class AttemptLog {
 public:
  explicit AttemptLog(const LabConfig& config) : config_(config) {}
  // A believed DCP frame's telemetry; reset: its control word's reset bit;
  // t_s: its session time.
  void ObserveFrame(const dcp_telemetry_t& m, bool reset, double t_s);
  // A restore the DCP logged (RMS_DCP_STATE RESTORE): the next frame starts
  // an attempt.
  void ObserveRestore(const std::string& what) {
    pending_restore_ = what.empty() ? "restore" : what;
  }
  // The operator station's state a frame (inputs, devices).
  void ObserveOperator(const operator_state_t& m);
  // A restart of a process (counted in the totals and the current attempt).
  void ObserveRestart() { ++restarts_; }

  // {"attempts": [...], "totals": {...}}.
  nlohmann::ordered_json Json() const;

 private:
  struct Run {  // a collision kind's or a hold's run of frames
    std::int64_t events = 0, frames = 0;
  };
  struct Attempt {
    int index = 0;
    std::string started_by;  // "start", "reset", "restore"
    std::string restored;    // the restore's checkpoint name, if any
    int start_mode = 1;
    double start_s = 0, last_s = 0;
    std::int64_t start_frame = -1, last_frame = -1, frames = 0;
    double t_acquired = -1, t_clear = -1, t_envelope = -1, t_docked = -1;
    nlohmann::ordered_json docking = nullptr;
    double best_dock_distance_ft = -1, best_dock_angle_deg = -1;
    std::vector<Run> collisions;  // by collision bit
    Run held, finger_held;
    std::uint32_t last_bits = 0;
    bool last_held = false, last_finger_held = false;
    double least_ee_payload_ft = -1, least_payload_bay_ft = -1, least_payload_cae_ft = -1;
    std::int64_t near_d3y = 0, near_tpob = 0, near_dock_distance = 0, near_dock_angle = 0;
    // Inputs (by hand).
    std::int64_t moving_frames = 0, multi_axis_frames = 0, reversals = 0, rate_limited_frames = 0;
    std::vector<std::int64_t> device_actions_start;  // the devices' counts when the attempt began
    std::vector<std::int64_t> device_actions_now;
    std::vector<std::string> device_names;
    int last_sign[6] = {0, 0, 0, 0, 0, 0};
    bool finger_closing = false;
    std::int64_t closures = 0, closures_acquired = 0;
  };
  void Begin(const dcp_telemetry_t& m, const std::string& by, double t_s);
  void Clearances(const dcp_telemetry_t& m, Attempt* a) const;
  nlohmann::ordered_json AttemptJson(const Attempt& a) const;

  const LabConfig config_;  // a copy: the summary builds the log from a temporary
  std::vector<Attempt> attempts_;
  std::string pending_restore_;
  bool last_reset_ = false;
  std::int64_t restarts_ = 0;
};

}  // namespace rms::session
