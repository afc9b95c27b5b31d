#pragma once
// operator_station: publishes the operator's input block (Table I) on
// RMS_OPERATOR_INPUT at the frame rate, from one source (input_sources.h): a
// timeline file, the hand controllers (keyboard, live window, gamepad, 3D
// mouse), or the autopilot; and what it does and shows on
// RMS_OPERATOR_STATE. It listens to the DCP's telemetry (guidance, the
// status screen, the autopilot), the processes' status reports (the screen's
// rates and latency), RMS_CONTROL (freeze, step, restore) and the live
// window's keys. docs/operator.md.
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>

#include "rms/base/config.h"
#include "rms/base/counters.h"
#include "rms/control_answer_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/lesson/lesson.h"
#include "rms/operator_input_t.hpp"
#include "rms/operator_station/follow_watch.h"
#include "rms/operator_station/guidance.h"
#include "rms/operator_station/input_sources.h"
#include "rms/operator_station/session_events.h"
#include "rms/operator_station/status_screen.h"
#include "rms/session_control_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/transport/process.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/input_block.h"

namespace rms::operator_station {

struct OperatorOptions {
  std::string timeline_path;  // --timeline FILE
  bool keyboard =
      false;  // --keyboard: by hand, the terminal's keyboard required (plus any other device)
  bool manual = false;     // --manual: by hand with whatever devices are found
  bool autopilot = false;  // --autopilot
  bool autopilot_straight =
      false;  // --autopilot-straight: no path planning, relieve collisions as they come
  std::string bindings_path;  // --bindings (default config/bindings.toml)
  bool gamepad = true;        // --no-gamepad: don't look for one
  bool spacemouse = true;     // --no-spacemouse: don't look for one
  bool window_keys = false;   // --window-keys: fly from the live window's keys (RMS_WINDOW_KEYS)
  int status = -1;       // --status / --no-status (-1: on when by hand and stdout is a terminal)
  double rate_hz = 0.0;  // --rate (0: config session.frame_rate_hz)
  bool hold = false;     // --hold: keep publishing after the timeline's end / docking
  double speed = 1.0;  // --speed: timeline seconds per wall-clock second (frames stay at the rate)
  std::int64_t max_frames = -1;  // --frames N: stop after N frames (-1: no limit)
  // --end-when-docked S: by hand, stop S s after docking (-1: never)
  double end_when_docked_s = -1;
  std::string lesson_path;  // --lesson FILE: scripted events (docs/lessons.md)
  std::string
      restore_path;  // --restore CHECKPOINT: start from its operator inputs (by hand, autopilot)
  std::string
      checkpoint_dir;  // --checkpoint-dir: RMS_CONTROL's RESTORE names a checkpoint here only
  // --dcp-state-file: the DCP's state file (dynamics_proc --state-file); a
  // restarted station (RMSLAB_RESTART) sends the inputs it holds from its
  // first frame, not the task's initial ones (docs/sessions.md "Faults").
  std::string dcp_state_path;
};

// Builds the numbered, time-stamped input blocks.
class InputBlockBuilder {
 public:
  explicit InputBlockBuilder(const InputCalibrations& cal) : cal_(cal) {}
  operator_input_t Build(const wire::OperatorInputs& in, std::int64_t send_time_us,
                         Counters* counters);
  std::int64_t next_frame() const { return next_frame_; }
  void set_next_frame(std::int64_t f) { next_frame_ = f; }

 private:
  const InputCalibrations& cal_;
  std::int64_t next_frame_ = 0;
};

// Exit codes: 0 done (the timeline's end, docked, quit); 2 a bad option or
// file; 3 the autopilot failed; 130 stopped by SIGINT / SIGTERM.
inline constexpr int kExitAutopilotFailed = 3;
inline constexpr int kExitInterrupted = 130;

// The source the options ask for (exactly one); throws rms::InputError.
std::unique_ptr<InputSource> MakeSource(const OperatorOptions& options, const LabConfig& config);
// Checks the files the options name (the bindings, the timeline, the
// checkpoint) without opening a device; throws rms::InputError naming what
// is wrong (operator_station --check).
void CheckSourceFiles(const OperatorOptions& options, const LabConfig& config);

class OperatorStation {
 public:
  OperatorStation(const OperatorOptions& options, const LabConfig& config,
                  transport::LcmInterface& lcm, std::unique_ptr<InputSource> source);
  // Runs until the source is done, quit or a stop signal; the exit code.
  int Run(const std::string& stats_path, const std::string& ready_path);
  const Counters& counters() const { return counters_; }

 private:
  void ResumeFromTelemetry();
  void ResumeFromDcpState();
  // The session's clock as this station last left it (frozen or not, the
  // next frame, when), beside the DCP's state file: a restarted station
  // resumes a freeze and does not count frozen time (docs/sessions.md "Faults").
  std::string ClockFilePath() const;
  void WriteClockFileOnChange();
  bool StepFrame(transport::StatusReporter* status);
  int Finish(const std::string& stats_path, transport::StatusReporter* status);
  void Subscribe();
  void OnTelemetry(const void* data, int size, std::int64_t recv_us);
  void OnStatus(const void* data, int size, std::int64_t recv_us);
  void OnControl(const void* data, int size, std::int64_t recv_us);
  void OnWindowKeys(const void* data, int size, std::int64_t recv_us);
  void SendControl(std::int8_t command, const std::string& name = "");
  // Publishes the answer to `m` (RMS_CONTROL_ANSWER; docs/protocol.md).
  void Answer(const session_control_t& m, std::int8_t outcome, const std::string& text);
  // The lesson's events due this frame, sent (docs/lessons.md).
  void FireLessonEvents();
  // RESTORE (docs/sessions.md "Freeze, run, step, checkpoint"): taken only
  // once dynamics_proc has answered it done, refused when it refused.
  void OnControlAnswer(const void* data, int size, std::int64_t recv_us);
  void SettleRestores();
  void ApplyRestore(const session_control_t& m);
  bool Holding() const { return frozen_ || !restores_waiting_.empty(); }
  // Drops the telemetry heard so far: after a reset or a restore nothing of
  // the frames before it is shown or flown on.
  void ForgetTelemetry(std::int64_t fresh_from_input_frame);
  bool RunFrozen();  // false: quit
  void PublishState(std::int64_t frame, const std::optional<Guidance>& guidance);
  void DrawScreen(std::int64_t frame, const wire::OperatorInputs& in, bool frozen);
  std::optional<Guidance> CurrentGuidance() const;
  void WatchClearance(const std::optional<Guidance>& guidance);

  const OperatorOptions& options_;
  const LabConfig& config_;
  transport::LcmInterface& lcm_;
  std::unique_ptr<InputSource> source_;
  GuidanceGeometry geometry_;
  double rate_hz_;
  std::int64_t period_ns_;
  Counters counters_;
  InputBlockBuilder builder_;
  std::unique_ptr<StatusScreen> screen_;
  TelemetryEvents events_;
  FollowWatch follow_;
  bool clearance_warned_ = false;

  // What the DCP and the other processes say.
  std::optional<dcp_telemetry_t> telemetry_;
  std::optional<lesson::Lesson> lesson_;
  std::int64_t run_again_at_us_ = 0;  // a lesson's freeze for_s: when to send RUN (0: none)
  // The telemetry's frame numbers: a frame beyond the session's clock is
  // refused (dropped.far_ahead), so one forged frame far ahead cannot make
  // every real one after it stale (docs/protocol.md "Frame numbers").
  wire::SequenceTracker telemetry_seq_;
  std::int64_t fresh_from_input_frame_ =
      -1;  // telemetry answering an older input is from before a reset / restore
  struct RateMeter {
    void Tick(std::int64_t now_us);
    double hz() const { return hz_; }
    std::int64_t t0_us = 0, count = 0;
    double hz_ = 0.0;
  };
  RateMeter publish_rate_, telemetry_rate_;
  double input_to_dcp_ms_ = -1.0, render_hz_ = -1.0, render_p50_ms_ = -1.0, render_p99_ms_ = -1.0;
  std::int64_t esg_rendered_ = -1, esg_status_us_ = 0;

  // RMS_CONTROL.
  bool frozen_ = false;
  int steps_pending_ = 0;
  bool clock_written_frozen_ = false;  // what the clock file says (none: running)
  std::int64_t clock_written_frame_ = -1;
  bool reset_pending_ = false;  // RMS_CONTROL RESET: the next frame's reset button
  // RESTOREs waiting for dynamics_proc's answer (the station holds its frame
  // meanwhile), and the DCP's answers heard before their command.
  struct WaitingRestore {
    session_control_t command;
    std::int64_t since_us = 0;
  };
  std::deque<WaitingRestore> restores_waiting_;
  std::deque<control_answer_t> dcp_restore_answers_;
  wire::CheckpointFolder checkpoints_;
  std::int64_t control_sequence_ = 0;
  std::int64_t frames_ = 0;
  wire::OperatorInputs last_;  // the last inputs published
};

}  // namespace rms::operator_station
