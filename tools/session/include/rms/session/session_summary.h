#pragma once
// A lab session's summary.json (docs/sessions.md): frames published,
// rendered and dropped per link, the mode, latency, and what the LCM log holds.
// Built from the session folder alone: the LCM log (lcmlog) and each
// process's final counters (stats/*.json).
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rms/base/config.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/wire/message_auth.h"

namespace rms::session {

// Reads SESSION/lcmlog and SESSION/stats/*.json. Throws rms::InputError when
// the log cannot be read.
nlohmann::ordered_json Summarize(const std::string& session_dir);

// A DCP's run held in memory (a re-simulated design: docs/sessions.md
// "Sweeps"): its frames and telemetry in the order it published them (as a
// log of it would hold them: repeats and all), and where it published an
// RMS_DCP_STATE RESTORE among them.
struct DcpRun {
  std::vector<dcp_frame_t> frames;
  std::vector<dcp_telemetry_t> telemetry;
  std::vector<std::size_t> restores_before;  // telemetry messages published before each restore
};
// The mission's part of summary.json -- final_mode, modes_seen, acquired,
// docked, attempts, totals, result_attempt, phase_durations_s, docking,
// held_frames -- as Summarize makes it from a log holding this run and
// nothing else (a re-simulation's log, whose session has no restarts), by
// the same code (the DCP frames believed, the telemetry they confirm, the
// attempt log), without writing and reading a log. `config`: the run's.
nlohmann::ordered_json SummarizeDcpRun(const LabConfig& config, const DcpRun& run);

// The indices of the longest run of strictly increasing values in v, in
// order (patience sorting, O(n log n)): the DCP's frames a reader of a log
// believes (the DCP numbers its frames upward; a frame off the run is a
// forgery: docs/security.md "What the summary trusts"). Of a value repeated
// where the run takes it, the first copy's index: what a reader placed after
// the first copy stays after it.
std::vector<std::size_t> LongestIncreasingRun(const std::vector<std::int64_t>& v);

// A logged channel's name without the session's channel suffix
// ("RMS_DCP_FRAME_BAY2" -> "RMS_DCP_FRAME"); other names unchanged.
std::string BaseChannel(const std::string& channel);

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

// Every rmslab session heard on an LCM address within `seconds`:
// {"url", "seconds", "sessions": [{"session_id", "channels": {name: n},
// "senders": ["dynamics_proc pid N", ...]}]} -- the launcher's look before it
// starts a session there (docs/sessions.md "Sharing a network").
// Throws rms::TransportError when the address cannot be opened.
nlohmann::ordered_json ProbeAddress(const std::string& url, double seconds);

// A replay's ESG frames against the recorded ones, matched by the DCP frame
// they were made from: {"recorded", "replayed", "identical", "missing",
// "first_difference"}.
nlohmann::ordered_json CompareEsgFrames(const std::string& original_dir,
                                        const std::string& replay_dir);

}  // namespace rms::session
