#include "rms/monitor/monitor.h"

#include <chrono>
#include <cstdio>
#include <sstream>
#include <string>

#include "rms/base/counters.h"
#include "rms/base/text.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/operator_input_t.hpp"
#include "rms/operator_state_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/session_control_t.hpp"
#include "rms/transport/process.h"
#include "rms/window_keys_t.hpp"
#include "rms/wire/channels.h"
#include "rms/wire/collision_bits.h"
#include "rms/wire/control_word.h"
#include "rms/wire/key_codes.h"
#include "rms/wire/message_io.h"
#include "rms/wire/word_blocks.h"

namespace rms::monitor {

void ChannelStats::Tick(std::int64_t now_us, int size) {
  ++messages;
  bytes += size;
  if (window_start_us == 0) window_start_us = now_us;
  ++window_count;
  if (now_us - window_start_us >= 1000000) {
    hz = window_count * 1e6 / static_cast<double>(now_us - window_start_us);
    window_start_us = now_us;
    window_count = 0;
  }
}

namespace {

// Each channel's message in a line; false when it is malformed.
bool Input(const void* d, int n, ChannelStats* c) {
  operator_input_t m;
  if (wire::SafeDecode(d, n, &m) != wire::DecodeError::kNone) return false;
  c->numbered = true;
  c->frames.Accept(m.frame);
  c->last = Sprintf("frame %lld, discrete word %06x", static_cast<long long>(m.frame),
                    static_cast<unsigned>(m.words[11]));
  return true;
}

bool DcpFrame(const void* d, int n, ChannelStats* c) {
  dcp_frame_t m;
  if (wire::SafeDecode(d, n, &m) != wire::DecodeError::kNone) return false;
  c->numbered = true;
  c->frames.Accept(m.frame);
  try {
    const wire::ControlWord w = wire::UnpackControlWord(m.control_word);
    c->last = Sprintf("frame %lld (input %lld), mode %d, camera %d%s%s%s%s",
                      static_cast<long long>(m.frame), static_cast<long long>(m.input_frame),
                      w.mode, w.camera_station, w.collision ? ", COLL" : "",
                      w.receptacle_collision ? ", RECPT" : "", w.acquired ? ", ACQ" : "",
                      w.docked ? ", DOCK" : "");
  } catch (const std::exception&) {
    return false;
  }
  return true;
}

bool Telemetry(const void* d, int n, ChannelStats* c) {
  dcp_telemetry_t m{};
  if (wire::SafeDecode(d, n, &m) != wire::DecodeError::kNone) return false;
  c->numbered = true;
  c->frames.Accept(m.frame);
  const std::string coll =
      wire::CollisionNames(static_cast<std::uint32_t>(m.collisions), ",", "none");
  c->last = Sprintf(
      "frame %lld, mode %d%s, A (%.2f, %.2f, %.2f) ft, dock %.3f ft / %.2f deg, collisions %s",
      static_cast<long long>(m.frame), m.mode, m.held ? " HELD" : "", m.p_RoA_R_ft[0],
      m.p_RoA_R_ft[1], m.p_RoA_R_ft[2], m.dock_distance_ft, m.dock_angle_deg, coll.c_str());
  return true;
}

bool EsgFrame(const void* d, int n, ChannelStats* c) {
  esg_frame_t m;
  if (wire::SafeDecode(d, n, &m) != wire::DecodeError::kNone) return false;
  c->numbered = true;
  c->frames.Accept(m.frame);
  try {
    const wire::EsgFrameData e = wire::UnpackEsgWords(m.words);
    c->last = Sprintf(
        "frame %lld (DCP %lld), %d words, camera %d, eye (%.1f, %.1f, %.1f) ft, fov %.1f deg",
        static_cast<long long>(m.frame), static_cast<long long>(m.dcp_frame), m.num_words,
        e.control.camera_station, e.p_RoEye_R_ft.x(), e.p_RoEye_R_ft.y(), e.p_RoEye_R_ft.z(),
        e.fov_deg);
  } catch (const std::exception&) {
    return false;
  }
  return true;
}

bool OperatorState(const void* d, int n, ChannelStats* c) {
  operator_state_t m{};
  if (wire::SafeDecode(d, n, &m) != wire::DecodeError::kNone) return false;
  c->last = Sprintf("frame %lld, source %d, to go %.2f ft / %.1f deg",
                    static_cast<long long>(m.frame), m.source, m.distance_ft, m.angle_deg);
  return true;
}

bool WindowKeys(const void* d, int n, ChannelStats* c) {
  window_keys_t m{};
  if (wire::SafeDecode(d, n, &m) != wire::DecodeError::kNone) return false;
  std::string held;
  for (int k : m.held) {
    if (!held.empty()) held += ' ';
    held += wire::KeyName(k);
  }
  c->last = Sprintf("#%lld held: %s%s", static_cast<long long>(m.sequence),
                    held.empty() ? "none" : held.c_str(), m.focused ? "" : " (window not focused)");
  return true;
}

bool Control(const void* d, int n, ChannelStats* c) {
  session_control_t m;
  if (wire::SafeDecode(d, n, &m) != wire::DecodeError::kNone) return false;
  c->last = Sprintf("#%lld %s %s", static_cast<long long>(m.sequence),
                    wire::ControlCommandName(m.command), m.name.c_str());
  return true;
}

}  // namespace

template <class Decode>
void Monitor::On(const char* channel, Decode decode) {
  channels_[channel];
  lcm_->Subscribe(channel, [this, channel, decode](const void* d, int n, std::int64_t t) {
    ChannelStats& c = channels_[channel];
    c.Tick(t, n);
    // Without the session (--session), a session's message is shown with
    // its tag unchecked (docs/security.md "Authenticated messages"): the
    // message is what precedes it.
    if (decode(d, n, &c)) return;
    if (!lcm_->authenticates() && n > wire::kMacBytes && decode(d, n - wire::kMacBytes, &c)) {
      ++c.tagged_unchecked;
      return;
    }
    ++c.malformed;
  });
}

Monitor::Monitor(transport::LcmInterface* lcm, transport::LcmOptions options)
    : lcm_(lcm), options_(std::move(options)) {
  On(wire::channels::kOperatorInput, Input);
  On(wire::channels::kDcpFrame, DcpFrame);
  On(wire::channels::kDcpTelemetry, Telemetry);
  On(wire::channels::kEsgFrame, EsgFrame);
  On(wire::channels::kStatus,
     [this](const void* d, int n, ChannelStats* c) { return Status(d, n, c); });
  On(wire::channels::kOperatorState, OperatorState);
  On(wire::channels::kWindowKeys, WindowKeys);
  On(wire::channels::kControl, Control);
}

// A process's status: its line in the processes' list.
bool Monitor::Status(const void* d, int n, ChannelStats* c) {
  process_status_t m;
  if (wire::SafeDecode(d, n, &m) != wire::DecodeError::kNone) return false;
  std::map<std::string, std::int64_t> v;
  for (int i = 0; i < m.num_counters; ++i) v[m.counter_names[i]] = m.counter_values[i];
  auto get = [&](Counter c) {
    const std::string k(CounterName(c));
    return v.count(k) ? v[k] : 0;
  };
  // At most kMaxProcesses names (forged statuses cannot grow it without end).
  if (!processes_.count(m.process) && processes_.size() >= kMaxProcesses) return true;
  processes_[m.process] =
      Sprintf("%-16s on %s (pid %d): frame %lld, published %lld, late %lld, missing %lld%s",
              m.process.c_str(), m.host.c_str(), m.pid, static_cast<long long>(m.frame),
              static_cast<long long>(get(Counter::kPublished)),
              static_cast<long long>(get(Counter::kFramesLate)),
              static_cast<long long>(get(Counter::kInputMissing)) + get(Counter::kDcpMissing) +
                  get(Counter::kEsgMissing),
              m.final ? " (final)" : "");
  c->last = Sprintf("%zu processes reporting", processes_.size());
  return true;
}

std::string Monitor::Render() const {
  std::ostringstream os;
  os << "rmslab monitor: " << options_.url
     << (options_.channel_suffix.empty() ? "" : " suffix " + options_.channel_suffix) << "\n";
  os << Sprintf("%-22s %9s %8s %9s %7s %9s  %s\n", "channel", "messages", "rate Hz", "kB", "gaps",
                "malformed", "latest");
  for (const auto& [name, c] : channels_) {
    os << Sprintf("%-22s %9lld %8.1f %9.1f %7s %9lld  %s\n",
                  (name + options_.channel_suffix).c_str(), static_cast<long long>(c.messages),
                  c.hz, c.bytes / 1024.0,
                  c.numbered ? std::to_string(c.frames.missing()).c_str() : "-",
                  static_cast<long long>(c.malformed), c.last.c_str());
  }
  os << "processes:\n";
  for (const auto& [p, line] : processes_) os << "  " << line << "\n";
  // Names, hosts and checkpoint names come from messages: their control
  // characters are shown, not obeyed (docs/security.md).
  return TerminalText(os.str());
}

std::string Monitor::Run(double for_s) {
  const auto start = std::chrono::steady_clock::now();
  auto last_draw = start;
  const bool live = for_s <= 0.0;
  if (live) std::fputs("\x1b[?1049h\x1b[?25l", stdout);
  while (!transport::StopRequested()) {
    lcm_->HandleSubscriptions(50);
    const auto now = std::chrono::steady_clock::now();
    if (!live && now - start >= std::chrono::duration<double>(for_s)) break;
    if (live && now - last_draw >= std::chrono::milliseconds(500)) {
      last_draw = now;
      // Home, each line cleared to its end, the rest of the screen cleared.
      std::string out = "\x1b[H";
      std::istringstream is(Render());
      for (std::string line; std::getline(is, line);) out.append(line).append("\x1b[K\n");
      out.append("\x1b[J");
      std::fputs(out.c_str(), stdout);
      std::fflush(stdout);
    }
  }
  if (live) std::fputs("\x1b[?25h\x1b[?1049l", stdout);
  return Render();
}

}  // namespace rms::monitor
