#pragma once
// A lab file (docs/sessions.md "Several hosts"): which process of a session
// runs on which host, the multicast TTL, and where rmslab is on remote
// hosts. Read strictly, as every configuration file: errors name the file,
// the key and the reason.
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace rms::session {

struct LabFile {
  std::string source;
  // "operator_station", "dynamics_proc", "scene_proc", "esg_renderer",
  // "recorder" (lcm-logger) -> "localhost", "netns:NAME" (a network
  // namespace on this machine) or "ssh:[USER@]HOST".
  std::map<std::string, std::string> hosts;
  int ttl = 1;                          // LCM multicast TTL when not all on one host
  std::string group = "239.255.76.67";  // LCM multicast group of the lab
  int port = 7667;                      // and its UDP port
  std::string remote_root;              // rmslab on ssh hosts ("" = the same path as here)
  std::string remote_build;             // its build folder ("" = remote_root/build)
  // [instructor] bind: where the instructor's page is served ("" = 127.0.0.1
  // only; docs/instructor.md "Beyond this host"); optional.
  std::string instructor_bind;
  // [sweep] (optional; docs/sessions.md "Sweeps"): the hosts scripts/lab
  // sweep runs its cells on (none: every distinct host of [hosts]) and how
  // many at once on each (0: each host's cores).
  std::vector<std::string> sweep_hosts;
  int sweep_jobs_per_host = 0;
  bool all_local() const;
};

LabFile LoadLabFile(const std::string& path);
// The same from the file's text (path names it in errors).
LabFile ParseLabFile(std::string_view text, const std::string& path);
// {"hosts": {process: host}, "ttl", "group", "port", "all_local",
// "remote_root", "remote_build", "instructor_bind", "sweep_hosts",
// "sweep_jobs_per_host"}: for the launcher (scripts/lab).
nlohmann::ordered_json LabFileJson(const LabFile& lab);

}  // namespace rms::session
