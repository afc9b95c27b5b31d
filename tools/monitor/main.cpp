// rms_monitor: live decoded traffic of a session, per channel, with rates
// (docs/sessions.md "Monitor"); lcm-spy does not run on Java 17.
//   rms_monitor [--lcm-url URL] [--channel-suffix S]        redraws twice a second
//   rms_monitor --for SECONDS                                one plain snapshot, then exit
#include <CLI/CLI.hpp>
#include "rms/base/command_line.h"
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <thread>

#include "rms/wire/channels.h"
#include "rms/wire/collision_bits.h"
#include "rms/wire/control_word.h"
#include "rms/base/counters.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/message_io.h"
#include "rms/operator_input_t.hpp"
#include "rms/transport/process.h"
#include "rms/process_status_t.hpp"
#include "rms/wire/key_codes.h"
#include "rms/operator_state_t.hpp"
#include "rms/session_control_t.hpp"
#include "rms/window_keys_t.hpp"
#include "rms/wire/word_blocks.h"
#include "rms/base/text.h"

using rms::Sprintf;

namespace {

struct ChannelStats {
  std::int64_t messages = 0, malformed = 0, bytes = 0;
  rms::wire::SequenceTracker frames;
  bool numbered = false;
  std::int64_t window_start_us = 0, window_count = 0;
  double hz = 0.0;
  std::string last;  // the latest message, decoded, one line
  void Tick(std::int64_t now_us, int size) {
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
};


}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rmslab rms_monitor: live decoded traffic of a session, per channel, with rates"};
  rms::transport::LcmOptions lcm_options;
  double for_s = 0.0;
  app.add_option("--lcm-url", lcm_options.url, "LCM URL of the session")->capture_default_str();
  app.add_option("--channel-suffix", lcm_options.channel_suffix, "The session's channel suffix");
  app.add_option("--for", for_s, "Listen this many seconds, print one snapshot and exit (0: live, until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  rms::transport::InstallStopHandlers();
  try {
    rms::transport::UdpLcm lcm(lcm_options);
    std::map<std::string, ChannelStats> ch;
    std::map<std::string, std::string> processes;  // name -> its last status line
    auto on = [&](const char* name, auto decode) {
      ch[name];
      lcm.Subscribe(name, [&, name, decode](const void* d, int n, std::int64_t t) {
        ChannelStats& c = ch[name];
        c.Tick(t, n);
        if (!decode(d, n, &c)) ++c.malformed;
      });
    };
    using rms::wire::DecodeError;
    on(rms::wire::channels::kOperatorInput, [](const void* d, int n, ChannelStats* c) {
      rms::operator_input_t m;
      if (rms::wire::SafeDecode(d, n, &m) != rms::wire::DecodeError::kNone) return false;
      c->numbered = true;
      c->frames.Accept(m.frame);
      c->last = Sprintf("frame %lld, discrete word %06x", static_cast<long long>(m.frame), static_cast<unsigned>(m.words[11]));
      return true;
    });
    on(rms::wire::channels::kDcpFrame, [](const void* d, int n, ChannelStats* c) {
      rms::dcp_frame_t m;
      if (rms::wire::SafeDecode(d, n, &m) != rms::wire::DecodeError::kNone) return false;
      c->numbered = true;
      c->frames.Accept(m.frame);
      try {
        const rms::wire::ControlWord w = rms::wire::UnpackControlWord(m.control_word);
        c->last = Sprintf("frame %lld (input %lld), mode %d, camera %d%s%s%s%s", static_cast<long long>(m.frame),
                      static_cast<long long>(m.input_frame), w.mode, w.camera_station, w.collision ? ", COLL" : "",
                      w.receptacle_collision ? ", RECPT" : "", w.acquired ? ", ACQ" : "", w.docked ? ", DOCK" : "");
      } catch (const std::exception&) {
        return false;
      }
      return true;
    });
    on(rms::wire::channels::kDcpTelemetry, [](const void* d, int n, ChannelStats* c) {
      rms::dcp_telemetry_t m{};
      if (rms::wire::SafeDecode(d, n, &m) != rms::wire::DecodeError::kNone) return false;
      c->numbered = true;
      c->frames.Accept(m.frame);
      const std::string coll = rms::wire::CollisionNames(static_cast<std::uint32_t>(m.collisions), ",", "none");
      c->last = Sprintf("frame %lld, mode %d%s, A (%.2f, %.2f, %.2f) ft, dock %.3f ft / %.2f deg, collisions %s",
                    static_cast<long long>(m.frame), m.mode, m.held ? " HELD" : "", m.p_RoA_R_ft[0], m.p_RoA_R_ft[1],
                    m.p_RoA_R_ft[2], m.dock_distance_ft, m.dock_angle_deg, coll.c_str());
      return true;
    });
    on(rms::wire::channels::kEsgFrame, [](const void* d, int n, ChannelStats* c) {
      rms::esg_frame_t m;
      if (rms::wire::SafeDecode(d, n, &m) != rms::wire::DecodeError::kNone) return false;
      c->numbered = true;
      c->frames.Accept(m.frame);
      try {
        const rms::wire::EsgFrameData e = rms::wire::UnpackEsgWords(m.words);
        c->last = Sprintf("frame %lld (DCP %lld), %d words, camera %d, eye (%.1f, %.1f, %.1f) ft, fov %.1f deg",
                      static_cast<long long>(m.frame), static_cast<long long>(m.dcp_frame), m.num_words,
                      e.control.camera_station, e.p_RoEye_R_ft.x(), e.p_RoEye_R_ft.y(), e.p_RoEye_R_ft.z(), e.fov_deg);
      } catch (const std::exception&) {
        return false;
      }
      return true;
    });
    on(rms::wire::channels::kStatus, [&processes](const void* d, int n, ChannelStats* c) {
      rms::process_status_t m;
      if (rms::wire::SafeDecode(d, n, &m) != rms::wire::DecodeError::kNone) return false;
      std::map<std::string, std::int64_t> v;
      for (int i = 0; i < m.num_counters; ++i) v[m.counter_names[i]] = m.counter_values[i];
      auto get = [&](rms::Counter c) {
        const std::string k(rms::CounterName(c));
        return v.count(k) ? v[k] : 0;
      };
      processes[m.process] = Sprintf("%-16s on %s (pid %d): frame %lld, published %lld, late %lld, missing %lld%s",
                                 m.process.c_str(), m.host.c_str(), m.pid, static_cast<long long>(m.frame),
                                 static_cast<long long>(get(rms::Counter::kPublished)), static_cast<long long>(get(rms::Counter::kFramesLate)),
                                 static_cast<long long>(get(rms::Counter::kInputMissing) + get(rms::Counter::kDcpMissing) + get(rms::Counter::kEsgMissing)),
                                 m.final ? " (final)" : "");
      c->last = Sprintf("%zu processes reporting", processes.size());
      return true;
    });
    on(rms::wire::channels::kOperatorState, [](const void* d, int n, ChannelStats* c) {
      rms::operator_state_t m{};
      if (rms::wire::SafeDecode(d, n, &m) != rms::wire::DecodeError::kNone) return false;
      c->last = Sprintf("frame %lld, source %d, to go %.2f ft / %.1f deg", static_cast<long long>(m.frame), m.source,
                        m.distance_ft, m.angle_deg);
      return true;
    });
    on(rms::wire::channels::kWindowKeys, [](const void* d, int n, ChannelStats* c) {
      rms::window_keys_t m{};
      if (rms::wire::SafeDecode(d, n, &m) != rms::wire::DecodeError::kNone) return false;
      std::string held;
      for (int k : m.held) held += (held.empty() ? "" : " ") + rms::wire::KeyName(k);
      c->last = Sprintf("#%lld held: %s%s", static_cast<long long>(m.sequence), held.empty() ? "none" : held.c_str(),
                        m.focused ? "" : " (window not focused)");
      return true;
    });
    on(rms::wire::channels::kControl, [](const void* d, int n, ChannelStats* c) {
      rms::session_control_t m;
      if (rms::wire::SafeDecode(d, n, &m) != rms::wire::DecodeError::kNone) return false;
      static const char* kNames[] = {"?", "freeze", "run", "step", "checkpoint", "restore"};
      c->last = Sprintf("#%lld %s %s", static_cast<long long>(m.sequence), m.command >= 1 && m.command <= 5 ? kNames[m.command] : "?",
                    m.name.c_str());
      return true;
    });

    auto render = [&]() {
      std::ostringstream os;
      os << "rmslab monitor: " << lcm_options.url
         << (lcm_options.channel_suffix.empty() ? "" : " suffix " + lcm_options.channel_suffix) << "\n";
      os << Sprintf("%-22s %9s %8s %9s %7s %9s  %s\n", "channel", "messages", "rate Hz", "kB", "gaps", "malformed", "latest");
      for (const auto& [name, c] : ch) {
        os << Sprintf("%-22s %9lld %8.1f %9.1f %7s %9lld  %s\n", (name + lcm_options.channel_suffix).c_str(),
                  static_cast<long long>(c.messages), c.hz, c.bytes / 1024.0,
                  c.numbered ? std::to_string(c.frames.missing()).c_str() : "-", static_cast<long long>(c.malformed),
                  c.last.c_str());
      }
      os << "processes:\n";
      for (const auto& [p, line] : processes) os << "  " << line << "\n";
      return os.str();
    };

    const auto start = std::chrono::steady_clock::now();
    auto last_draw = start;
    const bool live = for_s <= 0.0;
    if (live) std::fputs("\x1b[?1049h\x1b[?25l", stdout);
    while (!rms::transport::StopRequested()) {
      lcm.HandleSubscriptions(50);
      const auto now = std::chrono::steady_clock::now();
      if (!live && now - start >= std::chrono::duration<double>(for_s)) break;
      if (live && now - last_draw >= std::chrono::milliseconds(500)) {
        last_draw = now;
        std::string frame = "\x1b[H" + render();
        std::string out;
        std::istringstream is(frame);
        for (std::string line; std::getline(is, line);) out += line + "\x1b[K\n";
        std::fputs((out + "\x1b[J").c_str(), stdout);
        std::fflush(stdout);
      }
    }
    if (live) std::fputs("\x1b[?25h\x1b[?1049l", stdout);
    std::fputs(render().c_str(), stdout);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rms_monitor: %s\n", e.what());
    return 2;
  }
}
