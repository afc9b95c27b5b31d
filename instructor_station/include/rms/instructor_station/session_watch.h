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
#include <initializer_list>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "rms/base/config.h"
#include "rms/base/counters.h"
#include "rms/control_answer_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/operator_state_t.hpp"
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
                             // "control", "answer", "process", "failure", "malfunction",
                             // "lesson", "mark", "station"
  std::string text;          // what a person reads
};

// The session's state as the banner says it (docs/instructor.md "The
// banner"), from the operator station's answers and the processes' reports.
struct SessionState {
  bool frozen = false;
  std::int64_t frozen_wall_us = 0;  // when it froze (wall clock)
  double frozen_session_s = 0.0;    // at what session time
  bool ended = false;               // the operator station sent its final report
  std::int64_t ended_wall_us = 0;
  std::string ended_how;  // "docked at 63.2 s", "ended without docking"
};

// One of this station's own commands and the answers it has had
// (RMS_CONTROL_ANSWER): the page shows each outcome, never "sent".
struct CommandRecord {
  // Its sequence: with `pid`, its id on the wire. A restarted station goes
  // on from the last sequence its earlier instances sent (NextCommandId), so
  // a page's id means one command through restarts.
  std::int64_t id = 0;
  std::int32_t pid = 0;  // the station that sent it (this one, or an earlier instance)
  std::int8_t command = 0;
  std::string name;
  std::int64_t sent_wall_us = 0;
  std::vector<std::string> expected;  // the processes that answer it
  struct Heard {
    std::string process;
    bool done = false;
    std::string text;
  };
  std::vector<Heard> answers;
};

// A point of the live plots (docs/instructor.md "Plots"), every few DCP
// frames: the distance to the goal (Mode 1: to the grasp on the BAR, from
// the operator station's guidance; Modes 2 and 3: the probe to the port)
// and each acquisition margin.
struct PlotPoint {
  double session_s = 0.0;
  std::int64_t frame = 0;
  int mode = 0;
  double goal_ft = 0.0;  // NaN: not known
  std::array<double, 6> margin_ft{};
  double dock_angle_deg = 0.0;
};

class SessionWatch {
 public:
  static constexpr std::size_t kMaxProcesses = 16;
  static constexpr std::size_t kMaxEvents = 10000;
  static constexpr std::size_t kMaxPathPoints = 20000;
  static constexpr std::size_t kMaxPlotPoints = 20000;
  // DCP frames kept for the debrief's scrubbing: an hour at 30 Hz.
  static constexpr std::size_t kMaxHistoryFrames = 108000;
  static constexpr std::size_t kMaxCommands = 200;
  static constexpr std::size_t kMaxMarks = 1000;
  static constexpr std::size_t kMaxMarkLineBytes = 4096;
  static constexpr std::size_t kMaxMarkTextBytes = 500;
  static constexpr double kMaxMarkSessionS = 1e7;
  // Each answer: at most this many events or points (the page asks again from where it ended).
  static constexpr int kMaxEventsAnswer = 1000;
  static constexpr std::size_t kMaxPathAnswer = 5000;
  // Of a process's latency figures, at most this many are kept.
  static constexpr std::size_t kMaxLatencyFigures = 32;

  // Subscribes on `lcm` to RMS_DCP_FRAME, RMS_DCP_TELEMETRY, RMS_DCP_STATE,
  // RMS_STATUS, RMS_CONTROL, RMS_CONTROL_ANSWER and RMS_OPERATOR_STATE
  // (unless `live` is false: a debrief, fed from the log alone).
  // Malformed messages are counted in `counters` and dropped.
  SessionWatch(const LabConfig& config, transport::LcmInterface* lcm, Counters* counters,
               bool live = true);

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

  // A command of this station's about to be sent: its answers are kept
  // (CommandJson).
  void NoteCommand(std::int64_t id, std::int8_t command, const std::string& name);
  // The id this station's next command takes: after every one an earlier
  // instance of it sent (read back from the log), so ids never repeat.
  std::int64_t NextCommandId() const;
  // {id, command, name, state: pending|done|refused|unanswered, answers}.
  nlohmann::json CommandJson(std::int64_t id) const;

  // The plots' points from index `since` ({first, next, points}, as PathJson).
  nlohmann::json PlotJson(std::size_t since) const;
  // The DCP frame `frame`, or the nearest kept at or before it, with the
  // `lead` frames before it (the camera drive's run-up) and the camera
  // stations lost then; empty when none is kept.
  struct PastFrames {
    std::vector<wire::DcpFrameData> frames;  // oldest first; the last is the one asked for
    std::uint32_t lost_stations = 0;
  };
  PastFrames HistoryAt(std::int64_t frame, std::size_t lead) const;
  // The DCP frames kept: {first, last} frame numbers ({-1, -1}: none).
  std::pair<std::int64_t, std::int64_t> HistoryRange() const;

  // The session's log read into this watch (a restarted station, or a
  // debrief: docs/instructor.md "A restarted station", "Debrief"): every
  // message of the session's own, through the same handlers, in log order.
  // Returns how many messages were taken. A status of an instructor
  // station with another pid means this station is a restart.
  std::int64_t ReadLog(const std::string& session_dir);
  // True when the log read showed an earlier run of this station.
  bool restarted() const;
  // Marks placed by the instructor (docs/instructor.md "Marks"): each an
  // event of kind "mark" at its session time, kept in `marks_path`
  // (JSON lines) when given, and read from it at start.
  void SetMarksFile(const std::string& marks_path);
  nlohmann::json AddMark(double session_s, const std::string& text);
  nlohmann::json MarksJson() const;

 private:
  void OnDcpFrame(const void* data, int size, std::int64_t recv_us);
  void OnTelemetry(const void* data, int size, std::int64_t recv_us);
  void OnStatus(const void* data, int size);
  void OnControl(const void* data, int size);
  void OnDcpState(const void* data, int size);
  void OnAnswer(const void* data, int size);
  void OnOperatorState(const void* data, int size);
  void AddEvent(const std::string& kind, const std::string& text);  // mu_ held
  void TelemetryEvents(const dcp_telemetry_t& t);                   // mu_ held
  void TelemetryPlot(const dcp_telemetry_t& t);                     // mu_ held
  void Score(const dcp_telemetry_t& t);                             // mu_ held
  std::string NotFollowingWhat() const;                             // mu_ held
  nlohmann::json OperatorJson() const;                              // mu_ held
  nlohmann::json WarningsJson() const;                              // mu_ held
  nlohmann::json StateJson() const;                                 // mu_ held
  std::int64_t Now() const;  // the wall clock, or the log's time while reading it
  void ReadLogFile(const std::string& session_dir, const std::string& name,
                   std::initializer_list<std::string_view> channels, std::int64_t* taken);
  void SortEvents();                                 // mu_ held
  double LogSessionTime(std::int64_t log_us) const;  // mu_ held

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
  // Commands already seen, by id (process, pid, sequence), and their
  // answers by answerer: a log read and live traffic that overlap count once.
  std::set<std::tuple<int, std::int32_t, std::int64_t>> commands_seen_;
  std::set<std::tuple<int, std::int32_t, std::int64_t, int>> answers_seen_;
  std::map<std::tuple<int, std::int32_t, std::int64_t>, std::string> command_texts_;
  // With mu_ held: one of this station's commands, or an earlier instance's.
  void RecordCommand(std::int64_t id, std::int32_t pid, std::int8_t command,
                     const std::string& name, std::int64_t wall_us);
  std::int64_t next_command_id_ = 0;
  std::deque<CommandRecord> own_commands_;  // the last kMaxCommands of this station's
  SessionState state_;
  std::optional<operator_state_t> operator_;
  std::deque<PlotPoint> plot_;
  std::size_t plot_first_ = 0;
  std::deque<wire::DcpFrameData> history_;  // the last kMaxHistoryFrames DCP frames
  std::deque<std::uint32_t> history_lost_;  // the stations lost at each
  // The live scorecard (docs/instructor.md "Scorecard"), from the telemetry.
  struct Scorecard {
    int attempts = 1;
    std::int64_t frames = 0;
    std::array<std::int64_t, 4> mode_frames{};  // by mode 0..3
    int collisions = 0;                         // detrimental collisions begun
    std::int64_t collision_frames = 0;
    int holds = 0;
    double acquired_s = -1, docked_s = -1;  // session time of the first (this attempt)
    int malfunctions = 0;
    double min_goal_ft = -1;
  } score_;
  bool reading_log_ = false;
  std::int64_t log_now_us_ = 0;
  double log_session_s_ = 0.0;  // the session time of the log message being read
  // (recorder time, session time) at each change, of the network log read:
  // the session time of a journal's messages.
  std::vector<std::pair<std::int64_t, double>> log_times_;
  bool restarted_ = false;
  bool debrief_ = false;
  std::string marks_path_;
  std::string session_dir_;  // the session's folder, once its log is read
  std::vector<nlohmann::json> marks_;
};

}  // namespace rms::instructor_station
