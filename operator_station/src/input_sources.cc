#include "rms/operator_station/input_sources.h"

#include <unistd.h>

#include <spdlog/spdlog.h>

#include "rms/base/check.h"

namespace rms::operator_station {

// ---- timeline ----

TimelineSource::TimelineSource(const std::string& path, const LabConfig& config, double speed,
                               bool hold)
    : path_(path), timeline_(Timeline::Load(path, config.inputs)), speed_(speed), hold_(hold) {
  for (const std::string& w : timeline_.warnings()) spdlog::warn("{}", w);
  spdlog::info("timeline {}: {:.2f} s at {:.1f} Hz, speed {}", path, timeline_.end_time(),
               config.session.frame_rate_hz, speed);
}

std::optional<wire::OperatorInputs> TimelineSource::Next(const Frame& f) {
  // Timeline time is the frame count over the rate: jitter-free and reproducible.
  const double t = speed_ * static_cast<double>(f.count) * f.dt_s;
  if (t > timeline_.end_time() + 1e-9 && !hold_) return std::nullopt;
  wire::OperatorInputs in = timeline_.Sample(t);
  in.reset = timeline_.ResetIn(prev_t_, t);
  prev_t_ = t;
  return in;
}

// ---- by hand ----

// Groups two spaces apart (the status screen wraps between groups).
std::map<std::string, std::string> KeyHints(const Bindings& b) {
  std::map<std::string, std::string> m;
  for (const auto& [code, a] : b.keys) {
    std::string& k = m[ActionName(a)];
    if (!k.empty()) k += ",";
    k += wire::KeyName(code);
  }
  return m;
}

std::string KeyHelp(const Bindings& b) {
  // Keys grouped by what they do, the pairs of an axis together.
  std::map<std::string, std::string> by_action = KeyHints(b);
  std::string s = "keys:";
  auto pair = [&](const std::string& plus, const std::string& minus, const char* what) {
    if (by_action.count(plus) && by_action.count(minus)) {
      s += "  " + by_action[plus] + "/" + by_action[minus] + " " + what;
      by_action.erase(plus);
      by_action.erase(minus);
    }
  };
  pair("thc_x+", "thc_x-", "fwd/back");
  pair("thc_y+", "thc_y-", "right/left");
  pair("thc_z+", "thc_z-", "down/up");
  pair("rhc_pitch+", "rhc_pitch-", "pitch up/down");
  pair("rhc_yaw+", "rhc_yaw-", "yaw right/left");
  pair("rhc_roll+", "rhc_roll-", "roll right/left");
  pair("finger+", "finger-", "finger close/open");
  pair("shoulder_height+", "shoulder_height-", "shoulder up/down");
  pair("camera_pan+", "camera_pan-", "pan");
  pair("camera_tilt+", "camera_tilt-", "tilt");
  pair("camera_zoom+", "camera_zoom-", "zoom");
  std::string nulls;  // shift and an axis's keys: "W,S/D,A/F,R/... null"
  for (const char* axis : {"thc_x", "thc_y", "thc_z", "rhc_pitch", "rhc_yaw", "rhc_roll"}) {
    const std::string n = "null_" + std::string(axis);
    if (by_action.count(n)) nulls += (nulls.empty() ? "" : "/") + by_action[n];
  }
  if (!nulls.empty()) s += "  " + nulls + " fly the axis to 0";
  static const std::pair<const char*, const char*> kOnes[] = {{"square_up", "square up"},
                                                              {"unwind", "unwind wrist"},
                                                              {"stow", "stow the arm"},
                                                              {"stop", "stop"},
                                                              {"vernier", "scale"},
                                                              {"mode", "mode"},
                                                              {"frame", "frame"},
                                                              {"joint_next", "joint_next"},
                                                              {"joint_prev", "joint_prev"},
                                                              {"crosshairs", "crosshairs"},
                                                              {"guidance", "guidance"},
                                                              {"overlay", "overlay"},
                                                              {"reset", "reset"},
                                                              {"freeze", "freeze"},
                                                              {"step", "step"},
                                                              {"quit", "quit"}};
  for (const auto& [one, what] : kOnes) {
    if (by_action.count(one)) {
      s += "  " + by_action[one] + " " + what;
      by_action.erase(one);
    }
  }
  s += "  1-" + std::to_string(kNumCameraStations) + " camera";
  return s;
}

HandSource::HandSource(const LabConfig& config, const HandOptions& o)
    : bindings_(LoadBindings(o.bindings_path.empty() ? DefaultBindingsPath() : o.bindings_path)),
      end_when_docked_s_(o.end_when_docked_s) {
  hands_ = std::make_unique<HandControllers>(config, bindings_);
  // Each device is optional: looked for, and reported either way.
  if (isatty(STDIN_FILENO)) {
    terminal_ = std::make_unique<TerminalKeys>();
    hands_->AddDevice(
        std::make_unique<KeyboardDevice>(bindings_, [t = terminal_.get()] { return t->Next(); }));
  } else if (o.keyboard_required) {
    throw InputError("--keyboard needs a terminal on standard input");
  } else {
    device_report_.push_back("keyboard: none (standard input is not a terminal)");
  }
  if (o.window) {
    auto w = std::make_unique<WindowKeyboardDevice>(bindings_);
    window_ = w.get();
    hands_->AddDevice(std::move(w));
  }
  std::string why;
  if (o.gamepad) {
    if (auto g = GamepadDevice::Open(bindings_, &why))
      hands_->AddDevice(std::move(g));
    else
      device_report_.push_back("gamepad: none (" + why + ")");
  }
  if (o.spacemouse) {
    if (auto m = SpaceMouseDevice::Open(bindings_, &why))
      hands_->AddDevice(std::move(m));
    else
      device_report_.push_back("3D mouse: none (" + why + ")");
  }
  for (const auto& d : device_report_) spdlog::info("{}", d);
  if (hands_->devices().empty()) {
    throw InputError("no input device found (" + device_report_.front() +
                     "; give --window-keys to fly from the live window)");
  }
  for (const auto& d : hands_->devices())
    device_report_.insert(device_report_.begin(), d->Describe());
  help_ = KeyHelp(bindings_);
}

std::optional<wire::OperatorInputs> HandSource::Next(const Frame& f) {
  if (window_) window_->SetNow(f.now_us);
  const wire::OperatorInputs in = hands_->Step(f.dt_s, f.telemetry);
  requests_ = {hands_->quit(), hands_->freeze_requested(), hands_->step_requests()};
  if (hands_->quit()) return std::nullopt;
  if (end_when_docked_s_ >= 0 && f.telemetry && (f.telemetry->docked || docked_s_ > 0)) {
    if (docked_s_ == 0) spdlog::info("docked: the session ends in {} s", end_when_docked_s_);
    docked_s_ += f.dt_s;
    if (docked_s_ > end_when_docked_s_) return std::nullopt;
  }
  return in;
}

void HandSource::WhileFrozen() {
  hands_->PollFrozen();
  requests_ = {hands_->quit(), hands_->freeze_requested(), hands_->step_requests()};
}

std::map<std::string, std::string> HandSource::key_hints() const { return KeyHints(bindings_); }

void HandSource::Resume(const wire::OperatorInputs& in, bool) { hands_->SetInputs(in); }

void HandSource::AddCounters(Counters* c) const {
  c->AddAll(hands_->counters());
  c->Set(Counter::kKeyActions, hands_->key_actions());
  if (window_) c->Set(Counter::kWindowKeysTimeouts, window_->timeouts());
}

// ---- autopilot ----

AutopilotSource::AutopilotSource(const LabConfig& config, const AutopilotOptions& options,
                                 bool hold, bool resume_from_telemetry)
    : config_(config),
      autopilot_(config, options),
      hold_(hold),
      resume_from_telemetry_(resume_from_telemetry) {}

std::string AutopilotSource::Describe() const {
  return std::string("autopilot: ") + AutopilotPhaseName(autopilot_.phase());
}

void AutopilotSource::Resume(const wire::OperatorInputs& in, bool from_checkpoint) {
  autopilot_.Resync(in);
  if (from_checkpoint) resume_from_telemetry_ = false;
}

std::optional<wire::OperatorInputs> AutopilotSource::Next(const Frame& f) {
  if (resume_from_telemetry_ && f.telemetry) {
    // Restarted mid-session by the launcher: carry on from the command the
    // DCP last answered, and let the autopilot pick up the task where the
    // telemetry says it is (no reset).
    const dcp_telemetry_t& t = *f.telemetry;
    wire::OperatorInputs from = wire::InitialInputs(config_.inputs);
    for (int i = 0; i < kNumJoints; ++i) from.value[i] = t.master_angles_deg[i];
    from.value[kShoulderHeight] = t.master_shoulder_height_ft;
    from.value[kFinger] = t.master_finger;
    autopilot_.Resync(from);
    resume_from_telemetry_ = false;
    spdlog::warn("restarted: the autopilot resumes from the DCP's telemetry (Mode {}, frame {})",
                 static_cast<int>(t.mode), t.frame);
  }
  const wire::OperatorInputs in = autopilot_.Step(f.telemetry);
  if (autopilot_.failed() && !hold_) return std::nullopt;
  // Docked: hold two seconds of session time (the scene shows it), then stop.
  if (autopilot_.docked() && ++docked_frames_ > 2 * config_.session.frame_rate_hz && !hold_)
    return std::nullopt;
  return in;
}

int AutopilotSource::exit_code() const { return autopilot_.failed() ? 3 : 0; }

void AutopilotSource::AddCounters(Counters* c) const {
  c->AddAll(autopilot_.counters());
  c->Set(Counter::kAutopilotDocked, autopilot_.docked());
  if (autopilot_.failed())
    spdlog::error("autopilot failed: {}", autopilot_.failure());
  else if (autopilot_.docked())
    spdlog::info("autopilot: docked {:.1f} s into the session", autopilot_.docked_at_s());
}

}  // namespace rms::operator_station
