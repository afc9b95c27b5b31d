#pragma once
// A session folder's files as the tests read them: summary.json and each
// process's stats (docs/sessions.md "The session folder").
#include <cstdint>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rms/wire/message_auth.h"

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

// A recorded session's message edited by a test, as an insider (one who
// holds SESSION/run/session.key) would: its tag made again for its new
// bytes, so readers take it (docs/security.md "Authenticated messages").
// `bytes` is the message without a tag; a session without a key is left as
// it is.
inline void TagAsTheSession(const std::string& session, const std::string& channel,
                            std::vector<std::uint8_t>* bytes) {
  std::ifstream probe(session + "/run/session.key");
  if (!probe) return;
  const wire::SessionKey key = wire::ReadSessionKeyFile(session + "/run/session.key");
  const auto tag = wire::MessageMac(key, channel, bytes->data(), static_cast<int>(bytes->size()));
  bytes->insert(bytes->end(), tag.begin(), tag.end());
}
// Whether the session's messages end in a tag (its manifest's message_auth).
inline bool SessionTagsMessages(const std::string& session) {
  return ReadJson(session + "/manifest.json").contains("message_auth");
}
}  // namespace rms::testing
