#pragma once
// A session folder's files as the tests read them: summary.json and each
// process's stats (docs/sessions.md "The session folder").
#include <cstdint>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace rms::testing {

// The file's JSON, or an empty object when it is missing or malformed.
inline nlohmann::json ReadJson(const std::string& path) {
  std::ifstream f(path);
  if (!f) return nlohmann::json::object();
  try {
    return nlohmann::json::parse(f);
  } catch (const std::exception&) {
    return nlohmann::json::object();
  }
}
// A counter of a process's stats (SESSION/stats/PROCESS.json), 0 when absent.
inline std::int64_t Counter(const std::string& session, const std::string& process,
                            const std::string& name) {
  return ReadJson(session + "/stats/" + process + ".json")
      .value("counters", nlohmann::json::object())
      .value(name, 0L);
}
}  // namespace rms::testing
