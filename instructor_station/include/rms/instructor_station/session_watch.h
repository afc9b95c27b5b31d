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
  // Subscribes on `lcm` to RMS_DCP_FRAME, RMS_DCP_TELEMETRY, RMS_DCP_STATE,
  // RMS_STATUS and RMS_CONTROL. Malformed messages are counted in `counters` and dropped.
  SessionWatch(const LabConfig& config, transport::LcmInterface* lcm, Counters* counters);

  // The latest DCP frame (what the views are drawn from), if any yet.
  std::optional<wire::DcpFrameData> LatestDcpFrame() const;
  // Mode, collisions, acquisition conditions with margins, docking, the
  // processes' rates, latencies and losses (docs/instructor.md "/api/status").
  nlohmann::json StatusJson() const;
  // The events with seq >= since (all of them from 0: a late viewer sees the
  // session from its start), at most `limit`.
  nlohmann::json EventsJson(std::int64_t since, int limit) const;
  // The end effector's path (point A, R, ft), a point every few frames.
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
  void OnTelemetry(const void* data, int size);
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
    std::map<std::string, std::int64_t> figures;
  };
  std::map<std::string, Process> processes_;
  std::vector<Event> events_;
  std::vector<std::array<double, 4>> path_;  // session_s, x, y, z of point A in R, ft
  std::int64_t last_path_frame_ = -1000;
  std::vector<std::string> malfunctions_;  // in force, as the DCP's last state says
  std::uint32_t lost_stations_ = 0;
};

}  // namespace rms::instructor_station
