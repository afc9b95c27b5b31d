#include "rms/session/manifest.h"

#include <unistd.h>

#include <ctime>
#include <filesystem>

#include "rms/base/check.h"
#include "rms/base/folder_file.h"
#include "rms/base/version.h"
#include "rms/session/session_folder.h"
#include "rms/transport/process.h"
#include "rms/wire/message_io.h"

namespace rms::session {

namespace fs = std::filesystem;

std::string BeganFrom(const nlohmann::json& m) {
  if (m.contains("began_from") && m["began_from"].is_string()) return m["began_from"];
  return m.contains("branch") ? "branch" : m.contains("restored_from") ? "restore" : "start";
}

nlohmann::ordered_json MakeManifest(const std::string& dir, const ManifestFields& f) {
  const std::string &pilot = f.pilot, &url = f.url, &suffix = f.suffix,
                    &config_sha256 = f.config_sha256, &timeline = f.timeline, &restore = f.restore,
                    &command = f.command;
  const std::vector<std::string>& hosts = f.hosts;
  nlohmann::ordered_json j;
  j["format"] = "rmslab-session-1";
  j["session"] = fs::absolute(dir).lexically_normal().filename().string();
  if (!f.session_id.empty())
    j["session_id"] =
        wire::FormatSessionId(transport::ParseSessionId(f.session_id, "--session-id"));
  const std::int64_t now = transport::WallTimeUs();
  const std::time_t secs = static_cast<std::time_t>(now / 1000000);
  char utc[32];
  std::strftime(utc, sizeof utc, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&secs));
  j["started_utc"] = utc;
  j["started_us"] = now;
  j["pilot"] = pilot;
  j["kind"] = f.kind;
  if (!f.parent.empty()) j[f.kind == "re-simulation" ? "resimulation_of" : "replay_of"] = f.parent;
  if (!f.subject.empty()) j["subject"] = f.subject;
  if (!f.note.empty()) j["note"] = f.note;
  if (!timeline.empty()) j["timeline"] = {{"file", "timeline.tl"}, {"source", timeline}};
  if (!restore.empty()) j["restored_from"] = restore;
  if (!f.branch_of.empty()) {
    j["branch"] = {{"parent", f.branch_of},
                   {"frame", f.branch_frame},
                   {"time_s", f.branch_time_s},
                   {"parent_log_sha256", f.branch_parent_log_sha256}};
  }
  if (!f.study.name.empty()) {
    if (f.study.condition.empty() || f.study.kind.empty() || f.study.trial < 1 || f.study.run < 1)
      throw InputError(
          "--study: give --condition, --trial (1 or more), --trial-kind and --trial-run");
    j["study"] = {{"name", f.study.name},           {"file_sha256", f.study.file_sha256},
                  {"condition", f.study.condition}, {"trial", f.study.trial},
                  {"kind", f.study.kind},           {"run", f.study.run}};
  }
  j["began_from"] = !f.began_from.empty()  ? f.began_from
                    : !f.branch_of.empty() ? "branch"
                    : !restore.empty()     ? "restore"
                                           : "start";
  if (!f.message_auth.empty()) {
    if (f.message_auth != wire::kMessageAuthName)
      throw InputError("--message-auth '" + f.message_auth + "': the one kind is " +
                       wire::kMessageAuthName);
    j["message_auth"] = f.message_auth;
  }
  j["config"] = {{"file", "config.toml"}, {"sha256", config_sha256}};
  if (!f.config_source.empty()) j["config"]["source"] = f.config_source;
  j["software"] = {{"version", VersionString()},         {"project", Version().project},
                   {"describe", Version().describe},     {"commit", Version().commit},
                   {"build_type", Version().build_type}, {"compiler", Version().compiler}};
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  j["lab_host"] = host;
  // A re-simulation ran on no network (no url), but its log's channels may
  // carry a suffix: said, so its readers find them.
  if (!url.empty() || !suffix.empty()) j["lcm"] = {{"url", url}, {"channel_suffix", suffix}};
  nlohmann::ordered_json layout = nlohmann::ordered_json::object();
  for (const char* p :
       {"operator_station", "dynamics_proc", "scene_proc", "esg_renderer", "lcm-logger"})
    layout[p] = "localhost";
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
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(p, ec)))
    throw InputError("no manifest.json in " + dir + ": not a session folder");
  const std::string text = ReadSessionFile(dir, "manifest.json", kMaxJsonBytes);
  SessionInfo s;
  s.dir = dir;
  try {
    const auto j = nlohmann::json::parse(text);
    if (j.contains("lcm")) {  // a re-simulation's folder has none: it ran on no network
      s.lcm_url = j.at("lcm").value("url", "");
      s.channel_suffix = j.at("lcm").value("channel_suffix", "");
    }
    if (j.contains("session_id"))
      s.session_id = transport::ParseSessionId(j.at("session_id").get<std::string>(),
                                               p.string() + " session_id");
    if (j.contains("message_auth")) s.message_auth = j.at("message_auth").get<std::string>();
  } catch (const InputError&) {
    throw;
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(p.string() + ": not valid JSON (at byte " + std::to_string(e.byte) +
                     "): not a session's manifest");
  } catch (const std::exception& e) {
    throw InputError(p.string() + ": not a session's manifest (" +
                     std::string(e.what()).substr(std::string(e.what()).find(']') + 1) + ")");
  }
  return s;
}

std::optional<wire::SessionKey> ReadSessionKey(const std::string& dir) {
  const SessionInfo info = ReadSessionInfo(dir);
  if (info.message_auth.empty()) return std::nullopt;
  if (info.message_auth != wire::kMessageAuthName)
    throw InputError(dir + "/manifest.json: message_auth '" + info.message_auth +
                     "' is not one this build knows (" + wire::kMessageAuthName + ")");
  try {
    return wire::ReadSessionKeyFile((fs::path(dir) / "run" / "session.key").string());
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) +
                     ": the session's messages carry tags (manifest.json message_auth), and "
                     "without its key no reader can tell its own from a stranger's");
  }
}

}  // namespace rms::session
