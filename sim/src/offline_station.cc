#include "rms/sim/offline_station.h"

#include <cmath>
#include <memory>

#include "rms/base/check.h"
#include "rms/dcp_model/dcp_telemetry.h"
#include "rms/operator_station/devices.h"
#include "rms/operator_station/input_sources.h"
#include "rms/operator_station/status_screen.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/input_block.h"
#include "rms/wire/key_codes.h"

#include "flight_log.h"

namespace rms::sim {

namespace {

// A key by tmux's send-keys name, as the keyboard devices read it (a
// character, or a key code of wire/key_codes.h).
int KeyCode(const std::string& name) {
  if (name.size() == 1) return static_cast<unsigned char>(name[0]);
  if (name == "Space") return ' ';
  if (name == "Enter") return '\r';
  if (name == "BSpace") return wire::kKeyBackspace;
  throw InputError("the offline station has no key '" + name +
                   "' (one character, Space, Enter or BSpace)");
}

}  // namespace

OfflineStation::OfflineStation(const LabConfig& config, const operator_station::Bindings& bindings,
                               double max_s, int width, int height, bool window_keys)
    : config_(config),
      bindings_(bindings),
      hands_(config, bindings_),
      geometry_(operator_station::MakeGuidanceGeometry(config)),
      program_(config),
      rate_hz_(config.session.frame_rate_hz),
      max_s_(max_s),
      width_(width),
      height_(height) {
  if (window_keys) {
    auto w = std::make_unique<operator_station::WindowKeyboardDevice>(bindings_);
    window_ = w.get();
    hands_.AddDevice(std::move(w));
    return;
  }
  hands_.AddDevice(std::make_unique<operator_station::KeyboardDevice>(
      bindings_,
      [this] {
        if (next_key_ >= pending_keys_.size()) return -1;
        return pending_keys_[next_key_++];
      },
      "the offline station"));
}

void OfflineStation::Release(const std::vector<std::string>& keys) {
  for (const std::string& k : keys) window_held_.erase(KeyCode(k));
}

void OfflineStation::Send(const std::vector<std::string>& keys) {
  if (window_) {
    for (const std::string& k : keys) {
      window_pressed_.push_back(KeyCode(k));
      window_held_.insert(KeyCode(k));
    }
    return;
  }
  if (next_key_ >= pending_keys_.size()) pending_keys_.clear(), next_key_ = 0;
  for (const std::string& k : keys) pending_keys_.push_back(KeyCode(k));
}

void OfflineStation::Wait(double s) {
  waited_s_ += std::max(0.0, s);
  // At least one frame a wait: what was typed is read, and the screen moves.
  do {
    if (session_s() >= max_s_) throw FlightTimeUp();
    StepFrame();
  } while (session_s() < waited_s_);
  waited_s_ = std::max(waited_s_, session_s());
}

void OfflineStation::StepFrame() {
  if (window_) {
    // The window's message this frame (it sends at every change and every
    // 100 ms while a key is held; every frame here).
    const auto now_us = static_cast<std::int64_t>(std::llround(frames_ * 1e6 / rate_hz_));
    operator_station::WindowKeyboardDevice::Message m;
    m.sequence = window_sequence_++;
    m.held.assign(window_held_.begin(), window_held_.end());
    m.pressed = window_pressed_;
    window_pressed_.clear();
    window_->Receive(m, now_us);
    window_->SetNow(now_us);
  }
  const wire::OperatorInputs in = hands_.Step(1.0 / rate_hz_, telemetry_ ? &*telemetry_ : nullptr);
  const auto words = wire::EncodeInputs(in, config_.inputs, &result_.dcp);
  const wire::OperatorInputs decoded = wire::DecodeInputs(words, config_.inputs, &result_.dcp);
  wire::DcpFrameData out = program_.Step(decoded);
  const int f = static_cast<int>(frames_);
  out.frame = f;
  out.input_frame = f;
  const dcp_telemetry_t tm = dcp_model::MakeTelemetry(program_.status(), out);
  ObserveFrame(tm, f, &colliding_, &result_);
  inputs_ = in;
  telemetry_ = tm;  // read by the next frame, as over LCM
  ++frames_;
  result_.frames = f + 1;
  result_.time_s = session_s();
}

std::string OfflineStation::Capture() {
  operator_station::StatusSnapshot s;
  s.source = "by hand";
  s.frame = frames_ - 1;
  s.session_s = session_s();
  s.inputs = inputs_;
  s.telemetry = telemetry_;
  if (telemetry_) {
    const operator_station::ArmState arm = operator_station::ArmStateFrom(*telemetry_);
    operator_station::CommandFrame f = hands_.status().frame;
    if (f == operator_station::CommandFrame::kPayload && arm.mode == wire::DcpMode::kAcquisition)
      f = operator_station::CommandFrame::kEndEffector;
    s.guidance = operator_station::ComputeGuidance(geometry_, arm, f);
  }
  s.hand = hands_.status();
  s.show_guidance = hands_.show_guidance();
  s.key_actions = hands_.key_actions();
  s.keys = operator_station::KeyHints(bindings_);
  s.publish_hz = s.telemetry_hz = rate_hz_;
  s.devices = {"keyboard (the offline station)"};
  s.help = operator_station::KeyHelp(bindings_);
  return operator_station::RenderStatusScreen(s, config_, width_, height_);
}

ScriptedFlight FlyScriptedSubject(const LabConfig& config,
                                  const operator_station::Bindings& bindings,
                                  const ScriptedOperatorOptions& options, double max_s,
                                  bool window_keys, bool again_after_reset) {
  OfflineStation station(config, bindings, max_s, 132, 50, window_keys);
  ScriptedOperator op(&station, options);
  ScriptedFlight flight;
  try {
    flight.report = op.Fly(false, max_s);
    if (again_after_reset && flight.report.docked) flight.report = op.FlyAgainAfterReset(max_s);
  } catch (const FlightTimeUp&) {
    flight.report = op.report();  // what it saw and did, up to there
    flight.report.failure = TimeUpFailure(station.result(), max_s);  // where the time ran out
  }
  flight.result = station.result();
  flight.key_actions = station.key_actions();
  ClosedLoopResult& r = flight.result;
  if (!r.docked && r.failure.empty())
    r.failure = flight.report.failure.empty() ? "frame limit" : flight.report.failure;
  return flight;
}

}  // namespace rms::sim
