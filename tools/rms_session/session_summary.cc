#include "session_summary.h"

#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <set>

#include "rms/channels.h"
#include "rms/check.h"
#include "rms/control_word.h"
#include "rms/counters.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/message_io.h"
#include "rms/operator_input_t.hpp"
#include "rms/process_status_t.hpp"

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

std::string StripSuffix(const std::string& channel) {
  for (const char* base : {channels::kOperatorInput, channels::kDcpFrame, channels::kEsgFrame,
                           channels::kStatus}) {
    if (channel.rfind(base, 0) == 0) return base;
  }
  return channel;
}

}  // namespace

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
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    ++events;
    if (first_us < 0) first_us = ev->timestamp;
    last_us = ev->timestamp;
    const std::string base = StripSuffix(ev->channel);
    ++by_channel[ev->channel];
    if (base == channels::kOperatorInput) {
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
    } else if (base == channels::kEsgFrame) {
      esg_frame_t m;
      if (SafeDecode(ev->data, ev->datalen, 1024, &m) == DecodeError::kNone) logged_esg.Accept(m.frame);
      else ++malformed;
    } else if (base == channels::kStatus) {
      process_status_t m;
      if (SafeDecode(ev->data, ev->datalen, 1 << 20, &m) == DecodeError::kNone) {
        if (m.final) final_status_seen[m.process] = true;
      } else {
        ++malformed;
      }
    }
  }

  std::map<std::string, nlohmann::json> stats;
  for (const char* p : {"operator_station", "dynamics_proc", "scene_proc", "esg_renderer"}) {
    stats[p] = ReadJson(root / "stats" / (std::string(p) + ".json"));
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
  nlohmann::ordered_json frames;
  frames["operator_published"] = Counter(op, "published");
  frames["dcp_published"] = Counter(dcp, "published");
  frames["esg_published"] = Counter(scene, "published");
  frames["rendered"] = Counter(esg, "rendered");
  frames["superseded"] = Counter(esg, "superseded");
  frames["png_written"] = Counter(esg, "png_written");
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

}  // namespace rms::session
