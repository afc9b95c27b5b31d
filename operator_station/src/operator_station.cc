#include "rms/operator_station/operator_station.h"

#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "rms/base/check.h"
#include "rms/base/text.h"
#include "rms/base/toml_reader.h"
#include "rms/control_answer_t.hpp"
#include "rms/operator_state_t.hpp"
#include "rms/operator_station/telemetry_check.h"
#include "rms/process_status_t.hpp"
#include "rms/session_control_t.hpp"
#include "rms/window_keys_t.hpp"
#include "rms/wire/channels.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/message_io.h"

namespace rms::operator_station {

operator_input_t InputBlockBuilder::Build(const wire::OperatorInputs& in, std::int64_t send_time_us,
                                          Counters* counters) {
  operator_input_t m;
  m.frame = next_frame_++;
  m.send_time_us = send_time_us;
  const auto words = wire::EncodeInputs(in, cal_, counters);
  std::copy(words.begin(), words.end(), m.words);
  return m;
}

namespace {

std::int64_t MonotonicNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

void SleepUntilNs(std::int64_t t_ns) {
  timespec ts{};
  ts.tv_sec = t_ns / 1000000000;
  ts.tv_nsec = t_ns % 1000000000;
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    if (transport::StopRequested()) return;
  }
}

bool Restarted() { return transport::RestartedByLauncher(); }

// A RESTORE waits at most this long for dynamics_proc's answer (within
// rms_control's 3 s for the station's own), and at most this many wait.
constexpr std::int64_t kRestoreWaitUs = 2'500'000;
constexpr std::size_t kMaxRestoresWaiting = 8;

}  // namespace

std::unique_ptr<InputSource> MakeSource(const OperatorOptions& o, const LabConfig& config) {
  const int sources = !o.timeline_path.empty() + o.keyboard + o.manual + o.autopilot;
  if (sources != 1) {
    throw InputError(
        "give exactly one input source: --timeline FILE, --keyboard, --manual or --autopilot");
  }
  if (!o.timeline_path.empty())
    return std::make_unique<TimelineSource>(o.timeline_path, config, o.speed, o.hold);
  if (o.keyboard || o.manual) {
    HandOptions h;
    h.bindings_path = o.bindings_path;
    h.keyboard_required = o.keyboard;
    h.gamepad = o.gamepad;
    h.spacemouse = o.spacemouse;
    h.window = o.window_keys;
    h.end_when_docked_s = o.end_when_docked_s;
    return std::make_unique<HandSource>(config, h);
  }
  AutopilotOptions ao;
  ao.plan_clear_paths = !o.autopilot_straight;
  return std::make_unique<AutopilotSource>(config, ao, o.hold, false);
}

void CheckSourceFiles(const OperatorOptions& o, const LabConfig& config) {
  const int sources = !o.timeline_path.empty() + o.keyboard + o.manual + o.autopilot;
  if (sources > 1)
    throw InputError("give one input source: --timeline FILE, --keyboard, --manual or --autopilot");
  if (!o.timeline_path.empty()) (void)Timeline::Load(o.timeline_path, config.inputs);
  if (o.keyboard || o.manual || !o.bindings_path.empty()) {
    (void)LoadBindings(o.bindings_path.empty() ? DefaultBindingsPath() : o.bindings_path);
  }
  if (!o.restore_path.empty()) (void)wire::ReadCheckpoint(o.restore_path);
  if (!o.lesson_path.empty()) (void)lesson::Lesson::Load(o.lesson_path);
}

void OperatorStation::RateMeter::Tick(std::int64_t now_us) {
  if (t0_us == 0) {  // the first event opens the window
    t0_us = now_us;
    return;
  }
  ++count;
  if (now_us - t0_us >= 1000000) {
    hz_ = count * 1e6 / static_cast<double>(now_us - t0_us);
    count = 0;
    t0_us = now_us;
  }
}

OperatorStation::OperatorStation(const OperatorOptions& options, const LabConfig& config,
                                 transport::LcmInterface& lcm, std::unique_ptr<InputSource> source)
    : options_(options),
      config_(config),
      lcm_(lcm),
      source_(std::move(source)),
      geometry_(MakeGuidanceGeometry(config)),
      rate_hz_(options.rate_hz > 0 ? options.rate_hz : config.session.frame_rate_hz),
      period_ns_(static_cast<std::int64_t>(std::llround(1e9 / rate_hz_))),
      builder_(config.inputs),
      follow_(config.session.frame_rate_hz),
      checkpoints_(options.checkpoint_dir) {
  telemetry_seq_.SetClock(transport::SessionFrameClock(config.session.frame_rate_hz));
  if (!options.lesson_path.empty()) {
    lesson_ = lesson::Lesson::Load(options.lesson_path);
    spdlog::info("lesson {}: {} events", options.lesson_path, lesson_->events().size());
  }
  Subscribe();
}

void OperatorStation::Subscribe() {
  lcm_.Subscribe(wire::channels::kDcpTelemetry,
                 [this](const void* d, int n, std::int64_t t) { OnTelemetry(d, n, t); });
  lcm_.Subscribe(wire::channels::kStatus,
                 [this](const void* d, int n, std::int64_t t) { OnStatus(d, n, t); });
  lcm_.Subscribe(wire::channels::kControl,
                 [this](const void* d, int n, std::int64_t t) { OnControl(d, n, t); });
  lcm_.Subscribe(wire::channels::kControlAnswer,
                 [this](const void* d, int n, std::int64_t t) { OnControlAnswer(d, n, t); });
  if (source_->window_keyboard()) {
    lcm_.Subscribe(wire::channels::kWindowKeys,
                   [this](const void* d, int n, std::int64_t t) { OnWindowKeys(d, n, t); });
  }
}

void OperatorStation::OnTelemetry(const void* data, int size, std::int64_t recv_us) {
  dcp_telemetry_t m{};
  if (const wire::DecodeError e = wire::SafeDecode(data, size, &m); e != wire::DecodeError::kNone) {
    counters_.Add(wire::DroppedTelemetryCounter(e));
    return;
  }
  if (const auto why = TelemetryProblem(m)) {
    counters_.Add(*why);
    return;
  }
  if (m.input_frame < fresh_from_input_frame_) {
    counters_.Add(
        Counter::kTelemetryBeforeReset);  // answers an input from before the last reset or restore
    return;
  }
  switch (telemetry_seq_.Accept(m.frame, recv_us)) {
    case wire::SequenceTracker::Verdict::kDuplicate:
    case wire::SequenceTracker::Verdict::kStale:
      counters_.Add(Counter::kTelemetryStale);
      return;
    case wire::SequenceTracker::Verdict::kFarAhead:
      if (counters_.Get(Counter::kDroppedFarAhead) == 0) {
        spdlog::warn(
            "telemetry frame {} refused: beyond what the session's clock allows "
            "(dropped.far_ahead)",
            m.frame);
      }
      counters_.Add(Counter::kDroppedFarAhead);
      return;
    case wire::SequenceTracker::Verdict::kResync:
      counters_.Add(Counter::kResyncs);
      spdlog::warn("the telemetry's numbering moved to frame {}: followed again (resyncs)",
                   m.frame);
      break;
    default:
      break;
  }
  telemetry_ = m;
  telemetry_rate_.Tick(recv_us);
  input_to_dcp_ms_ = (recv_us - m.input_send_time_us) / 1000.0;
  events_.Observe(m);
  bool commanding = false;
  if (const HandControllers* h = source_->hand()) {
    const HandStatus& st = h->status();
    commanding = st.automatic != 0;
    for (int i = 0; i < kNumHandAxes; ++i)
      commanding = commanding || st.rate[i] != 0.0 || st.pending[i] != 0.0;
  }
  for (const FollowWatch::Change& c : follow_.Observe(m, commanding)) {
    if (c.failing) {
      counters_.Add(Counter::kNotFollowing);
      spdlog::warn("{}", c.text);
    } else {
      spdlog::info("{}", c.text);
    }
  }
}

void OperatorStation::OnStatus(const void* data, int size, std::int64_t recv_us) {
  process_status_t m;
  if (wire::SafeDecode(data, size, &m) != wire::DecodeError::kNone) {
    counters_.Add(Counter::kDroppedStatusMalformed);
    return;
  }
  if (m.process != "esg_renderer") return;
  for (int i = 0; i < m.num_counters; ++i) {
    const std::string& n = m.counter_names[i];
    const std::int64_t v = m.counter_values[i];
    if (n == CounterName(Counter::kRendered)) {
      if (esg_rendered_ >= 0 && recv_us > esg_status_us_)
        render_hz_ = (v - esg_rendered_) * 1e6 / (recv_us - esg_status_us_);
      esg_rendered_ = v;
      esg_status_us_ = recv_us;
    } else if (n == "latency.input_to_render.p50_us") {
      render_p50_ms_ = v / 1000.0;
    } else if (n == "latency.input_to_render.p99_us") {
      render_p99_ms_ = v / 1000.0;
    }
  }
}

namespace {

constexpr int kMaxSteps = session_control_t::MAX_STEPS;

// A STEP's count (docs/protocol.md "RMS_CONTROL"): empty is 1; 0 when it
// is no number of frames 1..kMaxSteps.
int StepCount(const std::string& name) {
  if (name.empty()) return 1;
  if (name.size() > 6) return 0;
  int n = 0;
  for (char c : name) {
    if (c < '0' || c > '9') return 0;
    n = n * 10 + (c - '0');
  }
  return n >= 1 && n <= kMaxSteps ? n : 0;
}

}  // namespace

// RMS_CONTROL: freeze, run, step; a restored checkpoint (docs/sessions.md).
// The station is the session's clock: frozen, it stops its source and
// publishes nothing, so every process holds its frame and nothing is lost.
void OperatorStation::OnControl(const void* data, int size, std::int64_t) {
  session_control_t m;
  if (wire::SafeDecode(data, size, &m) != wire::DecodeError::kNone) {
    counters_.Add(Counter::kDroppedControlMalformed);
    return;
  }
  const std::string at = " at operator frame " + std::to_string(builder_.next_frame());
  switch (m.command) {
    case session_control_t::FREEZE:
      if (!frozen_) spdlog::info("FROZEN: the session holds its frame");
      Answer(m, control_answer_t::DONE, (frozen_ ? "already frozen" : "frozen") + at);
      frozen_ = true;
      counters_.Add(Counter::kControlFreezes);
      break;
    case session_control_t::RUN:
      if (frozen_) spdlog::info("running again");
      Answer(m, control_answer_t::DONE, (frozen_ ? "running again" : "already running") + at);
      frozen_ = false;
      counters_.Add(Counter::kControlRuns);
      steps_pending_ = 0;
      break;
    case session_control_t::STEP: {
      counters_.Add(Counter::kControlSteps);
      // `name`: how many frames, 1..kMaxSteps (empty: one).
      const int n = StepCount(m.name);
      if (n == 0) {
        Answer(m, control_answer_t::REFUSED,
               "'" + m.name.substr(0, 32) + "' is not a number of frames, 1.." +
                   std::to_string(kMaxSteps));
      } else if (!frozen_) {
        Answer(m, control_answer_t::REFUSED, "not frozen: a step is frames of a frozen session");
      } else {
        Answer(m, control_answer_t::DONE,
               (n == 1 ? std::string("one frame") : std::to_string(n) + " frames") +
                   ", operator frames " + std::to_string(builder_.next_frame() + steps_pending_) +
                   " to " + std::to_string(builder_.next_frame() + steps_pending_ + n - 1) +
                   "; then frozen again");
        steps_pending_ += n;
      }
      break;
    }
    case session_control_t::RESET:
      reset_pending_ = true;
      counters_.Add(Counter::kControlResets);
      Answer(m, control_answer_t::DONE,
             "the reset button pressed for one frame" + at + (frozen_ ? " (when it runs)" : ""));
      break;
    case session_control_t::RESTORE:
      // docs/sessions.md "Freeze, run, step, checkpoint": a restore freezes
      // the session, from whichever client; run resumes it. It is taken
      // only when dynamics_proc has restored its state, so one the DCP
      // refuses changes nothing. The station holds its frame meanwhile.
      if (restores_waiting_.size() >= kMaxRestoresWaiting) {
        counters_.Add(Counter::kControlRateLimited);
        Answer(m, control_answer_t::REFUSED,
               "more than " + std::to_string(kMaxRestoresWaiting) +
                   " restores waiting for dynamics_proc's answer: try again");
        break;
      }
      restores_waiting_.push_back({m, lcm_.NowUs()});
      break;
    default:
      break;
  }
}

// Every command this station acts on is answered (RMS_CONTROL_ANSWER;
// docs/protocol.md).
void OperatorStation::Answer(const session_control_t& m, std::int8_t outcome,
                             const std::string& text) {
  const control_answer_t a = wire::MakeControlAnswer(m, outcome, builder_.next_frame(), text);
  if (!transport::PublishMessage(lcm_, wire::channels::kControlAnswer, a))
    counters_.Add(Counter::kPublishFailed);
}

void OperatorStation::OnWindowKeys(const void* data, int size, std::int64_t recv_us) {
  window_keys_t m;
  if (const wire::DecodeError e = wire::SafeDecode(data, size, &m); e != wire::DecodeError::kNone) {
    counters_.Add(wire::DroppedWindowKeysCounter(e));
    return;
  }
  WindowKeyboardDevice::Message k;
  k.sequence = m.sequence;
  k.held.assign(m.held.begin(), m.held.end());
  k.pressed.assign(m.pressed.begin(), m.pressed.end());
  k.focused = m.focused;
  k.sender_pid = m.sender.pid;
  if (!source_->window_keyboard()->Receive(k, recv_us))
    counters_.Add(Counter::kDroppedWindowKeysStale);
}

void OperatorStation::SendControl(std::int8_t command, const std::string& name) {
  session_control_t m;
  m.send_time_us = lcm_.NowUs();
  m.sequence = control_sequence_++;
  m.command = command;
  m.name = name;
  if (!transport::PublishMessage(lcm_, wire::channels::kControl, m))
    counters_.Add(Counter::kPublishFailed);
}

void OperatorStation::ForgetTelemetry(std::int64_t fresh_from_input_frame) {
  fresh_from_input_frame_ = fresh_from_input_frame;
  telemetry_.reset();
  const wire::FrameClock clock = transport::SessionFrameClock(config_.session.frame_rate_hz);
  telemetry_seq_ = wire::SequenceTracker{};
  telemetry_seq_.SetClock(clock);
  events_.Forget();
  follow_.Forget();
}

namespace {

// `a` answers `m` (the command's id: docs/protocol.md "RMS_CONTROL_ANSWER").
bool Answers(const control_answer_t& a, const session_control_t& m) {
  return a.command == m.command && a.command_process == m.sender.process &&
         a.command_pid == m.sender.pid && a.command_sequence == m.sequence;
}

}  // namespace

// dynamics_proc's answers to RESTORE: what the station waits for.
void OperatorStation::OnControlAnswer(const void* data, int size, std::int64_t) {
  control_answer_t a;
  if (wire::SafeDecode(data, size, &a) != wire::DecodeError::kNone) {
    counters_.Add(Counter::kDroppedAnswerMalformed);
    return;
  }
  if (a.sender.process != sender_t::PROCESS_DYNAMICS || a.command != session_control_t::RESTORE)
    return;
  dcp_restore_answers_.push_back(a);
  if (dcp_restore_answers_.size() > kMaxRestoresWaiting) dcp_restore_answers_.pop_front();
}

// Each waiting RESTORE taken as dynamics_proc answered it: done, the
// checkpoint's inputs taken and one frame run, then frozen; refused,
// nothing changed; no answer within kRestoreWaitUs, refused and frozen
// (the DCP may have restored unheard: Run resumes).
void OperatorStation::SettleRestores() {
  while (!restores_waiting_.empty()) {
    const WaitingRestore w = restores_waiting_.front();
    const auto a = std::find_if(dcp_restore_answers_.begin(), dcp_restore_answers_.end(),
                                [&](const control_answer_t& x) { return Answers(x, w.command); });
    if (a == dcp_restore_answers_.end()) {
      if (lcm_.NowUs() - w.since_us < kRestoreWaitUs) return;
      restores_waiting_.pop_front();
      counters_.Add(Counter::kControlRefused);
      frozen_ = true;
      const std::string why = fmt::format(
          "no answer from dynamics_proc within {:.1f} s: the inputs not taken; frozen (run "
          "resumes)",
          kRestoreWaitUs / 1e6);
      spdlog::error("restore {}: {}", w.command.name, why);
      Answer(w.command, control_answer_t::REFUSED, why);
      continue;
    }
    const control_answer_t heard = *a;
    dcp_restore_answers_.erase(a);
    restores_waiting_.pop_front();
    if (heard.outcome == control_answer_t::DONE) {
      ApplyRestore(w.command);
    } else {
      counters_.Add(Counter::kControlRefused);
      spdlog::error("restore {} refused by dynamics_proc: {} (nothing changed)", w.command.name,
                    heard.text);
      Answer(w.command, control_answer_t::REFUSED,
             "dynamics_proc refused it (" + heard.text + "): nothing changed");
    }
  }
}

void OperatorStation::ApplyRestore(const session_control_t& m) {
  // Carry on from the checkpoint's inputs, so the first frame after it
  // commands the arm where the DCP now has it.
  try {
    const wire::Checkpoint c = checkpoints_.Read(m.name);
    source_->Resume(c.inputs, true);
    ForgetTelemetry(builder_.next_frame());
    spdlog::info("RESTORED the checkpoint {}: carrying on from its inputs",
                 checkpoints_.PathOf(m.name));
    counters_.Add(Counter::kControlRestores);
    // One frame from the checkpoint's inputs, so every display -- the
    // operator's, the ESG's, the instructor's -- shows the restored pose;
    // then frozen (docs/sessions.md "Freeze, run, step, checkpoint").
    if (!frozen_) spdlog::info("FROZEN for a restore");
    frozen_ = true;
    steps_pending_ = 1;
    Answer(m, control_answer_t::DONE,
           "frozen after one frame from the inputs of " + m.name +
               " (every display shows the restored pose): run resumes");
  } catch (const InputError& e) {
    // The DCP read it and restored: the checkpoint changed under us.
    counters_.Add(Counter::kControlRefused);
    frozen_ = true;
    spdlog::error("{}: the DCP restored it, its inputs not taken here; FROZEN", e.what());
    Answer(m, control_answer_t::REFUSED,
           std::string(e.what()) + " (the DCP restored it but its inputs could not be taken: " +
               "frozen, run resumes)");
  }
}

std::optional<Guidance> OperatorStation::CurrentGuidance() const {
  if (!telemetry_) return std::nullopt;
  const ArmState s = ArmStateFrom(*telemetry_);
  const HandControllers* hand = source_->hand();
  CommandFrame f = hand ? hand->status().frame : CommandFrame::kEndEffector;
  if (f == CommandFrame::kPayload && s.mode == wire::DcpMode::kAcquisition)
    f = CommandFrame::kEndEffector;
  const Guidance g = ComputeGuidance(geometry_, s, f);
  if (!hand || s.mode == wire::DcpMode::kAcquisition) return g;
  // The clearance over the turn in flight, where one is (else the whole turn's).
  const auto turn = TurnInFlight(hand->status(), g);
  return turn ? ComputeGuidance(geometry_, s, f, &*turn) : g;
}

// docs/operator.md "Clearance in Mode 3": said once each time the payload
// goes, or the turn in flight would take it, under the margin.
void OperatorStation::WatchClearance(const std::optional<Guidance>& g) {
  const bool warn = g && g->clearance_warning;
  if (warn && !clearance_warned_) {
    counters_.Add(Counter::kClearanceWarnings);
    spdlog::warn(
        "CLEARANCE: over the {} the payload goes {:.2f} ft {} the orbiter's sill line "
        "(margin {:.0f} ft): go up (orbiter frame, r) before turning",
        source_->hand() && TurnInFlight(source_->hand()->status(), *g) ? "turn in flight"
                                                                       : "turn the guidance shows",
        std::abs(g->turn_clearance_ft), g->turn_clearance_ft >= 0 ? "above" : "BELOW",
        kClearanceMarginFt);
  }
  clearance_warned_ = warn;
}

void OperatorStation::PublishState(std::int64_t frame, const std::optional<Guidance>& g) {
  operator_state_t m{};
  m.frame = frame;
  m.send_time_us = lcm_.NowUs();
  m.source = source_->kind();
  if (const HandControllers* h = source_->hand()) {
    const HandStatus& s = h->status();
    m.control_mode = static_cast<std::int8_t>(s.mode);
    m.command_frame = static_cast<std::int8_t>(s.frame);
    static_assert(static_cast<int>(ControlMode::kSingleJoint) ==
                      operator_state_t::CONTROL_SINGLE_JOINT &&
                  static_cast<int>(ControlMode::kManualAugmented) ==
                      operator_state_t::CONTROL_MANUAL_AUGMENTED);
    static_assert(static_cast<int>(RateScale::kCoarse) == operator_state_t::SCALE_COARSE &&
                  static_cast<int>(RateScale::kVernier) == operator_state_t::SCALE_VERNIER &&
                  static_cast<int>(RateScale::kFine) == operator_state_t::SCALE_FINE);
    static_assert(kAutoSquareUp == operator_state_t::AUTO_SQUARE_UP &&
                  kAutoUnwind == operator_state_t::AUTO_UNWIND &&
                  kAutoStow == operator_state_t::AUTO_STOW);
    static_assert(kNearLimitDeg == operator_state_t::NEAR_LIMIT_DEG);
    m.scale = static_cast<std::int8_t>(s.scale);
    for (int i = 0; i < kNumHandAxes; ++i) m.achieved_rate[i] = s.achieved[i];
    m.automatic = static_cast<std::int16_t>(s.automatic);
    m.joints_near_limit = static_cast<std::int8_t>(s.near_limit);
    m.joint = static_cast<std::int8_t>(s.joint);
    for (int i = 0; i < kNumHandAxes; ++i) m.hand_rate[i] = s.rate[i];
    m.joint_limits = static_cast<std::int8_t>(s.at_limit);
    m.singular = s.singular;
    m.sigma_min_ft = s.sigma_min_ft;
    m.show_guidance = h->show_guidance();
    m.key_actions = static_cast<std::int32_t>(h->key_actions());
    m.rate_limited = s.rate_limited;
    // Within the message's bounds (operator_state_t.lcm): the first devices, names cut.
    const std::size_t n =
        std::min<std::size_t>(h->device_actions().size(), operator_state_t::MAX_DEVICES);
    m.num_devices = static_cast<std::int8_t>(n);
    for (std::size_t i = 0; i < n; ++i) {
      m.device_names.push_back(
          h->device_name(i).substr(0, operator_state_t::MAX_DEVICE_NAMES_BYTES));
      m.device_actions.push_back(static_cast<std::int32_t>(h->device_actions()[i]));
    }
  }
  if (g) {
    const dcp_telemetry_t& t = *telemetry_;
    m.guidance_valid = true;
    m.mode = t.mode;
    m.target = static_cast<std::int8_t>(g->target);
    if (!source_->hand()) m.command_frame = static_cast<std::int8_t>(g->frame);
    for (int i = 0; i < 3; ++i) {
      m.offset_ft[i] = g->offset_ft[i];
      m.rotation_deg[i] = g->rotation_deg[i];
    }
    m.distance_ft = g->distance_ft;
    m.angle_deg = g->angle_deg;
    for (int i = 0; i < 6; ++i) {
      m.conditions[i] = t.acquisition_conditions[i];
      m.margin_ft[i] = t.acquisition_margin_ft[i];
    }
    m.close_gap_ft = g->close_gap_ft;
    m.close_ok = WouldAcquire(t, *g, config_.dcp.d3y_ft);
    m.bay_clearance_ft = t.bay_clearance_ft;
    static_assert(kClearanceMarginFt == operator_state_t::CLEARANCE_MARGIN_FT);
    m.next_axis = static_cast<std::int8_t>(g->next_axis);
    m.turn_clearance_ft = std::isnan(g->turn_clearance_ft) ? 0.0 : g->turn_clearance_ft;
    m.clearance_warning = g->clearance_warning;
    m.dock_distance_ft = t.dock_distance_ft;
    m.dock_angle_deg = t.dock_angle_deg;
  }
  if (!transport::PublishMessage(lcm_, wire::channels::kOperatorState, m))
    counters_.Add(Counter::kPublishFailed);
}

void OperatorStation::DrawScreen(std::int64_t frame, const wire::OperatorInputs& in, bool frozen) {
  if (!screen_) return;
  StatusSnapshot s;
  s.source =
      source_->Describe() +
      (frozen ? std::string(" -- FROZEN (") +
                    (source_->hand() ? "freeze key runs, step key steps" : "rms_control run") + ")"
              : "");
  s.frame = frame;
  s.session_s = static_cast<double>(frames_) / rate_hz_;
  s.inputs = in;
  s.telemetry = telemetry_;
  s.guidance = CurrentGuidance();
  if (const HandControllers* h = source_->hand()) {
    s.hand = h->status();
    s.show_guidance = h->show_guidance();
    s.key_actions = h->key_actions();
  }
  s.keys = source_->key_hints();
  s.publish_hz = publish_rate_.hz();
  s.telemetry_hz = telemetry_rate_.hz();
  s.not_following = follow_.failing();
  s.input_to_dcp_ms = input_to_dcp_ms_;
  s.render_hz = render_hz_;
  s.input_to_render_p50_ms = render_p50_ms_;
  s.input_to_render_p99_ms = render_p99_ms_;
  s.clamped_inputs =
      counters_.Sum(kClampedFirst, kClampedLast) +
      (source_->hand() ? source_->hand()->counters().Sum(kClampedFirst, kClampedLast) : 0);
  s.devices = source_->devices();
  s.help = source_->help();
  screen_->Draw(std::move(s));
}

// docs/lessons.md: each event once, when its trigger first holds at the
// start of a frame (the session time of the frames published so far).
void OperatorStation::FireLessonEvents() {
  if (!lesson_) return;
  const double t_s = static_cast<double>(frames_) / config_.session.frame_rate_hz;
  for (const std::size_t i : lesson_->Due(t_s, telemetry_ ? &*telemetry_ : nullptr)) {
    const lesson::LessonEvent& e = lesson_->events()[i];
    spdlog::warn("lesson: event {} ({}), at {:.3f} s of session time", i + 1, e.text, t_s);
    SendControl(e.command, e.name);
    counters_.Add(Counter::kLessonEvents);
    if (e.command == session_control_t::FREEZE && e.for_s > 0)
      run_again_at_us_ = lcm_.NowUs() + static_cast<std::int64_t>(e.for_s * 1e6);
    else if (e.command == session_control_t::FREEZE)
      spdlog::warn(
          "lesson: the session stays frozen until someone runs it (p, the instructor's Run, "
          "scripts/lab control run)");
  }
}

bool OperatorStation::RunFrozen() {
  // Frozen: no clock, no frames. The session's keys still work.
  if (run_again_at_us_ != 0 && lcm_.NowUs() >= run_again_at_us_) {
    run_again_at_us_ = 0;
    spdlog::info("lesson: the freeze is over: run");
    SendControl(session_control_t::RUN);
  }
  source_->WhileFrozen();
  const Requests r = source_->requests();
  if (r.quit) return false;
  if (r.freeze) SendControl(session_control_t::RUN);
  for (int i = 0; i < r.steps; ++i) SendControl(session_control_t::STEP);
  DrawScreen(builder_.next_frame() - 1, last_, true);
  return true;
}

// A restarted station (RMSLAB_RESTART) resumes from the command the DCP's
// first telemetry shows, not from the start of the task.
void OperatorStation::ResumeFromTelemetry() {
  const dcp_telemetry_t& t = *telemetry_;
  wire::OperatorInputs from = last_;
  for (int i = 0; i < kNumJoints; ++i) from.value[i] = t.master_angles_deg[i];
  from.value[kShoulderHeight] = t.master_shoulder_height_ft;
  from.value[kFinger] = t.master_finger;
  source_->Resume(from, false);
  spdlog::warn("restarted: resuming from the DCP's telemetry (Mode {}, frame {})",
               static_cast<int>(t.mode), t.frame);
}

// A restarted station must not send the task's initial inputs while it
// waits for the DCP's first telemetry (the DCP answers only inputs): in Mode
// 2 or 3 an open finger lets the payload go. It sends, until then, the
// inputs the DCP last took, as its state file holds them (written on every
// change of mode and at least every 0.5 s).
std::string OperatorStation::ClockFilePath() const {
  if (options_.dcp_state_path.empty()) return "";
  return (std::filesystem::path(options_.dcp_state_path).parent_path() / "operator_clock.json")
      .string();
}

// Written when the station freezes, steps while frozen or runs again: a
// station killed while frozen comes back frozen at the same frame, and one
// killed after a freeze numbers on from the run, not through the freeze.
void OperatorStation::WriteClockFileOnChange() {
  const std::string path = ClockFilePath();
  if (path.empty()) return;
  const std::int64_t frame = builder_.next_frame();
  if (frozen_ == clock_written_frozen_ && (!frozen_ || frame == clock_written_frame_)) return;
  clock_written_frozen_ = frozen_;
  clock_written_frame_ = frame;
  const nlohmann::json j = {{"frozen", frozen_}, {"next_frame", frame}, {"wall_us", lcm_.NowUs()}};
  try {
    WriteWholeFile(path + ".tmp", j.dump() + "\n");
    std::filesystem::rename(path + ".tmp", path);
  } catch (const std::exception& e) {
    spdlog::error("cannot write the session's clock file: {}", e.what());
  }
}

void OperatorStation::ResumeFromDcpState() {
  try {
    const wire::Checkpoint c = wire::ReadCheckpoint(options_.dcp_state_path);
    wire::OperatorInputs from = c.inputs;
    from.reset = false;
    last_ = from;
    source_->Resume(from, false);
    // Numbered on from the operator frame the state answered, by the
    // station's own rate (at --speed 4, four frames a session period; the
    // session's clock alone numbered far behind, and the DCP refused them).
    std::int64_t base_frame = c.input_frame + 1, base_us = c.saved_us;
    bool frozen = false;
    if (std::filesystem::exists(ClockFilePath())) {
      // Frozen time is no session time: from the freeze's frame, or from
      // the run that ended it when that came after the state was written.
      const auto clock = nlohmann::json::parse(ReadTextFile(ClockFilePath(), "the clock file"));
      frozen = clock.at("frozen").get<bool>();
      const std::int64_t clock_us = clock.at("wall_us").get<std::int64_t>();
      if (frozen || clock_us > base_us) {
        base_frame = clock.at("next_frame").get<std::int64_t>();
        base_us = frozen ? lcm_.NowUs() : clock_us;
      }
    }
    const double since_s = std::max<double>(0.0, (lcm_.NowUs() - base_us) * 1e-6);
    const auto next = base_frame + static_cast<std::int64_t>(since_s * rate_hz_);
    // Not the session's wall clock (FirstFrameNumber): that counts frozen time.
    if (c.input_frame >= 0) builder_.set_next_frame(next);
    if (frozen) {
      frozen_ = clock_written_frozen_ = true;
      clock_written_frame_ = builder_.next_frame();
      spdlog::warn("restarted while the session was frozen: frozen still, at frame {}",
                   builder_.next_frame());
    }
    spdlog::warn(
        "restarted: sending the inputs of the DCP's last state (DCP frame {}) until its "
        "first telemetry, from frame {}",
        c.dcp_frame, builder_.next_frame());
  } catch (const std::exception& e) {
    spdlog::warn(
        "restarted: the DCP's state could not be read ({}): resuming from its first "
        "telemetry only",
        e.what());
  }
}

// One frame: the source's inputs, published as the input block and the
// operator's state, the status and the screen. False when the source ended.
bool OperatorStation::StepFrame(transport::StatusReporter* status) {
  Frame f;
  f.count = frames_;
  f.dt_s = 1.0 / config_.session.frame_rate_hz;
  f.telemetry = telemetry_ ? &*telemetry_ : nullptr;
  f.now_us = lcm_.NowUs();
  FireLessonEvents();
  std::optional<wire::OperatorInputs> in = source_->Next(f);
  if (source_->requests().freeze) SendControl(session_control_t::FREEZE);
  if (!in) return false;
  if (reset_pending_) {
    // RESET from RMS_CONTROL (an instructor): the button for this frame;
    // the source carries on from these inputs (the autopilot begins the
    // task again from the telemetry after the reset).
    in->reset = true;
    reset_pending_ = false;
    source_->Resume(*in, false);
  }
  last_ = *in;
  if (in->reset) {
    spdlog::info("reset pressed: back to Mode 1");
    ForgetTelemetry(builder_.next_frame());
  }
  const operator_input_t block = builder_.Build(*in, lcm_.NowUs(), &counters_);
  if (transport::PublishMessage(lcm_, wire::channels::kOperatorInput, block))
    counters_.Add(Counter::kPublished);
  else
    counters_.Add(Counter::kPublishFailed);
  const std::optional<Guidance> guidance = CurrentGuidance();  // once a frame
  PublishState(block.frame, guidance);
  WatchClearance(guidance);
  publish_rate_.Tick(lcm_.NowUs());
  ++frames_;
  status->Tick(block.frame, counters_);
  DrawScreen(block.frame, *in, false);
  return true;
}

// At the end: the counters reported and written; the exit code.
int OperatorStation::Finish(const std::string& stats_path, transport::StatusReporter* status) {
  screen_.reset();  // the terminal back, the captured log written out
  if (lesson_ && lesson_->fired() < lesson_->events().size()) {
    std::string never;
    for (std::size_t i = 0; i < lesson_->events().size(); ++i)
      if (!lesson_->was_fired(i))
        never += "\n  event " + std::to_string(i + 1) + " (" + lesson_->events()[i].text + ")";
    spdlog::warn("lesson: {} of {} events never fired (their triggers never held):{}",
                 lesson_->events().size() - lesson_->fired(), lesson_->events().size(), never);
  }
  source_->AddCounters(&counters_);
  transport::NoteTransportCounters(lcm_, &counters_);
  counters_.Set(Counter::kFramesTotal, frames_);
  status->Final(builder_.next_frame() - 1, counters_);
  if (!stats_path.empty()) transport::WriteStatsJson(stats_path, "operator_station", counters_, {});
  spdlog::info("published {} input blocks ({} late, {} clamped inputs)",
               counters_.Get(Counter::kPublished), counters_.Get(Counter::kFramesLate),
               counters_.Sum(kClampedFirst, kClampedLast));
  if (transport::StopRequested()) {
    spdlog::info("stopped by a signal at frame {}", builder_.next_frame() - 1);
    return kExitInterrupted;
  }
  return source_->exit_code();
}

int OperatorStation::Run(const std::string& stats_path, const std::string& ready_path) {
  if (!options_.restore_path.empty()) {
    const wire::Checkpoint c = wire::ReadCheckpoint(options_.restore_path);
    spdlog::info("starting from the checkpoint {} (DCP frame {})", options_.restore_path,
                 c.dcp_frame);
    source_->Resume(c.inputs, true);
  }
  // RMSLAB_RESTART (set by the launcher when it restarts this process after a
  // fault, docs/sessions.md "Faults"): the source resumes from the first
  // telemetry's command instead of starting the task over.
  bool resume_from_telemetry =
      Restarted() && options_.restore_path.empty() && options_.timeline_path.empty();
  if (Restarted()) counters_.Add(Counter::kRestarted);
  const bool by_hand = source_->hand() != nullptr;
  if (options_.status == 1 || (options_.status == -1 && by_hand && isatty(STDOUT_FILENO))) {
    screen_ = std::make_unique<StatusScreen>(config_);
  }
  transport::StatusReporter status(&lcm_, "operator_station");
  builder_.set_next_frame(transport::FirstFrameNumber(rate_hz_));
  if (!ready_path.empty()) transport::WriteReadyFile(ready_path);

  std::int64_t next_ns = MonotonicNs();
  last_ = wire::InitialInputs(config_.inputs);
  if (resume_from_telemetry && !options_.dcp_state_path.empty()) ResumeFromDcpState();
  while (!transport::StopRequested()) {
    if (options_.max_frames >= 0 && frames_ >= options_.max_frames) break;
    if (lcm_.HandleSubscriptions(0) < 0) counters_.Add(Counter::kTransportErrors);
    transport::NoteTransportCounters(lcm_, &counters_);
    SettleRestores();
    WriteClockFileOnChange();
    if (Holding() && steps_pending_ == 0) {
      if (!RunFrozen()) break;
      status.Tick(builder_.next_frame() - 1, counters_);
      SleepUntilNs(MonotonicNs() + period_ns_);
      next_ns = MonotonicNs();
      continue;
    }
    if (steps_pending_ > 0) --steps_pending_;
    if (resume_from_telemetry && telemetry_) {
      ResumeFromTelemetry();
      resume_from_telemetry = false;
    }
    if (!StepFrame(&status)) break;
    WriteClockFileOnChange();
    next_ns += period_ns_;
    const std::int64_t now = MonotonicNs();
    if (now > next_ns + period_ns_) {
      counters_.Add(Counter::kFramesLate);
      next_ns = now;  // don't try to catch up with a burst
    } else {
      SleepUntilNs(next_ns);
    }
  }
  return Finish(stats_path, &status);
}

}  // namespace rms::operator_station
