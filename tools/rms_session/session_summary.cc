#include "session_summary.h"

#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <algorithm>
#include <map>
#include <set>
#include <ctime>
#include <unistd.h>

#include "rms/channels.h"
#include "rms/config.h"
#include "rms/collision_bits.h"
#include "rms/check.h"
#include "rms/control_word.h"
#include "rms/counters.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/message_io.h"
#include "rms/operator_input_t.hpp"
#include "rms/operator_state_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/lcm_interface.h"
#include "rms/version.h"

namespace fs = std::filesystem;

namespace rms::session {

namespace {

nlohmann::json ReadJson(const fs::path& p) {
  std::ifstream f(p);
  if (!f) return nlohmann::json::object();
  try {
    return nlohmann::json::parse(f);
  } catch (const std::exception&) {
    return nlohmann::json::object();
  }
}

std::int64_t Counter(const nlohmann::json& stats, const std::string& name) {
  if (!stats.contains("counters")) return 0;
  const auto& c = stats["counters"];
  return c.contains(name) ? c[name].get<std::int64_t>() : 0;
}

std::int64_t SumPrefix(const nlohmann::json& stats, const std::string& prefix) {
  std::int64_t s = 0;
  if (!stats.contains("counters")) return 0;
  for (auto it = stats["counters"].begin(); it != stats["counters"].end(); ++it) {
    if (it.key().rfind(prefix, 0) == 0) s += it.value().get<std::int64_t>();
  }
  return s;
}

constexpr int kCollisionBits = collision_bits::kCount;

// The hand controllers' modes over the session, from RMS_OPERATOR_STATE
// (docs/sessions.md "summary.json", "by_hand").
class HandControlLog {
 public:
  void Observe(const operator_state_t& m, double t_s) {
    if (m.source != operator_state_t::SOURCE_BY_HAND) return;
    seen_ = true;
    const int key = m.control_mode * 100 + m.command_frame * 10 + m.vernier;
    if (key != last_key_) {
      static const char* kModes[3] = {"?", "single joint", "manual augmented"};
      static const char* kFrames[4] = {"?", "end effector", "orbiter", "payload"};
      changes_.push_back({{"time_s", t_s},
                          {"frame", m.frame},
                          {"control_mode", kModes[m.control_mode >= 1 && m.control_mode <= 2 ? m.control_mode : 0]},
                          {"command_frame", kFrames[m.command_frame >= 1 && m.command_frame <= 3 ? m.command_frame : 0]},
                          {"scale", m.vernier ? "vernier" : "coarse"}});
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

}  // namespace

std::string BaseChannel(const std::string& channel) {
  for (const char* base : {channels::kOperatorInput, channels::kOperatorState, channels::kWindowKeys,
                           channels::kDcpTelemetry, channels::kDcpFrame, channels::kEsgFrame, channels::kStatus,
                           channels::kControl}) {
    if (channel.rfind(base, 0) == 0) return base;
  }
  return channel;
}

nlohmann::ordered_json Summarize(const std::string& dir) {
  const fs::path root(dir);
  const fs::path log_path = root / "lcmlog";
  lcm::LogFile log(log_path.string(), "r");
  if (!log.good()) throw InputError("cannot read the session's LCM log '" + log_path.string() + "'");

  std::map<std::string, std::int64_t> by_channel;
  std::int64_t events = 0, first_us = -1, last_us = -1;
  SequenceTracker logged_input, logged_dcp, logged_esg;
  std::int64_t malformed = 0;
  int final_mode = 0;
  std::set<int> modes;
  std::map<std::string, bool> final_status_seen;
  // Each process's runs (a restart after a fault is a new pid): the last
  // counters each run reported on RMS_STATUS.
  std::map<std::string, std::map<int, std::map<std::string, std::int64_t>>> status_runs;
  std::map<std::string, int> last_pid;
  // From the DCP's telemetry: mode changes, collision runs, docking.
  nlohmann::ordered_json mode_changes = nlohmann::ordered_json::array();
  nlohmann::ordered_json collision_events = nlohmann::ordered_json::array();
  std::map<std::string, std::array<double, 3>> collision_totals;  // events, frames, seconds; every kind
  for (const char* name : kCollisionNames) collision_totals[name] = {0, 0, 0};
  std::array<std::int64_t, kCollisionBits> run_start_us{};
  std::array<std::int64_t, kCollisionBits> run_frames{};
  std::uint32_t last_bits = 0;
  int last_mode = 0;
  bool acquired = false, docked = false;
  std::int64_t held_frames = 0, telemetry_frames = 0, prev_us = 0;
  nlohmann::ordered_json docking = nullptr;
  // Phase boundaries, DCP frame numbers (-1: not reached): the last start of
  // Mode 1 (the session's start or a reset), acquisition (1 -> 2), clear of
  // the bay (2 -> 3), the probe first in the docking envelope, docked.
  std::int64_t f_start = -1, f_acquired = -1, f_clear = -1, f_envelope = -1, f_docked = -1;
  HandControlLog hand;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    ++events;
    if (first_us < 0) first_us = ev->timestamp;
    last_us = ev->timestamp;
    const std::string base = BaseChannel(ev->channel);
    ++by_channel[ev->channel];
    if (base == channels::kOperatorState) {
      operator_state_t m;
      if (SafeDecode(ev->data, ev->datalen, 1024, &m) == DecodeError::kNone) hand.Observe(m, (ev->timestamp - first_us) * 1e-6);
      else ++malformed;
    } else if (base == channels::kOperatorInput) {
      operator_input_t m;
      if (SafeDecode(ev->data, ev->datalen, 1024, &m) == DecodeError::kNone) logged_input.Accept(m.frame);
      else ++malformed;
    } else if (base == channels::kDcpFrame) {
      dcp_frame_t m;
      if (SafeDecode(ev->data, ev->datalen, 1024, &m) == DecodeError::kNone) {
        logged_dcp.Accept(m.frame);
        try {
          final_mode = UnpackControlWord(m.control_word).mode;
          modes.insert(final_mode);
        } catch (const InputError&) {
          ++malformed;
        }
      } else {
        ++malformed;
      }
    } else if (base == channels::kDcpTelemetry) {
      dcp_telemetry_t m{};
      if (SafeDecode(ev->data, ev->datalen, 4096, &m) != DecodeError::kNone) {
        ++malformed;
        continue;
      }
      ++telemetry_frames;
      const double t_s = (ev->timestamp - first_us) * 1e-6;
      if (f_start < 0 || (m.mode == 1 && last_mode != 1)) {
        f_start = m.frame;
        f_acquired = f_clear = f_envelope = f_docked = -1;
      }
      if (m.mode == 2 && last_mode == 1) f_acquired = m.frame;
      if (m.mode == 3 && last_mode == 2) f_clear = m.frame;
      if (m.mode == 3 && m.probe_in_envelope && f_envelope < 0) f_envelope = m.frame;
      if (m.docked && f_docked < 0) f_docked = m.frame;
      if (m.mode != last_mode) {
        if (last_mode != 0) {
          mode_changes.push_back({{"frame", m.frame}, {"time_s", t_s}, {"from", last_mode}, {"to", m.mode}});
        }
        last_mode = m.mode;
      }
      acquired = acquired || m.acquired;
      if (m.docked && !docked) {
        docking = {{"frame", m.frame}, {"time_s", t_s}, {"distance_ft", m.dock_distance_ft},
                   {"angle_deg", m.dock_angle_deg}};
      }
      docked = docked || m.docked;
      held_frames += m.held;
      const auto bits = static_cast<std::uint32_t>(m.collisions);
      for (int b = 0; b < kCollisionBits; ++b) {
        const bool on = bits & (1u << b), was = last_bits & (1u << b);
        if (on && !was) {
          run_start_us[b] = ev->timestamp;
          run_frames[b] = 0;
        }
        if (on) ++run_frames[b];
        if (was && !on) {
          const double dur = (prev_us - run_start_us[b]) * 1e-6;
          collision_events.push_back({{"kind", kCollisionNames[b]},
                                      {"start_s", (run_start_us[b] - first_us) * 1e-6},
                                      {"duration_s", dur},
                                      {"frames", run_frames[b]}});
          auto& tot = collision_totals[kCollisionNames[b]];
          tot[0] += 1;
          tot[1] += run_frames[b];
          tot[2] += dur;
        }
      }
      last_bits = bits;
      prev_us = ev->timestamp;
    } else if (base == channels::kEsgFrame) {
      esg_frame_t m;
      if (SafeDecode(ev->data, ev->datalen, 1024, &m) == DecodeError::kNone) logged_esg.Accept(m.frame);
      else ++malformed;
    } else if (base == channels::kStatus) {
      process_status_t m;
      if (SafeDecode(ev->data, ev->datalen, 1 << 20, &m) == DecodeError::kNone) {
        if (m.final) final_status_seen[m.process] = true;
        auto& run = status_runs[m.process][m.pid];
        for (int i = 0; i < m.num_counters; ++i) run[m.counter_names[i]] = m.counter_values[i];
        last_pid[m.process] = m.pid;
      } else {
        ++malformed;
      }
    }
  }

  // Collisions still on at the end of the log.
  for (int b = 0; b < kCollisionBits; ++b) {
    if (last_bits & (1u << b)) {
      const double dur = (prev_us - run_start_us[b]) * 1e-6;
      collision_events.push_back({{"kind", kCollisionNames[b]}, {"start_s", (run_start_us[b] - first_us) * 1e-6},
                                  {"duration_s", dur}, {"frames", run_frames[b]}, {"open", true}});
      auto& tot = collision_totals[kCollisionNames[b]];
      tot[0] += 1;
      tot[1] += run_frames[b];
      tot[2] += dur;
    }
  }

  std::sort(collision_events.begin(), collision_events.end(),
            [](const auto& a, const auto& b) { return a["start_s"].template get<double>() < b["start_s"].template get<double>(); });

  std::map<std::string, nlohmann::json> stats;
  for (const char* p : {"operator_station", "dynamics_proc", "scene_proc", "esg_renderer"}) {
    stats[p] = ReadJson(root / "stats" / (std::string(p) + ".json"));
    // The stats file is the last run's; a run that ended in a fault (killed,
    // restarted by the launcher) left its counts on RMS_STATUS in the log:
    // they are added (counts only: not the mode, not latency percentiles).
    for (const auto& [pid, counters] : status_runs[p]) {
      if (pid == last_pid[p]) continue;
      if (!stats[p].contains("counters")) stats[p]["counters"] = nlohmann::json::object();
      for (const auto& [k, v] : counters) {
        if (k == "mode" || k.rfind("latency.", 0) == 0) continue;
        stats[p]["counters"][k] = stats[p]["counters"].value(k, std::int64_t{0}) + v;
      }
    }
  }
  const auto& op = stats["operator_station"];
  const auto& dcp = stats["dynamics_proc"];
  const auto& scene = stats["scene_proc"];
  const auto& esg = stats["esg_renderer"];

  nlohmann::ordered_json j;
  j["session"] = fs::absolute(root).lexically_normal().filename().string();
  if (j["session"].get<std::string>().empty()) j["session"] = fs::absolute(root).parent_path().filename().string();
  j["duration_s"] = first_us >= 0 ? (last_us - first_us) * 1e-6 : 0.0;
  j["final_mode"] = final_mode;
  j["modes_seen"] = std::vector<int>(modes.begin(), modes.end());
  j["acquired"] = acquired;
  j["docked"] = docked;
  j["docking"] = docking;
  // Phase durations in session time (DCP frames over the frame rate), so
  // they do not depend on how fast the session ran.
  double rate_hz = 30.0;
  try {
    rate_hz = LoadConfig((root / "config.toml").string()).session.frame_rate_hz;
  } catch (const std::exception&) {
  }
  auto span = [&](std::int64_t a, std::int64_t b) -> nlohmann::ordered_json {
    if (a < 0 || b < 0) return nullptr;
    return static_cast<double>(b - a) / rate_hz;
  };
  j["phase_durations_s"] = {{"acquisition", span(f_start, f_acquired)},
                            {"extraction", span(f_acquired, f_clear)},
                            {"maneuvering", span(f_clear, f_envelope >= 0 ? f_envelope : f_docked)},
                            {"docking", span(f_envelope >= 0 ? f_envelope : f_docked, f_docked)}};
  if (docked && docking.is_object()) {
    try {
      const LabConfig c = LoadConfig((root / "config.toml").string());
      docking["within_tolerance"] = docking["distance_ft"].get<double>() <= c.dcp.dock_distance_ft &&
                                    docking["angle_deg"].get<double>() <= c.dcp.dock_angle_deg;
      j["docking"] = docking;
    } catch (const std::exception&) {
    }
  }
  {
    std::ifstream pilot((root / "run" / "pilot").string());
    std::string who;
    if (pilot >> who) j["pilot"] = who;
  }
  {
    // Processes the launcher restarted after a fault (docs/sessions.md
    // "Faults"): run/restarts, one line "NAME N EXIT_CODE DOWN_AT READY_AT".
    nlohmann::ordered_json restarts = nlohmann::ordered_json::array();
    std::ifstream f((root / "run" / "restarts").string());
    std::string name;
    int n = 0, rc = 0;
    double down = 0, ready = 0;
    while (f >> name >> n >> rc >> down >> ready) {
      restarts.push_back({{"process", name},
                          {"restart", n},
                          {"exit_code", rc},
                          {"signal", rc > 128 ? rc - 128 : 0},
                          {"restart_s", ready - down}});
    }
    j["restarts"] = restarts;
  }
  j["mode_changes"] = mode_changes;  j["by_hand"] = hand.Json();
  if (j["by_hand"].is_object()) {
    // The station's own count has the last key too (a quit ends it before
    // another state message goes out).
    j["by_hand"]["key_actions"] = std::max(j["by_hand"]["key_actions"].get<std::int64_t>(), Counter(op, "key_actions"));
  }

  j["collisions"] = collision_events;
  nlohmann::ordered_json by_kind = nlohmann::ordered_json::object();
  for (const auto& [kind, t] : collision_totals) {
    by_kind[kind] = {{"events", static_cast<std::int64_t>(t[0])}, {"frames", static_cast<std::int64_t>(t[1])},
                     {"duration_s", t[2]}};
  }
  j["collisions_by_kind"] = by_kind;
  j["held_frames"] = held_frames;
  j["telemetry_frames"] = telemetry_frames;
  nlohmann::ordered_json frames;
  frames["operator_published"] = Counter(op, "published");
  frames["dcp_published"] = Counter(dcp, "published");
  frames["esg_published"] = Counter(scene, "published");
  frames["rendered"] = Counter(esg, "rendered");
  frames["superseded"] = Counter(esg, "superseded");
  frames["scenes_drawn"] = Counter(esg, "rendered.scenes");
  frames["skipped_unchanged"] = Counter(esg, "skipped.unchanged");
  frames["png_written"] = Counter(esg, "png_written");
  frames["video_frames"] = Counter(esg, "video.frames");
  frames["video_dropped"] = Counter(esg, "video.dropped");
  frames["late_operator_frames"] = Counter(op, "frames.late");
  frames["dropped"] = {
      {"operator_to_dcp", Counter(dcp, "input.missing")},
      {"dcp_to_scene", Counter(scene, "dcp.missing")},
      {"scene_to_esg", Counter(esg, "esg.missing")},
      {"malformed_at_dcp", SumPrefix(dcp, "dropped.")},
      {"malformed_at_scene", SumPrefix(scene, "dropped.")},
      {"malformed_at_esg", SumPrefix(esg, "dropped.")},
  };
  frames["clamped_inputs"] = {{"operator_station", SumPrefix(op, "clamped.")},
                              {"dynamics_proc", SumPrefix(dcp, "clamped.")},
                              {"scene_proc", SumPrefix(scene, "clamped.")}};
  j["frames"] = frames;
  nlohmann::ordered_json lat = nlohmann::ordered_json::object();
  for (const auto& [proc, s] : stats) {
    if (!s.contains("latency_us")) continue;
    for (auto it = s["latency_us"].begin(); it != s["latency_us"].end(); ++it) {
      lat[it.key()] = {{"count", it.value()["count"]},
                       {"p50_ms", it.value()["p50"].get<double>() / 1000.0},
                       {"p99_ms", it.value()["p99"].get<double>() / 1000.0},
                       {"max_ms", it.value()["max"].get<double>() / 1000.0}};
    }
  }
  j["latency"] = lat;
  // Timing health, by process: frames lost on the way in (from the frame
  // numbers), frames late (more than a frame period after the operator sent
  // them), malformed ones dropped, and each link's latency.
  {
    double rate_hz = 30.0;
    try {
      rate_hz = LoadConfig((root / "config.toml").string()).session.frame_rate_hz;
    } catch (const std::exception&) {
    }
    nlohmann::ordered_json timing;
    timing["frame_period_ms"] = 1000.0 / rate_hz;
    auto links = [&](const nlohmann::json& st) {
      nlohmann::ordered_json l = nlohmann::ordered_json::object();
      if (!st.contains("latency_us")) return l;
      for (auto it = st["latency_us"].begin(); it != st["latency_us"].end(); ++it) {
        l[it.key()] = {{"p50_ms", it.value()["p50"].get<double>() / 1000.0},
                       {"p99_ms", it.value()["p99"].get<double>() / 1000.0},
                       {"max_ms", it.value()["max"].get<double>() / 1000.0}};
      }
      return l;
    };
    timing["operator_station"] = {{"late_frames", Counter(op, "frames.late")}};
    timing["dynamics_proc"] = {{"dropped_frames", Counter(dcp, "input.missing")},
                               {"late_frames", Counter(dcp, "frames.late")},
                               {"malformed", SumPrefix(dcp, "dropped.")},
                               {"latency", links(dcp)}};
    timing["scene_proc"] = {{"dropped_frames", Counter(scene, "dcp.missing")},
                            {"late_frames", Counter(scene, "frames.late")},
                            {"malformed", SumPrefix(scene, "dropped.")},
                            {"latency", links(scene)}};
    timing["esg_renderer"] = {{"dropped_frames", Counter(esg, "esg.missing")},
                              {"superseded", Counter(esg, "superseded")},
                              {"late_frames", Counter(esg, "frames.late")},
                              {"malformed", SumPrefix(esg, "dropped.")},
                              {"latency", links(esg)}};
    j["timing"] = timing;
  }
  nlohmann::ordered_json lj;
  lj["file"] = "lcmlog";
  lj["events"] = events;
  lj["by_channel"] = by_channel;
  lj["operator_frames"] = logged_input.received();
  lj["dcp_frames"] = logged_dcp.received();
  lj["esg_frames"] = logged_esg.received();
  lj["esg_frames_missing"] = logged_esg.missing();
  lj["malformed"] = malformed;
  lj["final_status_from"] = nlohmann::json::array();
  for (const auto& [p, seen] : final_status_seen) lj["final_status_from"].push_back(p);
  j["log"] = lj;
  return j;
}

nlohmann::ordered_json MakeManifest(const std::string& dir, const ManifestFields& f) {
  const std::string &pilot = f.pilot, &url = f.url, &suffix = f.suffix, &config_sha256 = f.config_sha256,
                    &timeline = f.timeline, &restore = f.restore, &command = f.command;
  const std::vector<std::string>& hosts = f.hosts;
  nlohmann::ordered_json j;
  j["format"] = "rmslab-session-1";
  j["session"] = fs::absolute(dir).lexically_normal().filename().string();
  if (!f.session_id.empty()) j["session_id"] = FormatSessionId(ParseSessionId(f.session_id, "--session-id"));
  const std::int64_t now = WallTimeUs();
  const std::time_t secs = static_cast<std::time_t>(now / 1000000);
  char utc[32];
  std::strftime(utc, sizeof utc, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&secs));
  j["started_utc"] = utc;
  j["started_us"] = now;
  j["pilot"] = pilot;
  if (!timeline.empty()) j["timeline"] = {{"file", "timeline.tl"}, {"source", timeline}};
  if (!restore.empty()) j["restored_from"] = restore;
  j["config"] = {{"file", "config.toml"}, {"sha256", config_sha256}};
  j["software"] = {{"version", VersionString()}, {"project", Version().project}, {"describe", Version().describe},
                   {"commit", Version().commit}, {"build_type", Version().build_type}, {"compiler", Version().compiler}};
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  j["lab_host"] = host;
  j["lcm"] = {{"url", url}, {"channel_suffix", suffix}};
  nlohmann::ordered_json layout = nlohmann::ordered_json::object();
  for (const char* p : {"operator_station", "dynamics_proc", "scene_proc", "esg_renderer", "lcm-logger"}) layout[p] = "localhost";
  for (const std::string& h : hosts) {
    const auto eq = h.find('=');
    if (eq == std::string::npos) throw InputError("--host must be PROCESS=HOST, got '" + h + "'");
    layout[h.substr(0, eq)] = h.substr(eq + 1);
  }
  j["hosts"] = layout;
  if (!command.empty()) j["command"] = command;
  return j;
}

SessionInfo ReadSessionInfo(const std::string& dir) {
  const fs::path p = fs::path(dir) / "manifest.json";
  std::ifstream f(p);
  if (!f) throw InputError("no manifest.json in " + dir + ": not a session folder");
  SessionInfo s;
  s.dir = dir;
  try {
    const auto j = nlohmann::json::parse(f);
    s.lcm_url = j.at("lcm").at("url").get<std::string>();
    s.channel_suffix = j.at("lcm").value("channel_suffix", "");
    if (j.contains("session_id")) s.session_id = ParseSessionId(j.at("session_id").get<std::string>(), p.string() + " session_id");
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(p.string() + ": " + e.what());
  }
  return s;
}

nlohmann::ordered_json CompareEsgFrames(const std::string& original_dir, const std::string& replay_dir) {
  auto read = [](const fs::path& log_path) {
    std::map<std::int64_t, esg_frame_t> by_dcp;
    lcm::LogFile log(log_path.string(), "r");
    if (!log.good()) throw InputError("cannot read '" + log_path.string() + "'");
    while (const lcm::LogEvent* ev = log.readNextEvent()) {
      if (BaseChannel(ev->channel) != channels::kEsgFrame) continue;
      esg_frame_t m;
      if (SafeDecode(ev->data, ev->datalen, 4096, &m) == DecodeError::kNone) by_dcp[m.dcp_frame] = m;
    }
    return by_dcp;
  };
  const auto a = read(fs::path(original_dir) / "lcmlog");
  const auto b = read(fs::path(replay_dir) / "lcmlog");
  std::int64_t identical = 0, missing = 0;
  std::string first;
  for (const auto& [dcp_frame, m] : a) {
    const auto it = b.find(dcp_frame);
    if (it == b.end()) {
      ++missing;
      if (first.empty()) first = "DCP frame " + std::to_string(dcp_frame) + ": not replayed";
      continue;
    }
    if (it->second.frame == m.frame && it->second.words == m.words) ++identical;
    else if (first.empty()) first = "DCP frame " + std::to_string(dcp_frame) + ": words differ";
  }
  nlohmann::ordered_json j;
  j["recorded"] = static_cast<std::int64_t>(a.size());
  j["replayed"] = static_cast<std::int64_t>(b.size());
  j["identical"] = identical;
  j["missing"] = missing;
  j["first_difference"] = first;
  return j;
}

}  // namespace rms::session
