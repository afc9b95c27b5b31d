#pragma once
// What the instructor station knows of the session, from the session's own
// channels (docs/instructor.md "Status and events"): the latest DCP frame and
// telemetry, each process's status reports, the end effector's path, and the
// events since the session began -- mode changes, acquisition, docking,
// collisions, holds, resets, control commands (freeze, run, step,
// checkpoint, restore, malfunction, repair), malfunctions the DCP took, a
// part the operator station saw not following its command, processes that
// started, restarted or ended. Fed by
// the LCM thread; read by the web server's threads (every method locks).
//
// Bounded whatever arrives (docs/instructor.md "Bounds"): at most
// kMaxProcesses processes, each taken only from a status whose name and pid
// are its sender's; the last kMaxEvents events and kMaxPathPoints points
// of the path; frames and telemetry numbered beyond the session's clock
// refused, as the operator station refuses them.
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rms/base/config.h"
#include "rms/base/counters.h"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/frame_numbers.h"
#include "rms/wire/word_blocks.h"

namespace rms::instructor_station {

struct Event {
  std::int64_t seq = 0;      // 0, 1, 2 ... in the order seen
  std::int64_t wall_us = 0;  // wall clock when seen, us since 1970
  double session_s = 0.0;    // the session's time (DCP frame / frame rate) when seen
  std::string kind;          // "mode", "acquired", "docked", "collision", "hold", "reset",
                             // "control", "process"
  std::string text;          // what a person reads
};

class SessionWatch {
 public:
  static constexpr std::size_t kMaxProcesses = 16;
  static constexpr std::size_t kMaxEvents = 10000;
  static constexpr std::size_t kMaxPathPoints = 20000;
  // Each answer: at most this many events or points (the page asks again from where it ended).
  static constexpr int kMaxEventsAnswer = 1000;
  static constexpr std::size_t kMaxPathAnswer = 5000;
  // Of a process's latency figures, at most this many are kept.
  static constexpr std::size_t kMaxLatencyFigures = 32;

  // Subscribes on `lcm` to RMS_DCP_FRAME, RMS_DCP_TELEMETRY, RMS_DCP_STATE,
  // RMS_STATUS and RMS_CONTROL. Malformed messages are counted in `counters` and dropped.
  SessionWatch(const LabConfig& config, transport::LcmInterface* lcm, Counters* counters);

  // The latest DCP frame (what the views are drawn from), if any yet.
  std::optional<wire::DcpFrameData> LatestDcpFrame() const;
  // The latest telemetry believed (in sequence, within the session's clock).
  std::optional<dcp_telemetry_t> LatestTelemetry() const;
  // Mode, collisions, acquisition conditions with margins, docking, the
  // processes' rates, latencies and losses (docs/instructor.md "/api/status").
  nlohmann::json StatusJson() const;
  // The events with seq >= since (all those kept from 0: a late viewer sees
  // the session from its start, or from the oldest event kept), at most
  // min(limit, kMaxEventsAnswer).
  nlohmann::json EventsJson(std::int64_t since, int limit) const;
  // The end effector's path (point A, R, ft), a point every few frames:
  // {"first": index of the oldest point kept, "next": the index after the
  // last point in this answer, "points": at most kMaxPathAnswer}.
  nlohmann::json PathJson(std::size_t since) const;
  std::int64_t events_seen() const;
  // The camera stations lost (docs/sessions.md "Malfunctions"), bit k-1 for
  // station k, as the DCP's last state says.
  std::uint32_t LostStations() const;

  // Called by the web server for commands it sends (also heard back on
  // RMS_CONTROL; this says who asked).
  void NoteLocal(const std::string& kind, const std::string& text);

 private:
  void OnDcpFrame(const void* data, int size, std::int64_t recv_us);
  void OnTelemetry(const void* data, int size, std::int64_t recv_us);
  void OnStatus(const void* data, int size);
  void OnControl(const void* data, int size);
  void OnDcpState(const void* data, int size);
  void AddEvent(const std::string& kind, const std::string& text);  // mu_ held
  void TelemetryEvents(const dcp_telemetry_t& t);                   // mu_ held

  const LabConfig& config_;
  transport::LcmInterface* lcm_;
  Counters* counters_;
  const std::string instance_;  // pid and start time of this station
  mutable std::mutex mu_;
  wire::SequenceTracker dcp_frames_;
  wire::SequenceTracker telemetry_seq_;
  std::optional<wire::DcpFrameData> dcp_;
  bool reset_bit_ = false;
  std::optional<dcp_telemetry_t> telemetry_;
  struct Process {
    std::int32_t pid = 0;
    std::string host;
    std::int64_t frame = 0;
    std::int64_t last_us = 0;  // when its last report came (wall clock)
    double rate_hz = 0.0;      // frames a second between its last two reports
    bool ended = false;
    std::int64_t dropped = 0;  // the sum of its dropped.* counters
    std::int64_t not_following = 0;
    std::map<std::string, std::int64_t> figures;  // the counters StatusJson shows
    std::map<std::string, std::int64_t> latency;  // latency.*.p50_us / p99_us, at most
                                                  // kMaxLatencyFigures
  };
  bool TakeStatus(const process_status_t& m);  // mu_ held; false: refused
  std::map<std::string, Process> processes_;
  std::deque<Event> events_;                // the last kMaxEvents
  std::int64_t next_event_seq_ = 0;         // seq of the next event
  std::deque<std::array<double, 4>> path_;  // session_s, x, y, z of point A in R, ft
  std::size_t path_first_ = 0;              // index of path_.front()
  std::int64_t last_path_frame_ = -1000;
  std::vector<std::string> malfunctions_;  // in force, as the DCP's last state says
  std::uint32_t lost_stations_ = 0;
};

}  // namespace rms::instructor_station
