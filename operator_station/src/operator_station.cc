#include "operator_station.h"

#include <cerrno>
#include <cmath>
#include <memory>
#include <spdlog/spdlog.h>
#include <time.h>

#include "keyboard.h"
#include "rms/channels.h"
#include "rms/check.h"
#include "rms/message_io.h"
#include "rms/process.h"
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

}  // namespace

int RunOperatorStation(const OperatorOptions& options, const LabConfig& config, LcmInterface& lcm,
                       const std::string& stats_path, const std::string& ready_path) {
  if (options.keyboard == !options.timeline_path.empty()) {
    throw InputError("give exactly one input source: --timeline FILE or --keyboard");
  }
  const double rate = options.rate_hz > 0 ? options.rate_hz : config.session.frame_rate_hz;
  const std::int64_t period_ns = static_cast<std::int64_t>(std::llround(1e9 / rate));

  std::unique_ptr<Timeline> timeline;
  std::unique_ptr<TerminalKeys> keys;
  if (!options.timeline_path.empty()) {
    timeline = std::make_unique<Timeline>(Timeline::Load(options.timeline_path, config.inputs));
    for (const std::string& w : timeline->warnings()) spdlog::warn("{}", w);
    spdlog::info("timeline {}: {:.2f} s at {:.1f} Hz, speed {}", options.timeline_path,
                 timeline->end_time(), rate, options.speed);
  } else {
    keys = std::make_unique<TerminalKeys>();
    spdlog::info("{}", KeyboardHelp());
  }

  Counters counters;
  LatencyMap latencies;
  StatusReporter status(&lcm, "operator_station");
  InputBlockBuilder builder(config.inputs);
  OperatorInputs kb_inputs = InitialInputs(config.inputs);
  if (!ready_path.empty()) TouchFile(ready_path);

  std::int64_t next_ns = MonotonicNs();
  double prev_t = -1.0;
  bool quit = false;
  std::int64_t frames = 0;
  std::int64_t last_status_line_ns = 0;
  while (!StopRequested() && !quit) {
    if (options.max_frames >= 0 && frames >= options.max_frames) break;
    // Timeline time is the frame count over the rate: jitter-free and reproducible.
    const double t = options.speed * static_cast<double>(frames) / rate;
    OperatorInputs in;
    if (timeline) {
      if (t > timeline->end_time() + 1e-9 && !options.hold) break;
      in = timeline->Sample(t);
      in.reset = timeline->ResetIn(prev_t, t);
    } else {
      kb_inputs.reset = false;
      for (int k = keys->Next(); k >= 0; k = keys->Next()) {
        if (!ApplyKey(k, config.inputs, &kb_inputs, &quit)) counters.Add("keyboard.unbound_key");
      }
      in = kb_inputs;
    }
    prev_t = t;
    const operator_input_t block = builder.Build(in, lcm.NowUs(), &counters);
    if (PublishMessage(lcm, channels::kOperatorInput, block)) counters.Add("published");
    else counters.Add("publish_failed");
    ++frames;
    lcm.HandleSubscriptions(0);
    status.Tick(block.frame, counters);

    if (keys && MonotonicNs() - last_status_line_ns > 500000000) {
      last_status_line_ns = MonotonicNs();
      std::fprintf(stderr,
                   "\rframe %6lld  yaw %6.1f pitch %6.1f elbow %6.1f wp %6.1f wy %6.1f wr %6.1f  "
                   "finger %.2f  h %5.2f ft  cam %d  pan %5.1f tilt %5.1f zoom %.2f   ",
                   static_cast<long long>(block.frame), in.value[0], in.value[1], in.value[2],
                   in.value[3], in.value[4], in.value[5], in.value[kFinger],
                   in.value[kShoulderHeight], in.camera_station, in.value[kCameraPan],
                   in.value[kCameraTilt], in.value[kCameraZoom]);
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
  if (keys) std::fprintf(stderr, "\n");
  counters.Set("frames.total", frames);
  status.Final(builder.next_frame() - 1, counters);
  if (!stats_path.empty()) WriteStatsJson(stats_path, "operator_station", counters, latencies);
  spdlog::info("published {} input blocks ({} late, {} clamped inputs)", counters.Get("published"),
               counters.Get("frames.late"), counters.SumPrefix("clamped."));
  if (StopRequested()) {
    spdlog::info("stopped by a signal at frame {}", builder.next_frame() - 1);
    return kExitInterrupted;
  }
  return 0;
}

}  // namespace rms::op
