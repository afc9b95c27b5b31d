#include "rms/session/lab_file.h"

#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "rms/base/check.h"
#include "rms/base/toml_reader.h"

namespace rms::session {

namespace {

constexpr const char* kProcesses[] = {"operator_station", "dynamics_proc", "scene_proc",
                                      "esg_renderer", "recorder"};

bool ValidName(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.' ||
          c == '@'))
      return false;
  }
  return true;
}

// "a.b.c.d", each 0..255, and nothing after: an IPv4 address.
bool DottedQuad(const std::string& s, std::array<int, 4>* a) {
  char tail = 0;
  if (std::sscanf(s.c_str(), "%d.%d.%d.%d%c", &(*a)[0], &(*a)[1], &(*a)[2], &(*a)[3], &tail) != 4)
    return false;
  for (int v : *a) {
    if (v < 0 || v > 255) return false;
  }
  return true;
}

}  // namespace

bool LabFile::all_local() const {
  for (const auto& [p, h] : hosts) {
    if (h != "localhost") return false;
  }
  return true;
}

namespace {

bool ValidHost(const std::string& v) {
  return v == "localhost" || (v.rfind("netns:", 0) == 0 && ValidName(v.substr(6))) ||
         (v.rfind("ssh:", 0) == 0 && ValidName(v.substr(4)));
}

// [sweep] (optional; docs/sessions.md "Sweeps"): where scripts/lab sweep runs its cells.
void ReadSweepHosts(TomlReader s, LabFile* lab) {
  const toml::node* n = s.table().get("hosts");
  s.Use("hosts");
  const toml::array* a = n ? n->as_array() : nullptr;
  if (!a || a->empty()) s.Fail("hosts", "must be an array of one or more hosts");
  for (const toml::node& h : *a) {
    const std::optional<std::string> v = h.value<std::string>();
    if (!h.is_string() || !ValidHost(*v)) {
      s.Fail("hosts", "each must be \"localhost\", \"netns:NAME\" or \"ssh:[USER@]HOST\"");
    }
    lab->sweep_hosts.push_back(*v);
  }
  lab->sweep_jobs_per_host = static_cast<int>(s.Number("jobs_per_host", 1, 256));
  s.Finish();
}

}  // namespace

LabFile LoadLabFile(const std::string& path) {
  return ParseLabFile(ReadTextFile(path, "the lab file"), path);
}

LabFile ParseLabFile(std::string_view text, const std::string& path) {
  LabFile lab;
  lab.source = path;
  const toml::table root = ParseToml(std::string(text), path);
  const std::string doc = "docs/sessions.md";
  TomlReader top(&root, "", &lab.source, doc);
  {
    TomlReader h = top.Sub("hosts");
    for (const char* p : kProcesses) {
      const std::string v = h.String(p);
      if (!ValidHost(v))
        h.Fail(p,
               "must be \"localhost\", \"netns:NAME\" or \"ssh:[USER@]HOST\", got \"" + v + "\"");
      lab.hosts[p] = v;
    }
    h.Finish();
  }
  {
    TomlReader l = top.Sub("lcm");
    // docs/security.md: a lab names its own multicast group and port.
    lab.group = l.String("group");
    {
      std::array<int, 4> a{};
      if (!DottedQuad(lab.group, &a) || a[0] < 224 || a[0] > 239)
        l.Fail("group",
               "must be an IPv4 multicast address (224.0.0.0 .. 239.255.255.255; 239.x.x.x for a "
               "lab), got \"" +
                   lab.group + "\"");
    }
    lab.port = static_cast<int>(l.Number("port", 1024, 65535));
    lab.ttl = static_cast<int>(l.Number("ttl", 0, 255));
    l.Finish();
  }
  {
    TomlReader r = top.Sub("remote");
    lab.remote_root = r.String("root");
    lab.remote_build = r.String("build");
    r.Finish();
  }
  if (root.contains("instructor")) {  // optional: docs/instructor.md "Beyond this host"
    TomlReader i = top.Sub("instructor");
    lab.instructor_bind = i.String("bind");
    std::array<int, 4> a{};
    if (!DottedQuad(lab.instructor_bind, &a)) {
      i.Fail("bind", "must be an IPv4 address of this host (\"0.0.0.0\": every one), got \"" +
                         lab.instructor_bind + "\"");
    }
    i.Finish();
  }
  if (root.contains("sweep")) ReadSweepHosts(top.Sub("sweep"), &lab);
  top.Finish();
  return lab;
}

nlohmann::ordered_json LabFileJson(const LabFile& lab) {
  nlohmann::ordered_json j;
  j["hosts"] = lab.hosts;
  j["ttl"] = lab.ttl;
  j["group"] = lab.group;
  j["port"] = lab.port;
  j["all_local"] = lab.all_local();
  j["remote_root"] = lab.remote_root;
  j["remote_build"] = lab.remote_build;
  j["instructor_bind"] = lab.instructor_bind;
  j["sweep_hosts"] = lab.sweep_hosts;
  j["sweep_jobs_per_host"] = lab.sweep_jobs_per_host;
  return j;
}

}  // namespace rms::session
