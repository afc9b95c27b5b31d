#include "operator_station.h"

#include <cerrno>
#include <cmath>
#include <memory>
#include <optional>
#include <spdlog/spdlog.h>
#include <time.h>
#include <unistd.h>

#include "autopilot.h"
#include "bindings.h"
#include "devices.h"
#include "keyboard.h"
#include "manual_control.h"
#include "rms/channels.h"
#include "rms/check.h"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/message_io.h"
#include "rms/telemetry_check.h"
#include "rms/process.h"
#include "rms/checkpoint.h"
#include "rms/process_status_t.hpp"
#include "rms/session_control_t.hpp"
#include "status_screen.h"
#include "timeline.h"

namespace rms::op {

operator_input_t InputBlockBuilder::Build(const OperatorInputs& in, std::int64_t send_time_us,
                                          Counters* counters) {
  operator_input_t m;
  m.frame = next_frame_++;
  m.send_time_us = send_time_us;
  const auto words = EncodeInputs(in, cal_, counters);
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
    if (StopRequested()) return;
  }
}

// Events a second over the last second or so.
class RateMeter {
 public:
  void Tick(std::int64_t now_us) {
    if (t0_us_ == 0) {  // the first event opens the window
      t0_us_ = now_us;
      return;
    }
    ++count_;
    if (now_us - t0_us_ >= 1000000) {
      hz_ = count_ * 1e6 / static_cast<double>(now_us - t0_us_);
      count_ = 0;
      t0_us_ = now_us;
    }
  }
  double hz() const { return hz_; }

 private:
  std::int64_t t0_us_ = 0, count_ = 0;
  double hz_ = 0.0;
};

std::string KeyHelp(const Bindings& b) {
  std::string s = "keys:";
  for (const auto& [code, a] : b.keys) {
    std::string key = code == ' ' ? "space" : code == kKeyUp ? "up" : code == kKeyDown ? "down" : code == kKeyLeft ? "left"
                      : code == kKeyRight ? "right" : std::string(1, static_cast<char>(code));
    std::string what;
    switch (a.kind) {
      case ActionKind::kIncrease: what = std::string(kAnalogInputNames[a.input]) + "+"; break;
      case ActionKind::kDecrease: what = std::string(kAnalogInputNames[a.input]) + "-"; break;
      case ActionKind::kCamera: what = "cam" + std::to_string(a.camera); break;
      case ActionKind::kCameraNext: what = "cam+"; break;
      case ActionKind::kCameraPrev: what = "cam-"; break;
      case ActionKind::kReset: what = "reset"; break;
      case ActionKind::kOverlay: what = "overlay"; break;
      case ActionKind::kQuit: what = "quit"; break;
      case ActionKind::kFreeze: what = "freeze"; break;
      case ActionKind::kStep: what = "step"; break;
    }
    s += " " + key + "=" + what;
  }
  return s;
}

}  // namespace

int RunOperatorStation(const OperatorOptions& options, const LabConfig& config, LcmInterface& lcm,
                       const std::string& stats_path, const std::string& ready_path) {
  const int sources = !options.timeline_path.empty() + options.keyboard + options.manual + options.autopilot;
  if (sources != 1) {
    throw InputError("give exactly one input source: --timeline FILE, --keyboard, --manual or --autopilot");
  }
  const bool by_hand = options.keyboard || options.manual;
  const double rate = options.rate_hz > 0 ? options.rate_hz : config.session.frame_rate_hz;
  const std::int64_t period_ns = static_cast<std::int64_t>(std::llround(1e9 / rate));

  // The source.
  std::unique_ptr<Timeline> timeline;
  std::unique_ptr<Bindings> bindings;
  std::unique_ptr<TerminalKeys> terminal;
  std::unique_ptr<ManualControl> manual;
  std::unique_ptr<Autopilot> autopilot;
  std::vector<std::string> device_report;
  std::string source;
  if (!options.timeline_path.empty()) {
    timeline = std::make_unique<Timeline>(Timeline::Load(options.timeline_path, config.inputs));
    for (const std::string& w : timeline->warnings()) spdlog::warn("{}", w);
    spdlog::info("timeline {}: {:.2f} s at {:.1f} Hz, speed {}", options.timeline_path, timeline->end_time(), rate,
                 options.speed);
    source = "timeline " + options.timeline_path;
  } else if (by_hand) {
    bindings = std::make_unique<Bindings>(
        LoadBindings(options.bindings_path.empty() ? DefaultBindingsPath() : options.bindings_path));
    manual = std::make_unique<ManualControl>(config, *bindings);
    // Each device is optional: looked for, and reported either way.
    if (isatty(STDIN_FILENO)) {
      terminal = std::make_unique<TerminalKeys>();
      manual->AddDevice(std::make_unique<KeyboardDevice>(*bindings, [t = terminal.get()] { return t->Next(); }));
    } else if (options.keyboard) {
      throw InputError("--keyboard needs a terminal on standard input");
    } else {
      device_report.push_back("keyboard: none (standard input is not a terminal)");
    }
    std::string why;
    if (options.gamepad) {
      if (auto g = GamepadDevice::Open(*bindings, &why)) manual->AddDevice(std::move(g));
      else device_report.push_back("gamepad: none (" + why + ")");
    }
    if (options.spacemouse) {
      if (auto m = SpaceMouseDevice::Open(*bindings, &why)) manual->AddDevice(std::move(m));
      else device_report.push_back("3D mouse: none (" + why + ")");
    }
    for (const auto& d : device_report) spdlog::info("{}", d);
    if (manual->devices().empty()) throw InputError("no input device found (" + device_report.front() + ")");
    for (const auto& d : manual->devices()) device_report.insert(device_report.begin(), d->Describe());
    source = "by hand";
  } else {
    AutopilotOptions ao;
    ao.plan_clear_paths = !options.autopilot_straight;
    autopilot = std::make_unique<Autopilot>(config, ao);
    source = "autopilot";
  }

  // What the DCP and the other processes say.
  std::optional<dcp_telemetry_t> telemetry;
  RateMeter publish_rate, telemetry_rate;
  double input_to_dcp_ms = -1.0, render_hz = -1.0, render_p50_ms = -1.0, render_p99_ms = -1.0;
  std::int64_t esg_rendered = -1, esg_status_us = 0;
  Counters counters;
  lcm.Subscribe(channels::kDcpTelemetry, [&](const void* data, int size, std::int64_t recv_us) {
    dcp_telemetry_t m{};
    if (const DecodeError e = SafeDecode(data, size, 4096, &m); e != DecodeError::kNone) {
      counters.Add(std::string("dropped.telemetry_") + DecodeErrorName(e));
      return;
    }
    if (const auto why = TelemetryProblem(m)) {
      counters.Add("dropped.telemetry_" + *why);
      return;
    }
    if (telemetry && m.frame <= telemetry->frame && m.frame != 0) {
      counters.Add("telemetry.stale");
      return;
    }
    telemetry = m;
    telemetry_rate.Tick(recv_us);
    input_to_dcp_ms = (recv_us - m.input_send_time_us) / 1000.0;
  });
  lcm.Subscribe(channels::kStatus, [&](const void* data, int size, std::int64_t recv_us) {
    process_status_t m;
    if (SafeDecode(data, size, 1 << 20, &m) != DecodeError::kNone) {
      counters.Add("dropped.status_malformed");
      return;
    }
    if (m.process != "esg_renderer") return;
    for (int i = 0; i < m.num_counters; ++i) {
      const std::string& n = m.counter_names[i];
      const std::int64_t v = m.counter_values[i];
      if (n == "rendered") {
        if (esg_rendered >= 0 && recv_us > esg_status_us) render_hz = (v - esg_rendered) * 1e6 / (recv_us - esg_status_us);
        esg_rendered = v;
        esg_status_us = recv_us;
      } else if (n == "latency.input_to_render.p50_us") {
        render_p50_ms = v / 1000.0;
      } else if (n == "latency.input_to_render.p99_us") {
        render_p99_ms = v / 1000.0;
      }
    }
  });

  // RMS_CONTROL: freeze, run, step; a restored checkpoint (docs/sessions.md).
  // The station is the session's clock: frozen, it stops its source and
  // publishes nothing, so every process holds its frame and nothing is lost.
  bool frozen = false;
  int steps_pending = 0;
  std::optional<std::string> restored_from;
  std::int64_t control_sequence = 0;
  lcm.Subscribe(channels::kControl, [&](const void* data, int size, std::int64_t) {
    session_control_t m;
    if (SafeDecode(data, size, 1 << 16, &m) != DecodeError::kNone) {
      counters.Add("dropped.control_malformed");
      return;
    }
    switch (m.command) {
      case session_control_t::FREEZE:
        if (!frozen) spdlog::info("frozen");
        frozen = true;
        counters.Add("control.freezes");
        break;
      case session_control_t::RUN:
        if (frozen) spdlog::info("running again");
        frozen = false;
        steps_pending = 0;
        break;
      case session_control_t::STEP:
        if (frozen) ++steps_pending;
        counters.Add("control.steps");
        break;
      case session_control_t::RESTORE:
        restored_from = m.path;
        break;
      default:
        break;
    }
  });
  auto send_control = [&](std::int8_t command) {
    session_control_t m;
    m.send_time_us = lcm.NowUs();
    m.sequence = control_sequence++;
    m.command = command;
    if (!PublishMessage(lcm, channels::kControl, m)) counters.Add("publish_failed");
  };
  if (!options.restore_path.empty()) {
    const Checkpoint c = ReadCheckpoint(options.restore_path);
    spdlog::info("starting from the checkpoint {} (DCP frame {})", options.restore_path, c.dcp_frame);
    if (manual) manual->SetInputs(c.inputs);
    if (autopilot) autopilot->Resync(c.inputs);
  }

  // RMSLAB_RESTART (set by the launcher when it restarts this process after a
  // fault, docs/sessions.md "Faults"): the autopilot resumes from the first
  // telemetry instead of starting the task over.
  const char* restart_env = std::getenv("RMSLAB_RESTART");
  bool resume_from_telemetry = autopilot && restart_env && *restart_env && std::string(restart_env) != "0";
  if (restart_env && *restart_env && std::string(restart_env) != "0") counters.Add("restarted");

  const bool screen_on = options.status == 1 || (options.status == -1 && by_hand && isatty(STDOUT_FILENO));
  std::unique_ptr<StatusScreen> screen;
  if (screen_on) screen = std::make_unique<StatusScreen>(config);
  const std::string help = bindings ? KeyHelp(*bindings) : "";

  StatusReporter status(&lcm, "operator_station");
  InputBlockBuilder builder(config.inputs);
  builder.set_next_frame(FirstFrameNumber(config.session.frame_rate_hz));
  if (!ready_path.empty()) TouchFile(ready_path);

  std::int64_t next_ns = MonotonicNs();
  double prev_t = -1.0;
  std::int64_t frames = 0, docked_frames = 0;
  int exit_code = 0;
  while (!StopRequested()) {
    if (options.max_frames >= 0 && frames >= options.max_frames) break;
    if (lcm.HandleSubscriptions(0) < 0) counters.Add("transport_errors");
    if (restored_from) {
      // Carry on from the checkpoint's inputs, so the first frame after it
      // commands the arm where the DCP now has it.
      try {
        const Checkpoint c = ReadCheckpoint(*restored_from);
        if (manual) manual->SetInputs(c.inputs);
        if (autopilot) autopilot->Resync(c.inputs);
        spdlog::info("restored checkpoint {}: carrying on from its inputs", *restored_from);
        counters.Add("control.restores");
      } catch (const InputError& e) {
        counters.Add("control.errors");
        spdlog::error("{}", e.what());
      }
      restored_from.reset();
    }
    if (frozen && steps_pending == 0) {
      // Frozen: no clock, no frames. The session's keys still work.
      if (manual) {
        manual->PollFrozen();
        if (manual->quit()) break;
        if (manual->freeze_requested()) send_control(session_control_t::RUN);
        if (manual->step_requested()) send_control(session_control_t::STEP);
      }
      if (screen) {
        StatusSnapshot s;
        s.source = source + " -- FROZEN (" + (bindings ? "freeze key runs, step key steps" : "rms_control run") + ")";
        s.frame = builder.next_frame() - 1;
        s.telemetry = telemetry;
        s.devices = device_report;
        s.help = help;
        screen->Draw(std::move(s));
      }
      status.Tick(builder.next_frame() - 1, counters);
      SleepUntilNs(MonotonicNs() + period_ns);
      next_ns = MonotonicNs();
      continue;
    }
    if (steps_pending > 0) --steps_pending;
    // Timeline time is the frame count over the rate: jitter-free and reproducible.
    const double t = options.speed * static_cast<double>(frames) / rate;
    OperatorInputs in;
    if (timeline) {
      if (t > timeline->end_time() + 1e-9 && !options.hold) break;
      in = timeline->Sample(t);
      in.reset = timeline->ResetIn(prev_t, t);
    } else if (manual) {
      in = manual->Step(1.0 / rate);
      if (manual->quit()) break;
      if (manual->freeze_requested()) send_control(session_control_t::FREEZE);
    } else {
      if (resume_from_telemetry && telemetry) {
        // Restarted mid-session by the launcher: carry on from the command
        // the DCP last answered, and let the autopilot pick up the task
        // where the telemetry says it is (no reset).
        OperatorInputs from = InitialInputs(config.inputs);
        for (int i = 0; i < 6; ++i) from.value[i] = telemetry->master_angles_deg[i];
        from.value[kShoulderHeight] = telemetry->master_shoulder_height_ft;
        from.value[kFinger] = telemetry->master_finger;
        autopilot->Resync(from);
        resume_from_telemetry = false;
        spdlog::warn("restarted: the autopilot resumes from the DCP's telemetry (Mode {}, frame {})",
                     static_cast<int>(telemetry->mode), telemetry->frame);
      }
      in = autopilot->Step(telemetry ? &*telemetry : nullptr);
      if (autopilot->failed()) {
        exit_code = kExitAutopilotFailed;
        if (!options.hold) break;
      }
      // Docked: hold two seconds of session time (the scene shows it), then stop.
      if (autopilot->docked() && ++docked_frames > 2 * config.session.frame_rate_hz && !options.hold) break;
    }
    prev_t = t;
    const operator_input_t block = builder.Build(in, lcm.NowUs(), &counters);
    if (PublishMessage(lcm, channels::kOperatorInput, block)) counters.Add("published");
    else counters.Add("publish_failed");
    publish_rate.Tick(lcm.NowUs());
    ++frames;
    status.Tick(block.frame, counters);

    if (screen) {
      StatusSnapshot s;
      s.source = source + (autopilot ? std::string(": ") + AutopilotPhaseName(autopilot->phase()) : "");
      s.frame = block.frame;
      s.inputs = in;
      s.telemetry = telemetry;
      s.publish_hz = publish_rate.hz();
      s.telemetry_hz = telemetry_rate.hz();
      s.input_to_dcp_ms = input_to_dcp_ms;
      s.render_hz = render_hz;
      s.input_to_render_p50_ms = render_p50_ms;
      s.input_to_render_p99_ms = render_p99_ms;
      s.clamped_inputs = counters.SumPrefix("clamped.") + (manual ? manual->counters().SumPrefix("clamped.") : 0);
      s.devices = device_report;
      s.help = help;
      screen->Draw(std::move(s));
    }

    next_ns += period_ns;
    const std::int64_t now = MonotonicNs();
    if (now > next_ns + period_ns) {
      counters.Add("frames.late");
      next_ns = now;  // don't try to catch up with a burst
    } else {
      SleepUntilNs(next_ns);
    }
  }
  screen.reset();  // the terminal back, the captured log written out
  if (manual) {
    for (const auto& [k, v] : manual->counters().values()) counters.Add(k, v);
  }
  if (autopilot) {
    for (const auto& [k, v] : autopilot->counters().values()) counters.Add(k, v);
    counters.Set("autopilot.docked", autopilot->docked());
    if (autopilot->failed()) spdlog::error("autopilot failed: {}", autopilot->failure());
    else if (autopilot->docked()) spdlog::info("autopilot: docked {:.1f} s into the session", autopilot->docked_at_s());
  }
  counters.Set("frames.total", frames);
  status.Final(builder.next_frame() - 1, counters);
  if (!stats_path.empty()) WriteStatsJson(stats_path, "operator_station", counters, {});
  spdlog::info("published {} input blocks ({} late, {} clamped inputs)", counters.Get("published"),
               counters.Get("frames.late"), counters.SumPrefix("clamped."));
  if (StopRequested()) {
    spdlog::info("stopped by a signal at frame {}", builder.next_frame() - 1);
    return kExitInterrupted;
  }
  return exit_code;
}

}  // namespace rms::op
