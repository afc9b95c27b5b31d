#pragma once
// A session's manifest.json (docs/sessions.md "The manifest"): written at
// its start (MakeManifest), read by every tool that talks to or reads the
// session (ReadSessionInfo, ReadSessionKey).
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rms/wire/message_auth.h"

namespace rms::session {

// SESSION/manifest.json (docs/sessions.md "The manifest"): the software
// (this build's version), the configuration (file and hash), the pilot, the
// LCM URL and channel suffix, which process ran on which host, the lab host,
// and the start time.
struct ManifestFields {
  std::string pilot, url, suffix, config_sha256, timeline, restore, command;
  std::string session_id;          // "0x..." (the launcher's random id; every message carries it)
  std::vector<std::string> hosts;  // PROCESS=HOST
  std::string subject,
      note;  // who flew it and the experimenter's note (scripts/lab demo --subject --note)
  std::string kind = "live";  // "live", "replay" or "re-simulation"
  std::string parent;         // a replay's or re-simulation's recorded session (absolute path)
  std::string config_source;  // where config.toml came from
  // A session branched from a recorded one (scripts/lab demo --from
  // SESSION@TIME; docs/sessions.md "Branching"): the recorded session, the
  // instant (its DCP frame, after which the branch took over) and its log's hash.
  std::string branch_of;           // the recorded session (absolute path); "" when not a branch
  std::int64_t branch_frame = -1;  // the last DCP frame of the recorded session's prefix
  double branch_time_s = 0;        // ... its session time (frame / frame rate)
  std::string branch_parent_log_sha256;  // SHA-256 of the recorded session's lcmlog
  // How its log's first attempt began: "start", "restore" or "branch"
  // (docs/sessions.md "The manifest"). "" derives it from `restore` and
  // `branch_of`; a re-simulation sets its recorded session's.
  std::string began_from;
  // The session's messages carry tags (wire::kMessageAuthName), its key in
  // SESSION/run/session.key; "" when they do not.
  std::string message_auth;
  // A study's trial (scripts/lab study run; docs/studies.md "The session
  // folders"): empty `name` when the session is none.
  struct StudyTrial {
    std::string name, file_sha256, condition, kind;
    int trial = 0, run = 1;
  } study;
};
nlohmann::ordered_json MakeManifest(const std::string& session_dir, const ManifestFields& f);
// A manifest's `began_from`; for one written before that field, derived
// from its `branch` and `restored_from`.
std::string BeganFrom(const nlohmann::json& manifest);

// What a tool needs to talk to, or read, a session: from its manifest.json.
struct SessionInfo {
  std::string dir;
  std::string lcm_url;
  std::string channel_suffix;
  std::int64_t session_id = 0;  // 0: a session recorded before session ids, or none
  std::string message_auth;     // the manifest's; "": messages carry no tag
};
// Throws rms::InputError when SESSION/manifest.json is missing or malformed.
SessionInfo ReadSessionInfo(const std::string& session_dir);
// The session's key (SESSION/run/session.key) when its manifest says its
// messages carry tags; none when they do not. Throws InputError naming the
// file when they do and the key cannot be read (docs/security.md
// "Authenticated messages").
std::optional<wire::SessionKey> ReadSessionKey(const std::string& session_dir);

}  // namespace rms::session
