#pragma once
// What every rmslab process does the same way: common command-line options,
// stop on SIGINT / SIGTERM, a once-a-second status report on RMS_STATUS, the
// final counters written as JSON (--stats) and a ready file (--ready-file)
// that launchers wait for.
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>

#include "rms/base/config.h"
#include "rms/base/counters.h"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/frame_numbers.h"

namespace CLI {
class App;
}

namespace rms::transport {

struct CommonOptions {
  std::string config_path;         // --config (default: DefaultConfigPath())
  LcmOptions lcm;                  // --lcm-url, --channel-suffix, --queue-capacity
  std::string stats_path;          // --stats FILE: final counters as JSON at exit
  std::string ready_path;          // --ready-file FILE: created once subscribed and running
  std::string log_level = "info";  // --log-level
  bool check = false;  // --check: check the configuration (and the process's own files), then exit
  std::string session_id;  // --session-id (default: RMSLAB_SESSION_ID, else 0: no session)
  // --journal-dir: every message published goes to DIR/PROCESS.N.lcmlog
  // too, before the wire (rms/transport/journal.h); "" for none.
  std::string journal_dir;
};

void AddCommonOptions(CLI::App& app, CommonOptions* options);

// The main() every process shares: adds the common options to `app`, parses
// the command line, sets up logging and the stop signals, loads the
// configuration, holds the CPUs' wake latency the launcher asked for
// (RMSLAB_CPU_WAKE_LATENCY_US, rms/base/cpu_wake_latency.h) while `body`
// runs, opens LCM and runs `body`. Bad input (a config error, no
// multicast route) is logged with its reason and exits 2. With --check it
// loads the configuration, runs `check` (the process's own files: throws
// rms::InputError naming what is wrong), says so on stderr and exits: 0 when
// all is good, 2 otherwise -- no LCM, nothing started (launchers check
// before they start anything).
int ProcessMain(CLI::App& app, int argc, char** argv, const std::string& process,
                CommonOptions* common,
                const std::function<int(const LabConfig&, LcmInterface&)>& body,
                const std::function<void(const LabConfig&)>& check = {});

// Sets up spdlog's default logger (stderr, "[time] [process] [level] msg").
void SetUpLogging(const std::string& process, const std::string& level);

// SIGINT / SIGTERM set the stop flag; the main loops poll it.
// The first frame number a process uses for what it publishes
// (docs/protocol.md "Frame numbers"): 0 at a first start; when the launcher
// restarted it after a fault (RMSLAB_RESTART > 0) and set
// RMSLAB_SESSION_EPOCH_US (the session's start, wall clock, us since 1970),
// the frames of rate_hz since then, so a process restarted mid-session
// continues the numbering and its peers see the frames it missed as a gap,
// not as stale. A malformed value is an InputError naming the variable.
std::int64_t FirstFrameNumber(double rate_hz);

// True when the launcher restarted this process after a fault
// (RMSLAB_RESTART set and not 0; docs/sessions.md "Faults").
bool RestartedByLauncher();

// The fastest a session's frames can go: the launcher's --speed is at most
// this many times the configured rate (docs/sessions.md).
inline constexpr double kMaxSessionSpeed = 100.0;

// The session's clock for frame-number checks (SequenceTracker::SetClock):
// RMSLAB_SESSION_EPOCH_US and rate_hz x kMaxSessionSpeed; inactive when the
// launcher set no epoch.
wire::FrameClock SessionFrameClock(double rate_hz);

void InstallStopHandlers();
// With RMSLAB_LIFELINE=stdin (set by the launcher), a thread waits on
// standard input and asks the process to stop when it closes: a session's
// processes never outlive their launcher (docs/sessions.md "The launcher").
void WatchLifeline();
bool StopRequested();
void RequestStop();

// The ready file launchers wait for (--ready-file): {"pid": N, "host": H,
// "cpu_wake_latency": what the request came to (CpuWakeLatencyRequest::state)},
// written whole (a temporary file renamed), so a reader never sees half of
// it; the launcher trusts the session's messages by these pids
// (docs/sessions.md "The launcher"). Throws InputError when it cannot.
void WriteReadyFile(const std::string& path);

// Latency histograms by link name, e.g. "input_to_dcp_us".
using LatencyMap = std::map<std::string, LatencyHistogram>;

// What a status report carries, by name: the counters the process touched
// and each link's latency as latency.LINK.count, .p50_us, .p99_us, .max_us.
std::map<std::string, std::int64_t> StatusFigures(const Counters& counters,
                                                  const LatencyMap& latencies);

// Publishes process_status_t on RMS_STATUS once a second (transport time)
// and once at exit.
class StatusReporter {
 public:
  StatusReporter(LcmInterface* lcm, std::string process);
  void Tick(std::int64_t frame, const Counters& counters, const LatencyMap& latencies = {});
  void Final(std::int64_t frame, const Counters& counters, const LatencyMap& latencies = {});

 private:
  void Publish(std::int64_t frame, const Counters& counters, const LatencyMap& latencies,
               bool final);
  LcmInterface* lcm_;
  std::string process_;
  std::string host_;
  std::int64_t last_us_ = 0;
};

// The transport's own counts into the process's counters:
// "dropped.other_session" (messages of another session) and "dropped.other_sender"
// (an impostor on a one-publisher channel), LcmInterface::Admit.
void NoteTransportCounters(const LcmInterface& lcm, Counters* counters);

// The main loop of a subscribing process: waits for messages (at most
// wait_ms, dispatching them to its handlers), calls `after_wait` after each
// wait, publishes the counters on RMS_STATUS once a second, and at SIGINT /
// SIGTERM publishes the final report and writes the stats file (if
// stats_path is set).
void RunNodeLoop(LcmInterface& lcm, const std::string& process, Counters& counters,
                 const LatencyMap& latencies, const std::function<std::int64_t()>& last_frame,
                 const std::function<void()>& after_wait, const std::string& stats_path,
                 int wait_ms = 100);

// Writes {"process":..., "cpu_wake_latency": what its request came to (as in
// the ready file), "counters":{...}, "latency_us":{NAME:{count,p50,p99,max,mean}}}.
void WriteStatsJson(const std::string& path, const std::string& process, const Counters& counters,
                    const LatencyMap& latencies);

}  // namespace rms::transport
