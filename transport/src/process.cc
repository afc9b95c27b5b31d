#include "rms/transport/process.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>
#include <thread>

#include "rms/base/check.h"
#include "rms/base/command_line.h"
#include "rms/base/config.h"
#include "rms/base/cpu_wake_latency.h"
#include "rms/base/text.h"
#include "rms/base/version.h"
#include "rms/process_status_t.hpp"
#include "rms/transport/journal.h"
#include "rms/wire/channels.h"
#include "rms/wire/message_auth.h"
#include "rms/wire/message_io.h"

namespace rms::transport {

void AddCommonOptions(CLI::App& app, CommonOptions* o) {
  o->config_path = DefaultConfigPath();
  app.add_option("--config", o->config_path, "Configuration file (docs/config.md)")
      ->capture_default_str();
  app.add_option("--lcm-url", o->lcm.url, "LCM URL (docs/protocol.md, Transport)")
      ->capture_default_str();
  app.add_option("--channel-suffix", o->lcm.channel_suffix,
                 "Suffix appended to every channel name, so several stations share a network");
  app.add_option("--queue-capacity", o->lcm.queue_capacity,
                 "LCM receive queue per subscription, messages")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  app.add_option("--stats", o->stats_path, "Write the final counters as JSON to this file at exit");
  app.add_option("--ready-file", o->ready_path,
                 "Create this file once subscribed and running (for launchers)");
  app.add_option("--log-level", o->log_level, "trace, debug, info, warn, error")
      ->capture_default_str()
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
  app.add_option(
      "--session-id", o->session_id,
      "The session this process belongs to (default: $RMSLAB_SESSION_ID; none: takes every "
      "session's "
      "messages); messages of other sessions are dropped and counted (docs/security.md)");
  app.add_option("--journal-dir", o->journal_dir,
                 "Append every message this process publishes to a journal in this folder, "
                 "PROCESS.N.lcmlog, before it goes on the wire (docs/sessions.md \"The record\")");
  app.add_flag("--check", o->check,
               "Check the configuration (and this process's own files), say what is wrong, and "
               "exit (0: good)");
  app.set_version_flag("--version", VersionString(), "Print the software version and exit");
}

namespace {

// The journal's folder can take it: a folder this process may write in.
void CheckJournalDir(const std::string& dir) {
  if (!std::filesystem::is_directory(dir))
    throw InputError("--journal-dir " + dir + ": no such folder");
  if (access(dir.c_str(), W_OK | X_OK) != 0)
    throw InputError("--journal-dir " + dir + ": cannot be written (" + std::strerror(errno) + ")");
}

// The launcher's restart count (RMSLAB_RESTART), 0 without one: the
// journal's first run number to try.
int RestartNumber() {
  const char* r = std::getenv("RMSLAB_RESTART");
  if (!r || !*r) return 0;
  char* end = nullptr;
  const long n = std::strtol(r, &end, 10);
  return *end == '\0' && n >= 0 && n < 1000 ? static_cast<int>(n) : 0;
}

// What the process's CPU wake-latency request came to, for its ready file.
std::string g_cpu_wake_latency = "off";

// The launcher's request (RMSLAB_CPU_WAKE_LATENCY_US), held for the
// process's life and said in its log; one that cannot be held is a warning
// (docs/performance.md "Wake latency").
CpuWakeLatencyRequest HoldCpuWakeLatency() {
  const std::optional<std::int32_t> us = CpuWakeLatencyFromEnv();
  if (!us) return {};
  CpuWakeLatencyRequest wake(*us);
  g_cpu_wake_latency = wake.state();
  if (wake.held())
    spdlog::info("cpu wake latency: {}", wake.state());
  else
    spdlog::warn(
        "cpu wake latency: {}: frames reach the pixels later (docs/performance.md \"Wake "
        "latency\")",
        wake.state());
  return wake;
}

}  // namespace

int ProcessMain(CLI::App& app, int argc, char** argv, const std::string& process,
                CommonOptions* common,
                const std::function<int(const LabConfig&, LcmInterface&)>& body,
                const std::function<void(const LabConfig&)>& check) {
  AddCommonOptions(app, common);
  if (const auto rc = ParseCommandLine(app, argc, argv)) return *rc;
  SetUpLogging(process, common->log_level);
  InstallStopHandlers();
  WatchLifeline();
  if (common->check) {
    try {
      const LabConfig config = LoadConfig(common->config_path);
      ValidateChannelSuffix(common->lcm.channel_suffix);
      if (!common->session_id.empty()) (void)ParseSessionId(common->session_id, "--session-id");
      (void)CpuWakeLatencyFromEnv();
      (void)wire::SessionKeyFromEnv();
      if (!common->journal_dir.empty()) CheckJournalDir(common->journal_dir);
      if (check) check(config);
      spdlog::info("check: {} and this process's files are good", common->config_path);
      return 0;
    } catch (const std::exception& e) {
      spdlog::error("{}", e.what());
      return 2;
    }
  }
  try {
    const LabConfig config = LoadConfig(common->config_path);
    const std::int64_t session = common->session_id.empty()
                                     ? SessionIdFromEnv()
                                     : ParseSessionId(common->session_id, "--session-id");
    const CpuWakeLatencyRequest wake = HoldCpuWakeLatency();
    UdpLcm lcm(common->lcm);
    lcm.SetSender({session, wire::ProcessCode(process), static_cast<std::int32_t>(getpid())});
    if (const auto key = wire::SessionKeyFromEnv()) {
      lcm.SetKey(*key);
      spdlog::info("messages authenticated with the session's key (docs/security.md)");
    }
    if (!common->journal_dir.empty()) {
      lcm.SetJournal(Journal::CreateIn(common->journal_dir, process, RestartNumber()));
      spdlog::info("journal: {}", lcm.journal()->path());
    }
    if (session != 0) spdlog::info("session {}", wire::FormatSessionId(session));
    return body(config, lcm);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
}

void SetUpLogging(const std::string& process, const std::string& level) {
  auto logger = spdlog::stderr_logger_mt(process);
  logger->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%n] [%l] %v");
  logger->set_level(spdlog::level::from_str(level));
  logger->flush_on(spdlog::level::info);
  spdlog::set_default_logger(logger);
}

namespace {
std::atomic<bool> g_stop{false};
extern "C" void OnStopSignal(int) { g_stop.store(true); }
}  // namespace

void WatchLifeline() {
  const char* v = std::getenv("RMSLAB_LIFELINE");
  if (!v || std::strcmp(v, "stdin") != 0) return;
  // The launcher holds the other end of this process's standard input and
  // never writes to it: end of file means the launcher is gone (killed, even
  // with SIGKILL; or, over ssh, the link to it): stop as on SIGINT.
  std::thread([] {
    char buf[256];
    for (;;) {
      const ssize_t n = read(STDIN_FILENO, buf, sizeof buf);
      if (n > 0) continue;
      if (n < 0 && errno == EINTR) continue;
      spdlog::warn("the launcher is gone (its lifeline, standard input, closed): stopping");
      RequestStop();
      return;
    }
  }).detach();
}

void InstallStopHandlers() {
  struct sigaction sa {};
  sa.sa_handler = OnStopSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGHUP, &sa, nullptr);  // a closed terminal: stop as cleanly as on Ctrl-C
  std::signal(SIGPIPE, SIG_IGN);
}
bool StopRequested() { return g_stop.load(); }
void RequestStop() { g_stop.store(true); }

void WriteReadyFile(const std::string& path) {
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp);
    f << nlohmann::json{{"pid", static_cast<int>(getpid())},
                        {"host", host},
                        {"cpu_wake_latency", g_cpu_wake_latency}}
             .dump()
      << "\n";
    f.close();
    if (!f) throw InputError("cannot write the ready file '" + tmp + "'");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw InputError("cannot create the ready file '" + path + "'");
}

StatusReporter::StatusReporter(LcmInterface* lcm, std::string process)
    : lcm_(lcm), process_(std::move(process)) {
  char buf[256] = {};
  gethostname(buf, sizeof buf - 1);
  host_ = buf;
}

void StatusReporter::Tick(std::int64_t frame, const Counters& counters,
                          const LatencyMap& latencies) {
  const std::int64_t now = lcm_->NowUs();
  if (now - last_us_ < 1000000) return;
  last_us_ = now;
  Publish(frame, counters, latencies, false);
}

void StatusReporter::Final(std::int64_t frame, const Counters& counters,
                           const LatencyMap& latencies) {
  Publish(frame, counters, latencies, true);
}

void StatusReporter::Publish(std::int64_t frame, const Counters& counters,
                             const LatencyMap& latencies, bool final) {
  process_status_t m;
  m.send_time_us = lcm_->NowUs();
  m.process = process_.substr(0, process_status_t::MAX_PROCESS_BYTES);
  m.host = host_.substr(0, process_status_t::MAX_HOST_BYTES);
  m.pid = static_cast<std::int32_t>(getpid());
  m.frame = frame;
  m.final = final;
  for (const auto& [k, v] : StatusFigures(counters, latencies)) {
    if (m.counter_names.size() >= static_cast<std::size_t>(process_status_t::MAX_COUNTERS)) break;
    m.counter_names.push_back(k.substr(0, process_status_t::MAX_COUNTER_NAMES_BYTES));
    m.counter_values.push_back(v);
  }
  m.num_counters = static_cast<std::int16_t>(m.counter_names.size());
  PublishMessage(*lcm_, wire::channels::kStatus, m);
}

void NoteTransportCounters(const LcmInterface& lcm, Counters* counters) {
  if (const std::int64_t n = lcm.other_session_dropped(); n > 0)
    counters->Set(Counter::kDroppedOtherSession, n);
  if (const std::int64_t n = lcm.other_sender_dropped(); n > 0)
    counters->Set(Counter::kDroppedOtherSender, n);
  if (const std::int64_t n = lcm.bad_mac_dropped(); n > 0)
    counters->Set(Counter::kDroppedBadMac, n);
  if (const std::int64_t n = lcm.replayed_dropped(); n > 0)
    counters->Set(Counter::kDroppedReplayed, n);
  if (const Journal* j = lcm.journal()) {
    counters->Set(Counter::kJournalEvents, j->events());
    if (j->failed() > 0) counters->Set(Counter::kJournalFailed, j->failed());
  }
}

std::map<std::string, std::int64_t> StatusFigures(const Counters& counters,
                                                  const LatencyMap& latencies) {
  std::map<std::string, std::int64_t> out = counters.ByName();
  for (const auto& [name, h] : latencies) {
    const std::string p = "latency." + name + ".";
    out[p + "count"] = h.count();
    out[p + "p50_us"] = static_cast<std::int64_t>(h.Percentile(0.5));
    out[p + "p99_us"] = static_cast<std::int64_t>(h.Percentile(0.99));
    out[p + "max_us"] = static_cast<std::int64_t>(h.max_us());
  }
  return out;
}

void RunNodeLoop(LcmInterface& lcm, const std::string& process, Counters& counters,
                 const LatencyMap& latencies, const std::function<std::int64_t()>& last_frame,
                 const std::function<void()>& after_wait, const std::string& stats_path,
                 int wait_ms) {
  StatusReporter status(&lcm, process);
  while (!StopRequested()) {
    if (lcm.HandleSubscriptions(wait_ms) < 0) counters.Add(Counter::kTransportErrors);
    if (after_wait) after_wait();
    NoteTransportCounters(lcm, &counters);
    status.Tick(last_frame(), counters, latencies);
  }
  NoteTransportCounters(lcm, &counters);
  status.Final(last_frame(), counters, latencies);
  if (!stats_path.empty()) WriteStatsJson(stats_path, process, counters, latencies);
}

void WriteStatsJson(const std::string& path, const std::string& process, const Counters& counters,
                    const LatencyMap& latencies) {
  nlohmann::ordered_json j;
  j["process"] = process;
  j["cpu_wake_latency"] = g_cpu_wake_latency;
  j["counters"] = nlohmann::ordered_json::object();
  for (const auto& [k, v] : counters.ByName()) j["counters"][k] = v;
  j["latency_us"] = nlohmann::ordered_json::object();
  for (const auto& [name, h] : latencies) {
    j["latency_us"][name] = {{"count", h.count()},
                             {"p50", h.Percentile(0.5)},
                             {"p99", h.Percentile(0.99)},
                             {"max", h.max_us()},
                             {"mean", h.mean_us()}};
  }
  WriteWholeFile(path, j.dump(2) + "\n");
}

wire::FrameClock SessionFrameClock(double rate_hz) {
  wire::FrameClock c;
  const char* v = std::getenv("RMSLAB_SESSION_EPOCH_US");
  if (!v || !*v) return c;
  char* end = nullptr;
  const long long epoch = std::strtoll(v, &end, 10);
  if (*end != '\0' || epoch <= 0) {
    throw InputError(std::string("RMSLAB_SESSION_EPOCH_US='") + v +
                     "': not a time in us since 1970");
  }
  c.epoch_us = epoch;
  c.max_rate_hz = rate_hz * kMaxSessionSpeed;
  return c;
}

bool RestartedByLauncher() {
  const char* r = std::getenv("RMSLAB_RESTART");
  return r && *r && std::strcmp(r, "0") != 0;
}

std::int64_t FirstFrameNumber(double rate_hz) {
  // A first start numbers from 0 (its peers have seen nothing yet; a
  // re-simulation starts there too); a restart carries on the session's
  // numbering from its epoch.
  if (!RestartedByLauncher()) return 0;
  const char* v = std::getenv("RMSLAB_SESSION_EPOCH_US");
  if (!v || !*v) return 0;
  char* end = nullptr;
  const long long epoch = std::strtoll(v, &end, 10);
  if (*end != '\0' || epoch <= 0) {
    throw InputError(std::string("RMSLAB_SESSION_EPOCH_US='") + v +
                     "': not a time in us since 1970");
  }
  const std::int64_t now = WallTimeUs();
  if (now <= epoch) return 0;
  return static_cast<std::int64_t>((now - epoch) * 1e-6 * rate_hz);
}

}  // namespace rms::transport
