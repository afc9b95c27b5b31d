#include "rms/dynamics_proc/dynamics_proc.h"

#include <algorithm>
#include <filesystem>
#include <spdlog/spdlog.h>

#include "rms/base/check.h"
#include "rms/control_answer_t.hpp"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/operator_input_t.hpp"
#include "rms/session_control_t.hpp"
#include "rms/wire/acquisition_conditions.h"
#include "rms/wire/channels.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/frame_receiver.h"
#include "rms/wire/malfunction.h"
#include "rms/wire/message_io.h"

namespace rms::dynamics_proc {

using namespace dcp_model;  // NOLINT(google-build-using-namespace): the model this node runs

DynamicsProc::DynamicsProc(const LabConfig& config, transport::LcmInterface* lcm)
    : config_(config), lcm_(lcm), dcp_(config) {
  lcm_->Subscribe(wire::channels::kOperatorInput,
                  [this](const void* d, int n, std::int64_t t) { OnInput(d, n, t); });
  lcm_->Subscribe(wire::channels::kControl,
                  [this](const void* d, int n, std::int64_t) { OnControl(d, n); });
}

wire::Checkpoint DynamicsProc::MakeCheckpoint() const {
  wire::Checkpoint c;
  c.dcp_frame = next_frame_ - 1;
  c.input_frame = last_input_frame_;
  c.saved_us = transport::WallTimeUs();
  c.config = config_.source;
  c.inputs = last_inputs_;
  c.dcp = dcp_.SaveState();
  return c;
}

void DynamicsProc::SaveCheckpoint(const std::string& path) const {
  wire::WriteCheckpoint(path, MakeCheckpoint());
}

void DynamicsProc::RestoreCheckpoint(const std::string& path) {
  Restore(wire::ReadCheckpoint(path), path);
}

namespace {

// A checkpoint whose arm (the command or the slave) is beyond a joint's
// limits (config [arm]) is a pose the arm cannot reach: refused
// (docs/sessions.md "Freeze, run, step, checkpoint"). Malformed angles are
// left to RestoreState, which names them.
void CheckJointLimits(const nlohmann::json& dcp, const LabConfig& config) {
  for (const char* who : {"master", "slave"}) {
    if (!dcp.is_object() || !dcp.contains(who) || !dcp[who].is_object()) continue;
    const nlohmann::json& a = dcp[who].value("angles_deg", nlohmann::json());
    if (!a.is_array() || a.size() != static_cast<std::size_t>(kNumJoints)) continue;
    for (int i = 0; i < kNumJoints; ++i) {
      if (!a[i].is_number()) continue;
      const double v = a[i].get<double>(), lo = config.arm.joint_min_deg[i],
                   hi = config.arm.joint_max_deg[i];
      if (v < lo - 1e-9 || v > hi + 1e-9)
        throw InputError(fmt::format(
            "checkpoint: the {} arm's joint {} ({}) at {:.3f} deg, beyond its limits {:.1f} .. "
            "{:.1f} deg (config [arm]): a pose the arm cannot reach",
            std::string(who) == "master" ? "commanded" : "slave", i + 1, kJointNames[i], v, lo,
            hi));
    }
  }
}

}  // namespace

void DynamicsProc::Restore(const wire::Checkpoint& c, const std::string& what) {
  try {
    CheckJointLimits(c.dcp, config_);
    dcp_.RestoreState(c.dcp);
  } catch (const std::exception& e) {
    throw InputError("checkpoint '" + what + "': " + e.what());
  }
  spdlog::info("restored the DCP's state from {} (saved at DCP frame {}): Mode {}{}{}", what,
               c.dcp_frame, wire::ModeNumber(dcp_.status().mode),
               dcp_.status().acquired ? ", acquired" : "", dcp_.status().docked ? ", docked" : "");
}

void DynamicsProc::PublishState(std::int8_t reason) {
  dcp_state_t m{};
  m.send_time_us = lcm_->NowUs();
  m.reason = reason;
  m.next_frame = next_frame_;
  m.input_frame = last_input_frame_;
  m.resume_pending = resume_.has_value();
  m.resume_dcp_frame = resume_ ? resume_->first : -1;
  m.resume_input_frame = resume_ ? resume_->second : -1;
  m.checkpoint = wire::CheckpointText(MakeCheckpoint());
  if (transport::PublishMessage(*lcm_, wire::channels::kDcpState, m))
    counters_.Add(Counter::kStatePublished);
  else
    counters_.Add(Counter::kPublishFailed);
  frames_since_state_ = 0;
}

void DynamicsProc::ApplyState(const dcp_state_t& m, bool with_state) {
  if (with_state) {
    const wire::Checkpoint c = wire::ParseCheckpoint(m.checkpoint, "RMS_DCP_STATE");
    try {
      dcp_.RestoreState(c.dcp);
    } catch (const std::exception& e) {
      throw InputError(std::string("RMS_DCP_STATE: ") + e.what());
    }
    last_inputs_ = c.inputs;
  } else if (m.reason == dcp_state_t::MALFUNCTION) {
    // Another design keeps its own state but fails as the recorded one did.
    const wire::Checkpoint c = wire::ParseCheckpoint(m.checkpoint, "RMS_DCP_STATE");
    MatchMalfunctions(wire::MalfunctionTexts(c.dcp));
  }
  next_frame_ = m.next_frame;
  last_input_frame_ = m.input_frame;
  if (m.resume_pending)
    resume_ = std::pair{m.resume_dcp_frame, m.resume_input_frame};
  else
    resume_.reset();
  frames_since_state_ = 0;
}

bool DynamicsProc::NumberingIs(const dcp_state_t& m) const {
  return next_frame_ == m.next_frame && last_input_frame_ == m.input_frame &&
         resume_.has_value() == static_cast<bool>(m.resume_pending) &&
         (!resume_ ||
          (resume_->first == m.resume_dcp_frame && resume_->second == m.resume_input_frame));
}

void DynamicsProc::MatchMalfunctions(const std::vector<std::string>& texts) {
  const std::vector<wire::Malfunction> now = dcp_.malfunctions().active();
  std::vector<wire::Malfunction> want;
  try {
    for (const std::string& t : texts) want.push_back(wire::ParseMalfunction(t));
  } catch (const InputError& e) {
    throw InputError(std::string("RMS_DCP_STATE: ") + e.what());
  }
  auto in = [](const std::vector<wire::Malfunction>& v, const wire::Malfunction& m) {
    return std::find(v.begin(), v.end(), m) != v.end();
  };
  for (const wire::Malfunction& m : now) {
    if (!in(want, m)) dcp_.Repair(wire::RepairFor(m));
  }
  for (const wire::Malfunction& m : want) {
    if (!in(now, m)) dcp_.Inject(m);
  }
}

bool DynamicsProc::ResumeFromStateFile() {
  if (state_file_.empty() || !std::filesystem::exists(state_file_)) return false;
  const wire::Checkpoint c = wire::ReadCheckpoint(state_file_);
  try {
    dcp_.RestoreState(c.dcp);
  } catch (const std::exception& e) {
    throw InputError("state file '" + state_file_ + "': " + e.what());
  }
  // The DCP frames are one to one with the operator's: the first input
  // after the resume sets the numbering, so the scene sees as missing exactly
  // the inputs that came while this process was down.
  next_frame_ = c.dcp_frame + 1;
  resume_ = std::pair{c.dcp_frame, c.input_frame};
  last_inputs_ = c.inputs;
  counters_.Add(Counter::kResumed);
  spdlog::warn("resumed from the last state written ({}, DCP frame {}): Mode {}{}{}", state_file_,
               c.dcp_frame, wire::ModeNumber(dcp_.status().mode),
               dcp_.status().acquired ? ", payload attached" : "",
               dcp_.status().docked ? ", docked" : "");
  return true;
}

void DynamicsProc::WriteStateFile() {
  if (state_file_.empty()) return;
  const std::string tmp = state_file_ + ".tmp";
  try {
    SaveCheckpoint(tmp);
    std::filesystem::rename(tmp, state_file_);
    counters_.Add(Counter::kStateFileWrites);
  } catch (const std::exception& e) {
    counters_.Add(Counter::kStateFileErrors);
    spdlog::error("cannot write the state file: {}", e.what());
  }
  state_written_us_ = lcm_->NowUs();
}

// Every command this process acts on is answered, done or refused with the
// reason, on RMS_CONTROL_ANSWER (docs/protocol.md): the sender, and the
// log, know what took effect.
void DynamicsProc::Answer(const session_control_t& m, std::int8_t outcome,
                          const std::string& text) {
  const control_answer_t a = wire::MakeControlAnswer(m, outcome, next_frame_, text);
  counters_.Add(transport::PublishMessage(*lcm_, wire::channels::kControlAnswer, a)
                    ? Counter::kPublished
                    : Counter::kPublishFailed);
}

void DynamicsProc::OnControl(const void* data, int size) {
  session_control_t m;
  if (wire::SafeDecode(data, size, &m) != wire::DecodeError::kNone) {
    counters_.Add(Counter::kDroppedControlMalformed);
    return;
  }
  if (m.command == session_control_t::MALFUNCTION || m.command == session_control_t::REPAIR) {
    OnMalfunction(m);
    return;
  }
  if (m.command != session_control_t::CHECKPOINT && m.command != session_control_t::RESTORE) return;
  // The name is the sender's (docs/security.md "The control channel"): it
  // is looked up in the session's checkpoints folder only, a few times a
  // second at most.
  if (!checkpoint_rate_.Allow(lcm_->NowUs())) {
    if (counters_.Get(Counter::kControlRateLimited) == 0) {
      spdlog::warn("checkpoint commands refused: more than {} a second (control.rate_limited)",
                   wire::CheckpointRateLimit::kPerSecond);
    }
    counters_.Add(Counter::kControlRateLimited);
    Answer(m, control_answer_t::REFUSED,
           "more than " + std::to_string(wire::CheckpointRateLimit::kPerSecond) +
               " checkpoints or restores a second: try again");
    return;
  }
  try {
    if (m.command == session_control_t::CHECKPOINT) {
      checkpoints_.Write(m.name, MakeCheckpoint());
      counters_.Add(Counter::kControlCheckpoints);
      spdlog::info("checkpoint: DCP frame {} saved as {}", next_frame_ - 1,
                   checkpoints_.PathOf(m.name));
      Answer(m, control_answer_t::DONE,
             "saved DCP frame " + std::to_string(next_frame_ - 1) + " as " + m.name);
    } else {
      Restore(checkpoints_.Read(m.name), checkpoints_.PathOf(m.name));
      counters_.Add(Counter::kControlRestores);
      PublishState(dcp_state_t::RESTORE);
      Answer(m, control_answer_t::DONE,
             "restored " + m.name + ": Mode " +
                 std::to_string(wire::ModeNumber(dcp_.status().mode)) +
                 (dcp_.status().acquired ? ", acquired" : "") +
                 (dcp_.status().docked ? ", docked" : ""));
    }
  } catch (const InputError& e) {
    counters_.Add(Counter::kControlRefused);
    spdlog::error("{}", e.what());
    Answer(m, control_answer_t::REFUSED, e.what());
  }
}

// docs/sessions.md "Malfunctions": taken between frames, and logged with
// the state from which the next frame has it (and written to the state file
// at once, so a restarted DCP keeps it). Injections at most
// CheckpointRateLimit's rate (each sends the DCP's state to the log);
// repairs always (one sends a state only when it clears something, and
// nothing is in force that was not injected).
void DynamicsProc::OnMalfunction(const session_control_t& m) {
  if (m.command == session_control_t::MALFUNCTION && !malfunction_rate_.Allow(lcm_->NowUs())) {
    if (counters_.Get(Counter::kControlRateLimited) == 0) {
      spdlog::warn("malfunction commands refused: more than {} a second (control.rate_limited)",
                   wire::CheckpointRateLimit::kPerSecond);
    }
    counters_.Add(Counter::kControlRateLimited);
    Answer(m, control_answer_t::REFUSED,
           "more than " + std::to_string(wire::CheckpointRateLimit::kPerSecond) +
               " malfunctions a second: try again");
    return;
  }
  const char* from = wire::ProcessCodeName(m.sender.process);
  std::string done;
  try {
    if (m.command == session_control_t::MALFUNCTION) {
      const wire::Malfunction f = wire::ParseMalfunction(m.name);
      dcp_.Inject(f);
      counters_.Add(Counter::kControlMalfunctions);
      done = wire::MalfunctionText(f) + ", from DCP frame " + std::to_string(next_frame_);
      spdlog::warn("malfunction from {}: {}", from, done);
    } else {
      const wire::Repair r = wire::ParseRepair(m.name);
      const std::size_t before = dcp_.malfunctions().active().size();
      dcp_.Repair(r);
      if (dcp_.malfunctions().active().size() == before) {
        throw InputError(wire::RepairText(r) == "all"
                             ? std::string("nothing to repair: no malfunction is in force")
                             : "nothing to repair: no malfunction of '" + wire::RepairText(r) +
                                   "' is in force");
      }
      counters_.Add(Counter::kControlRepairs);
      done = wire::RepairText(r) + ", from DCP frame " + std::to_string(next_frame_);
      spdlog::info("repair from {}: {}", from, done);
      done.insert(0, "repaired ");
    }
  } catch (const InputError& e) {
    counters_.Add(Counter::kControlRefused);
    spdlog::error("{} from {} refused: {}", wire::ControlCommandName(m.command), from, e.what());
    Answer(m, control_answer_t::REFUSED, e.what());
    return;
  }
  PublishState(dcp_state_t::MALFUNCTION);
  WriteStateFile();
  Answer(m, control_answer_t::DONE, done);
}

void DynamicsProc::EnableLiveChecks(double frame_rate_hz) {
  inputs_.SetClock(transport::SessionFrameClock(frame_rate_hz));
  late_ = wire::LateFrameFilter(frame_rate_hz);
}

void DynamicsProc::OnInput(const void* data, int size, std::int64_t recv_time_us) {
  // Live, the age is taken as the input is handled (a stopped process's
  // queue is handled on waking, long after it arrived); from a log, the
  // log's time.
  const std::int64_t now_us = late_.enabled() ? lcm_->NowUs() : recv_time_us;
  auto got = wire::ReceiveFrame<operator_input_t>(
      data, size, &inputs_, &counters_,
      [this](const operator_input_t& m) {
        std::array<std::int32_t, wire::kInputWords> words{};
        std::copy(m.words, m.words + wire::kInputWords, words.begin());
        return wire::DecodeInputs(words, config_.inputs, &counters_);
      },
      now_us, &late_);
  if (!got) return;
  const auto& [msg, in] = *got;
  counters_.Set(Counter::kInputMissing, inputs_.missing());
  RecordEndToEnd(now_us - msg.send_time_us, config_.session.frame_rate_hz,
                 &latencies_["input_to_dcp"], &counters_);

  if (resume_) {
    if (msg.frame > resume_->second) next_frame_ = resume_->first + (msg.frame - resume_->second);
    resume_.reset();
  }
  last_inputs_ = in;
  last_input_frame_ = msg.frame;
  wire::DcpFrameData out = dcp_.Step(in);
  out.frame = next_frame_++;
  out.input_frame = msg.frame;
  out.input_send_time_us = msg.send_time_us;
  out.send_time_us = lcm_->NowUs();
  dcp_frame_t wire_msg;
  wire::PackDcpFrame(out, &wire_msg, &counters_);
  if (transport::PublishMessage(*lcm_, wire::channels::kDcpFrame, wire_msg))
    counters_.Add(Counter::kPublished);
  else
    counters_.Add(Counter::kPublishFailed);
  const dcp_telemetry_t tm = MakeTelemetry(dcp_.status(), out);
  if (!transport::PublishMessage(*lcm_, wire::channels::kDcpTelemetry, tm))
    counters_.Add(Counter::kPublishFailed);
  Report(dcp_.status(), out.frame);
  made_a_frame_ = true;
  if (++frames_since_state_ >=
      static_cast<std::int64_t>(kStateEverySeconds * config_.session.frame_rate_hz)) {
    if (periodic_states_)
      PublishState(dcp_state_t::PERIODIC);
    else
      frames_since_state_ = 0;
  }
  if (!state_file_.empty()) {
    const DcpStatus& st = dcp_.status();
    const std::uint32_t key = static_cast<std::uint32_t>(st.mode) | (st.acquired << 4) |
                              (st.docked << 5) | (dcp_.released() << 6);
    if (key != state_key_ || out.send_time_us - state_written_us_ >= 500000) {
      state_key_ = key;
      WriteStateFile();
    }
  }
}

void DynamicsProc::Report(const DcpStatus& st, std::int64_t frame) {
  counters_.Set(Counter::kMode, wire::ModeNumber(st.mode));
  if (st.held) counters_.Add(Counter::kFramesHeld);
  if (st.finger_held) counters_.Add(Counter::kFramesFingerHeld);
  // docs/collision.md "Collision response": what the DCP refused.
  if (st.motion_collision) counters_.Add(Counter::kFramesMotionHeld);
  if (st.too_fast) counters_.Add(Counter::kFramesTooFast);
  if (st.essential_contact) counters_.Add(Counter::kFramesEssentialContact);
  if (st.input_refused) counters_.Add(Counter::kInputsNonFinite);
  if (st.reset_refused) counters_.Add(Counter::kResetsRefused);
  if (st.let_go) counters_.Add(Counter::kGraspsLetGo);
  for (int b = 0; b < wire::collision_bits::kCount; ++b) {
    if (st.collisions & (1u << b)) counters_.Add(wire::CollisionFramesCounter(b));
  }
  if (last_mode_ != st.mode) {  // (last_mode_: the number, 0 before the first)
    if (last_mode_ != 0) counters_.Add(Counter::kModeChanges);
    last_mode_ = wire::ModeNumber(st.mode);
  }
  // Each collision as it starts and ends.
  const std::uint32_t started = st.collisions & ~last_collisions_;
  const std::uint32_t ended = last_collisions_ & ~st.collisions;
  for (int b = 0; b < wire::collision_bits::kCount; ++b) {
    if (started & (1u << b)) {
      counters_.Add(wire::CollisionCounter(b));
      spdlog::info("frame {}: collision {} (slave {})", frame, wire::CollisionName(b),
                   st.held          ? "holds"
                   : st.finger_held ? "holds the finger"
                                    : "follows");
    }
    if (ended & (1u << b))
      spdlog::info("frame {}: collision {} relieved", frame, wire::CollisionName(b));
  }
  last_collisions_ = st.collisions;
}

int RunDynamicsProc(const LabConfig& config, transport::LcmInterface& lcm,
                    const std::string& stats_path, const std::string& ready_path,
                    const std::string& restore_path, const std::string& state_file,
                    const std::string& checkpoint_dir) {
  DynamicsProc node(config, &lcm);
  node.set_next_frame(transport::FirstFrameNumber(config.session.frame_rate_hz));
  node.EnableLiveChecks(config.session.frame_rate_hz);
  node.set_checkpoint_folder(wire::CheckpointFolder(checkpoint_dir));
  node.set_state_file(state_file);
  const bool resumed = node.ResumeFromStateFile();
  const bool restored = !restore_path.empty() && !resumed;
  if (restored) node.RestoreCheckpoint(restore_path);
  // Its state for the log, until the first frame: the recorder may not
  // have heard the first one (docs/sessions.md "Re-simulation").
  const std::int8_t start_reason = resumed    ? dcp_state_t::RESUME
                                   : restored ? dcp_state_t::RESTORE
                                              : dcp_state_t::START;
  node.PublishState(start_reason);
  std::int64_t state_sent_us = lcm.NowUs();
  auto until_first_frame = [&] {
    if (node.made_a_frame() || lcm.NowUs() - state_sent_us < 500000) return;
    node.PublishState(start_reason);
    state_sent_us = lcm.NowUs();
  };
  if (!ready_path.empty()) transport::WriteReadyFile(ready_path);
  spdlog::info("ready: {} -> {}", lcm.FullChannel(wire::channels::kOperatorInput),
               lcm.FullChannel(wire::channels::kDcpFrame));
  transport::RunNodeLoop(
      lcm, "dynamics_proc", node.counters(), node.latencies(), [&] { return node.last_frame(); },
      until_first_frame, stats_path);
  node.WriteStateFile();
  spdlog::info(
      "published {} DCP frames; inputs missing {}, late {}, dropped {}; final mode {}",
      node.counters().Get(Counter::kPublished), node.counters().Get(Counter::kInputMissing),
      node.counters().Get(Counter::kFramesLate), node.counters().Sum(kDroppedFirst, kDroppedLast),
      wire::ModeNumber(node.program().mode()));
  return 0;
}

}  // namespace rms::dynamics_proc
