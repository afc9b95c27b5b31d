#include "rms/session/esg_compare.h"

#include <cstdint>
#include <map>

#include "rms/esg_frame_t.hpp"
#include "rms/session/session_log.h"
#include "rms/wire/channels.h"

namespace rms::session {

nlohmann::ordered_json CompareEsgFrames(const std::string& original_dir,
                                        const std::string& replay_dir) {
  auto read = [](const std::string& dir) {
    std::map<std::int64_t, esg_frame_t> by_dcp;
    SessionLog log(dir);  // each session's own ESG frames
    log.Read({wire::channels::kEsgFrame}, [&](const LogMessage& ev) {
      esg_frame_t m;
      if (log.Decode(ev, &m)) by_dcp[m.dcp_frame] = m;
    });
    return by_dcp;
  };
  const auto a = read(original_dir);
  const auto b = read(replay_dir);
  std::int64_t identical = 0, missing = 0;
  std::string first;
  for (const auto& [dcp_frame, m] : a) {
    const auto it = b.find(dcp_frame);
    if (it == b.end()) {
      ++missing;
      if (first.empty()) first = "DCP frame " + std::to_string(dcp_frame) + ": not replayed";
      continue;
    }
    if (it->second.frame == m.frame && it->second.words == m.words)
      ++identical;
    else if (first.empty())
      first = "DCP frame " + std::to_string(dcp_frame) + ": words differ";
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
