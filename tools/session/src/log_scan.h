#pragma once
// One pass over a session's log for its summary (docs/sessions.md
// "summary.json"): the DCP frames to believe first (docs/security.md "What
// the summary trusts"), then the telemetry they confirm, the hand
// controllers' modes, the processes' status runs, the control commands and
// their answers, the malfunctions and the frame numbers of every channel.
// Private to rms::session (session_summary.cc is its reader).
#include <array>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/operator_state_t.hpp"
#include "rms/session/session_log.h"
#include "rms/wire/collision_bits.h"
#include "rms/wire/control_word.h"
#include "rms/wire/frame_numbers.h"
#include "rms/wire/message_io.h"

#include "attempts.h"

namespace rms::session {

inline constexpr int kCollisionBits = wire::collision_bits::kCount;

// A DCP frame as logged: what confirms the telemetry of the same frame.
struct DcpFrameRecord {
  std::int64_t input_frame = -1;
  wire::ControlWord word;
  // Two different DCP frames of this number in the log, both with the
  // session's id and the DCP's pid: one is forged, and neither is believed.
  bool disputed = false;
};

// First pass: the session's own DCP frames (as logged, in the log's order),
// by frame number. The DCP numbers its frames upward, across restarts and
// restores, so the frames believed are the longest run of increasing numbers in the log's order; a
// frame off it -- a forgery far ahead or behind, with the DCP's own id and
// pid -- is left out (out_of_sequence), and its telemetry with it. Two
// different frames of one number mark that number disputed.
struct DcpFrames {
  std::map<std::int64_t, DcpFrameRecord> by_frame;
  std::int64_t out_of_sequence = 0;
};
DcpFrames BelieveDcpFrames(const std::vector<dcp_frame_t>& frames);
DcpFrames ReadDcpFrames(SessionLog& log);

// The hand controllers' modes over the session, from RMS_OPERATOR_STATE
// (docs/sessions.md "summary.json", "by_hand").
class HandControlLog {
 public:
  void Observe(const operator_state_t& m, double t_s) {
    if (m.source != operator_state_t::SOURCE_BY_HAND) return;
    seen_ = true;
    const int key = m.control_mode * 100 + m.command_frame * 10 + m.scale;
    if (key != last_key_) {
      static const char* kModes[3] = {"?", "single joint", "manual augmented"};
      static const char* kFrames[4] = {"?", "end effector", "orbiter", "payload"};
      static const char* kScales[4] = {"?", "coarse", "vernier",
                                       "fine"};  // operator_state_t SCALE_*
      changes_.push_back(
          {{"time_s", t_s},
           {"frame", m.frame},
           {"control_mode",
            kModes[m.control_mode >= 1 && m.control_mode <= 2 ? m.control_mode : 0]},
           {"command_frame",
            kFrames[m.command_frame >= 1 && m.command_frame <= 3 ? m.command_frame : 0]},
           {"scale", kScales[m.scale >= 1 && m.scale <= 3 ? m.scale : 0]}});
      last_key_ = key;
    }
    key_actions_ = std::max<std::int64_t>(key_actions_, m.key_actions);
    joint_limit_frames_ += m.joint_limits != 0;
    singular_frames_ += m.singular;
  }
  nlohmann::ordered_json Json() const {
    if (!seen_) return nullptr;
    return {{"control_changes", changes_},
            {"key_actions", key_actions_},
            {"joint_limit_frames", joint_limit_frames_},
            {"singular_frames", singular_frames_}};
  }

 private:
  bool seen_ = false;
  int last_key_ = -1;
  nlohmann::ordered_json changes_ = nlohmann::ordered_json::array();
  std::int64_t key_actions_ = 0, joint_limit_frames_ = 0, singular_frames_ = 0;
};

// The mission as the DCP's telemetry tells it: mode changes, collision runs,
// docking and the phases' boundaries (DCP frame numbers; -1: not reached).
class TelemetryLog {
 public:
  explicit TelemetryLog(double rate_hz = 30.0) : rate_hz_(rate_hz) {
    for (const char* name : wire::kCollisionNames) totals_[name] = {0, 0, 0};
  }
  // wall_s: the message's wall time, s from the session's first logged
  // message (-1 where there is no log: a run made in memory).
  void Observe(const dcp_telemetry_t& m, double wall_s) {
    ++frames_;
    // Session time (docs/sessions.md "Session time"): the operator frame it
    // answers over the frame rate.
    const double t_s = m.input_frame / rate_hz_;
    // (Phases and docking are each attempt's: AttemptLog.)
    if (m.mode != last_mode_) {
      if (last_mode_ != 0) {
        nlohmann::ordered_json e = {{"frame", m.frame}, {"time_s", t_s}};
        if (wall_s >= 0) e["wall_s"] = wall_s;
        e["from"] = last_mode_;
        e["to"] = m.mode;
        mode_changes.push_back(std::move(e));
      }
      last_mode_ = m.mode;
    }
    acquired = acquired || m.acquired;
    docked = docked || m.docked;
    held_frames += m.held;
    // Detrimental collisions only: the finger resting on the bar is the essential contact.
    const auto bits =
        wire::DetrimentalCollisions(static_cast<std::uint32_t>(m.collisions), m.finger_held, m.held,
                                    m.master_finger > m.slave_finger);
    for (int b = 0; b < kCollisionBits; ++b) {
      const bool on = bits & (1u << b), was = last_bits_ & (1u << b);
      if (on && !was) {
        run_start_s_[b] = t_s;
        run_start_wall_s_[b] = wall_s;
        run_frames_[b] = 0;
      }
      if (on) ++run_frames_[b];
      if (was && !on) EndRun(b, false);
    }
    last_bits_ = bits;
  }
  // Collisions still on at the end of the log; events in time order.
  void Finish() {
    for (int b = 0; b < kCollisionBits; ++b) {
      if (last_bits_ & (1u << b)) EndRun(b, true);
    }
    std::sort(collisions.begin(), collisions.end(), [](const auto& a, const auto& b) {
      return a["start_s"].template get<double>() < b["start_s"].template get<double>();
    });
  }
  nlohmann::ordered_json ByKind() const {
    nlohmann::ordered_json by_kind = nlohmann::ordered_json::object();
    for (const auto& [kind, t] : totals_) {
      by_kind[kind] = {{"events", static_cast<std::int64_t>(t[0])},
                       {"frames", static_cast<std::int64_t>(t[1])},
                       {"duration_s", t[2]}};
    }
    return by_kind;
  }
  std::int64_t frames() const { return frames_; }

  nlohmann::ordered_json mode_changes = nlohmann::ordered_json::array();
  nlohmann::ordered_json collisions = nlohmann::ordered_json::array();
  bool acquired = false, docked = false;
  std::int64_t held_frames = 0;

 private:
  // A run's session time: a frame period each of its frames (as the
  // attempts' collisions count it).
  void EndRun(int b, bool open) {
    const double dur = static_cast<double>(run_frames_[b]) / rate_hz_;
    nlohmann::ordered_json e = {{"kind", wire::kCollisionNames[b]},
                                {"start_s", run_start_s_[b]},
                                {"duration_s", dur},
                                {"frames", run_frames_[b]}};
    if (run_start_wall_s_[b] >= 0) e["wall_s"] = run_start_wall_s_[b];
    if (open) e["open"] = true;
    collisions.push_back(e);
    auto& tot = totals_[wire::kCollisionNames[b]];
    tot[0] += 1;
    tot[1] += run_frames_[b];
    tot[2] += dur;
  }
  std::map<std::string, std::array<double, 3>> totals_;  // events, frames, seconds; every kind
  std::array<double, kCollisionBits> run_start_s_{}, run_start_wall_s_{};
  std::array<std::int64_t, kCollisionBits> run_frames_{};
  std::uint32_t last_bits_ = 0;
  int last_mode_ = 0;
  std::int64_t frames_ = 0;
  double rate_hz_;
};

// Each process's runs (a restart after a fault is a new pid): the last
// counters each run reported on RMS_STATUS.
struct StatusRuns {
  std::map<std::string, std::map<int, std::map<std::string, std::int64_t>>> runs;
  std::map<std::string, int> last_pid;
  std::map<std::string, bool> final_seen;
};

// What one pass over the log finds, the session's own messages only.
struct LogScan {
  std::map<std::string, std::int64_t> by_channel;
  std::int64_t events = 0, first_us = -1, last_us = -1, malformed = 0;
  double session_s = 0;  // the session time its operator frames reach (the last one's end)
  wire::SequenceTracker input, dcp, esg;  // frame numbers as logged
  // The distinct numbers of the operator's and the ESG's frames, of those
  // not refused as far ahead: what the record holds (RecordJson), where a
  // number sent again after a resync is one frame, not a stale one.
  std::set<std::int64_t> input_logged, esg_logged;
  double rate_hz = 30.0;
  std::set<std::int64_t> telemetry_frames;  // believed
  std::set<std::int64_t> telemetry_logged;  // of the DCP's frames, whether believed or not
  int final_mode = 0;
  std::set<int> modes;
  TelemetryLog telemetry;
  HandControlLog hand;
  StatusRuns status;
  nlohmann::ordered_json control = nlohmann::ordered_json::array();
  // Each command's place in `control`, by its id (sender process, pid,
  // sequence): where its answers go (RMS_CONTROL_ANSWER).
  std::map<std::tuple<int, std::int32_t, std::int64_t>, std::size_t> control_index;
  AttemptLog* attempts = nullptr;
  std::string last_restore_name;
  std::int64_t answers_unmatched = 0;
  // docs/sessions.md "Malfunctions": each change of the malfunctions in
  // force, as the DCP's logged states show it, and those in force now.
  nlohmann::ordered_json malfunctions = nlohmann::ordered_json::array();
  std::vector<std::string> in_force;
};

// Why a telemetry message is not believed, as SenderCheck counts it, or
// nullptr when it is: it is believed only where the DCP frame of its number
// (believed, not disputed) says the same, and once a frame (`believed`: the
// frames whose telemetry was; docs/security.md "What the summary trusts").
const char* Disbelief(const dcp_telemetry_t& m, const std::map<std::int64_t, DcpFrameRecord>& dcp,
                      std::set<std::int64_t>* believed);

// The pass: every message of the session's own, against the DCP frames
// believed (`dcp`); each attempt's frames to `attempts`.
LogScan ScanLog(SessionLog& log, const std::map<std::int64_t, DcpFrameRecord>& dcp,
                AttemptLog* attempts);

}  // namespace rms::session
