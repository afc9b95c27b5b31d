#pragma once
#include <optional>
#include <utility>
// dynamics_proc's LCM side: RMS_OPERATOR_INPUT in, RMS_DCP_FRAME out, one
// output frame per input block, counters and latency.
#include <string>
#include <vector>

#include "rms/base/counters.h"
#include "rms/dcp_model/dcp_telemetry.h"
#include "rms/dcp_model/dynamic_collision_program.h"
#include "rms/dcp_state_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/session_control_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/transport/process.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/frame_receiver.h"

namespace rms::dynamics_proc {

// The model this process runs (rms::dcp_model, docs/architecture.md).
using dcp_model::DcpStatus;
using dcp_model::DynamicCollisionProgram;
using dcp_model::MakeTelemetry;

class DynamicsProc {
 public:
  DynamicsProc(const LabConfig& config, transport::LcmInterface* lcm);
  // Handles one raw RMS_OPERATOR_INPUT message: malformed ones are counted
  // ("dropped.REASON") and dropped; a good one produces one RMS_DCP_FRAME.
  void OnInput(const void* data, int size, std::int64_t recv_time_us);

  const Counters& counters() const { return counters_; }
  Counters& counters() { return counters_; }
  const transport::LatencyMap& latencies() const { return latencies_; }
  std::int64_t last_frame() const { return next_frame_ - 1; }
  const DynamicCollisionProgram& program() const { return dcp_; }

  // Checkpoints (docs/sessions.md "Freeze, run, step, checkpoint"): the
  // DCP's state and the last operator inputs, to a file and back. Throw
  // rms::InputError naming the file and what is wrong.
  wire::Checkpoint MakeCheckpoint() const;
  void SaveCheckpoint(const std::string& path) const;
  void RestoreCheckpoint(const std::string& path);
  void Restore(const wire::Checkpoint& c, const std::string& what);
  // RMS_CONTROL's checkpoints live in this folder, by name only
  // (CheckpointFolder; docs/security.md "The control channel").
  void set_checkpoint_folder(wire::CheckpointFolder folder) { checkpoints_ = std::move(folder); }
  const wire::CheckpointFolder& checkpoint_folder() const { return checkpoints_; }
  // An RMS_CONTROL message: CHECKPOINT, RESTORE, MALFUNCTION and REPAIR
  // act (between frames), each kind at most CheckpointRateLimit's rate; a
  // bad or refused one is counted and logged, never fatal.
  void OnControl(const void* data, int size);

  // Process faults (docs/sessions.md "Faults"): with a state file, the node
  // writes its checkpoint there (atomically: a temporary file renamed) when
  // the mode, acquisition, docking or release changes and at least every
  // 0.5 s, and at exit; ResumeFromStateFile() restores it at start, so a
  // dynamics_proc restarted by the launcher goes on from its last state
  // (mode, payload attached, poses), not from Mode 1. Returns false when
  // there is no file yet; throws InputError for a bad one.
  void set_state_file(std::string path) { state_file_ = std::move(path); }
  bool ResumeFromStateFile();
  void WriteStateFile();
  // RMS_DCP_STATE (docs/protocol.md): the DCP's whole state now, with its
  // frame numbering, for a reader of the log (dcp_state_t::START, ...).
  // Sent at start (again every 0.5 s until the first frame), after a
  // restore or a resume, and every kStateEverySeconds of frames.
  static constexpr double kStateEverySeconds = 5.0;
  void PublishState(std::int8_t reason);
  // Whether the periodic RMS_DCP_STATE is sent (true unless set; a
  // re-simulation that writes no log sets false: nobody reads it, and the
  // checkpoint's JSON is most of its cost). The count to the next one runs
  // on either way.
  void set_periodic_states(bool on) { periodic_states_ = on; }
  // Re-simulation (docs/sessions.md "Re-simulation"): takes a logged
  // RMS_DCP_STATE as the live DCP had it, the state and its numbering; with
  // with_state false, the numbering only (another design's DCP keeps its
  // own state), and from a MALFUNCTION state the malfunctions in force
  // (MatchMalfunctions). Throws InputError for a checkpoint it cannot read.
  void ApplyState(const dcp_state_t& m, bool with_state);
  // Whether the node's frame numbering is the state's: what ApplyState would
  // set (the next DCP frame, the last operator frame, a resume pending).
  bool NumberingIs(const dcp_state_t& m) const;
  // The operator frames' numbers as received (docs/protocol.md "Frame
  // numbers"): which the next input must follow. No state carries it.
  const wire::SequenceTracker& input_sequence() const { return inputs_; }
  // The malfunctions in force become these (their text): those not among
  // them repaired, those new injected where this DCP's arm is now.
  void MatchMalfunctions(const std::vector<std::string>& texts);
  // Whether the node has made a frame since it started.
  bool made_a_frame() const { return made_a_frame_; }
  // The first DCP frame number to publish (FirstFrameNumber).
  void set_next_frame(std::int64_t f) { next_frame_ = f; }
  // A live session's receive checks (docs/protocol.md "Frame numbers and
  // times"): input frame numbers beyond the session clock refused,
  // inputs that waited too long dropped. Off in re-simulation, which must
  // answer exactly the inputs the recorded DCP answered.
  void EnableLiveChecks(double frame_rate_hz);

 private:
  void Report(const DcpStatus& status, std::int64_t frame);
  void OnMalfunction(const session_control_t& m);
  // Publishes the answer to `m` (RMS_CONTROL_ANSWER; docs/protocol.md).
  void Answer(const session_control_t& m, std::int8_t outcome, const std::string& text);
  const LabConfig& config_;
  transport::LcmInterface* lcm_;
  DynamicCollisionProgram dcp_;
  Counters counters_;
  transport::LatencyMap latencies_;
  wire::SequenceTracker inputs_;
  wire::LateFrameFilter late_;
  std::int64_t next_frame_ = 0;
  std::int64_t last_input_frame_ = -1;
  wire::OperatorInputs last_inputs_{};
  int last_mode_ = 0;
  std::uint32_t last_collisions_ = 0;
  std::string state_file_;
  wire::CheckpointFolder checkpoints_;
  wire::CheckpointRateLimit checkpoint_rate_;
  wire::CheckpointRateLimit malfunction_rate_;
  std::optional<std::pair<std::int64_t, std::int64_t>>
      resume_;  // (DCP frame, input frame) of the state resumed
  std::int64_t state_written_us_ = 0;
  std::int64_t frames_since_state_ = 0;
  bool periodic_states_ = true;
  bool made_a_frame_ = false;
  std::uint32_t state_key_ = 0;  // mode, acquired, docked, released: a change writes at once
};

// Main loop until SIGINT / SIGTERM. Returns the exit code.
// restore_path: a checkpoint to start from ("" for the initial state).
int RunDynamicsProc(const LabConfig& config, transport::LcmInterface& lcm,
                    const std::string& stats_path, const std::string& ready_path,
                    const std::string& restore_path, const std::string& state_file = "",
                    const std::string& checkpoint_dir = "");

}  // namespace rms::dynamics_proc
