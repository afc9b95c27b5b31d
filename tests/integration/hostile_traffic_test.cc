// Hostile traffic (docs/security.md): while the four real processes fly a
// timeline over real LCM, another program publishes on every channel
// messages of the wrong type, truncated ones, words with bits above 24,
// NaN and out-of-range values, stale frame numbers, and a flood. Every
// process counts what it dropped and why, keeps its frame rate and exits
// cleanly.
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <thread>

#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/operator_input_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/session_control_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/channels.h"
#include "rms/wire/input_block.h"
#include "rms/wire/message_io.h"

#include "lab_processes.h"
#include "subprocess.h"

namespace rms {
namespace {

using testing::LabProcesses;

nlohmann::json Counters(const std::string& path) {
  std::ifstream f(path);
  if (!f) return nlohmann::json::object();
  return nlohmann::json::parse(f).value("counters", nlohmann::json::object());
}
std::int64_t Get(const nlohmann::json& c, const std::string& k) {
  return c.value(k, std::int64_t{0});
}

struct Attacker {
  transport::UdpLcm* lcm = nullptr;
  std::mt19937_64 rng{19721122};
  std::atomic<long> sent{0};
  std::optional<dcp_frame_t> seen_dcp;
  std::optional<esg_frame_t> seen_esg;
  void Listen() {
    lcm->Subscribe(wire::channels::kDcpFrame, [this](const void* d, int n, std::int64_t) {
      dcp_frame_t m;
      if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone && m.frame > 0) seen_dcp = m;
    });
    lcm->Subscribe(wire::channels::kEsgFrame, [this](const void* d, int n, std::int64_t) {
      esg_frame_t m;
      if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone && m.frame > 0) seen_esg = m;
    });
  }

  template <class Msg>
  void Send(const char* channel, const Msg& m) {
    const auto bytes = wire::EncodeMessage(m);
    lcm->Publish(channel, bytes.data(), static_cast<int>(bytes.size()));
    ++sent;
  }
  template <class Msg>
  void SendTruncated(const char* channel, const Msg& m) {
    const auto bytes = wire::EncodeMessage(m);
    lcm->Publish(channel, bytes.data(), static_cast<int>(bytes.size() / 2));
    ++sent;
  }
  void SendRaw(const char* channel, const std::vector<std::uint8_t>& b) {
    lcm->Publish(channel, b.data(), static_cast<int>(b.size()));
    ++sent;
  }

  static operator_input_t Input(std::int64_t frame) {
    operator_input_t m{};
    m.frame = frame;
    m.send_time_us = transport::WallTimeUs();
    return m;
  }
  static dcp_frame_t Dcp(std::int64_t frame) {
    dcp_frame_t m{};
    m.frame = frame;
    m.send_time_us = m.input_send_time_us = transport::WallTimeUs();
    return m;
  }
  static esg_frame_t Esg(std::int64_t frame) {
    esg_frame_t m{};
    m.frame = frame;
    m.send_time_us = m.input_send_time_us = transport::WallTimeUs();
    m.num_words = 10;
    m.words.assign(10, 0);
    return m;
  }
  static dcp_telemetry_t Telemetry(std::int64_t frame) {
    dcp_telemetry_t m{};
    m.frame = frame;
    m.send_time_us = m.input_send_time_us = transport::WallTimeUs();
    m.mode = 1;
    for (int i = 0; i < 9; i += 4) m.R_RS2[i] = m.R_RP[i] = 1;
    return m;
  }

  // One round of every kind on every channel.
  void Round() {
    using namespace wire::channels;
    // Wrong type: a well-formed message of another type on each channel.
    Send(kOperatorInput, Esg(1));
    Send(kDcpFrame, Input(1));
    Send(kEsgFrame, Dcp(1));
    Send(kDcpTelemetry, Input(1));
    Send(kStatus, Telemetry(1));
    Send(kControl, Esg(1));
    // Truncated.
    SendTruncated(kOperatorInput, Input(1));
    SendTruncated(kDcpFrame, Dcp(1));
    SendTruncated(kEsgFrame, Esg(1));
    SendTruncated(kDcpTelemetry, Telemetry(1));
    process_status_t st{};
    st.process = "esg_renderer";
    SendTruncated(kStatus, st);
    session_control_t ctl{};
    ctl.command = session_control_t::FREEZE;
    SendTruncated(kControl, ctl);
    // Bits above 24 in a word, at a stale frame number (never a future one:
    // see docs/security.md on what no check can refuse).
    operator_input_t in = Input(0);
    in.words[0] = 0x1000000;
    Send(kOperatorInput, in);
    dcp_frame_t d = Dcp(0);
    d.arm_words[0] = 0x1000000;
    Send(kDcpFrame, d);
    esg_frame_t e = Esg(0);
    e.words[3] = 0x7000000;
    Send(kEsgFrame, e);
    // NaN and out-of-range values.
    dcp_telemetry_t t = Telemetry(1);
    t.finger_gap_ft = std::nan("");
    Send(kDcpTelemetry, t);
    t = Telemetry(1);
    t.mode = 7;
    Send(kDcpTelemetry, t);
    operator_input_t r = Input(0);
    r.words[wire::kInputWords - 1] = 0xFFFFE0;  // reserved discrete bits
    Send(kOperatorInput, r);
    esg_frame_t big = Esg(0);
    big.num_words = 200;
    big.words.assign(200, 0);
    Send(kEsgFrame, big);
    operator_input_t neg = Input(-5);
    Send(kOperatorInput, neg);
    // Stale frame numbers: well-formed, long past -- real messages seen on
    // the bus, replayed with frame 0, as a careless or hostile peer would.
    Send(kOperatorInput, Input(0));
    lcm->HandleSubscriptions(0);
    if (seen_dcp) {
      dcp_frame_t old = *seen_dcp;
      old.frame = 0;
      Send(kDcpFrame, old);
    }
    if (seen_esg) {
      esg_frame_t old = *seen_esg;
      old.frame = 0;
      Send(kEsgFrame, old);
    }
    // Random bytes.
    std::vector<std::uint8_t> junk(1 + rng() % 300);
    for (auto& b : junk) b = static_cast<std::uint8_t>(rng());
    for (const char* ch : {kOperatorInput, kDcpFrame, kEsgFrame, kDcpTelemetry, kStatus, kControl})
      SendRaw(ch, junk);
  }

  void Flood(int n) {
    using namespace wire::channels;
    const char* chs[] = {kOperatorInput, kDcpFrame, kEsgFrame, kDcpTelemetry, kStatus, kControl};
    for (int i = 0; i < n; ++i) {
      std::vector<std::uint8_t> junk(8 + rng() % 200);
      for (auto& b : junk) b = static_cast<std::uint8_t>(rng());
      SendRaw(chs[i % 6], junk);
    }
  }
};

TEST(HostileTraffic, EveryProcessCountsWhatItDroppedAndKeepsItsFrameRate) {
  const std::string dir = testing::MakeTempDir("hostile");
  const std::string url = testing::UniqueLcmUrl(8300);
  const std::string timeline = dir + "/six_seconds.tl";
  std::ofstream(timeline)
      << "0.0 camera=8\n6.0 shoulder_yaw=20 shoulder_pitch=30 elbow_pitch=-40 finger=1\n6.0 end\n";
  LabProcesses lab(dir, url);
  std::string error;
  ASSERT_TRUE(lab.Start(&error)) << error;

  transport::LcmOptions o;
  o.url = url;
  transport::UdpLcm listen(o), attack_lcm(o);
  long esg_frames = 0;
  listen.Subscribe(wire::channels::kEsgFrame,
                   [&](const void*, int, std::int64_t) { ++esg_frames; });

  Attacker attacker;
  attacker.lcm = &attack_lcm;
  attacker.Listen();
  std::atomic<bool> done{false};
  const int kFlood = 20000;
  std::printf("hostile traffic: seed 19721122, flood %d messages\n", kFlood);
  std::thread t([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(1000));  // frames are flowing
    int round = 0;
    while (!done) {
      attacker.Round();
      if (++round == 20) attacker.Flood(kFlood);
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });
  const int rc = lab.Fly(listen, timeline);
  done = true;
  t.join();
  EXPECT_EQ(rc, 0) << testing::ReadFile(dir + "/operator_station.log");
  ASSERT_TRUE(lab.Stop(&error)) << error;  // every process exits 0: nothing crashed
  std::printf("hostile messages sent: %ld\n", attacker.sent.load());

  const auto op = Counters(dir + "/operator_station.json");
  const auto dcp = Counters(dir + "/dynamics_proc.json");
  const auto scene = Counters(dir + "/scene_proc.json");
  const auto esg = Counters(dir + "/esg_renderer.json");
  std::printf("operator_station: %s\ndynamics_proc: %s\nscene_proc: %s\nesg_renderer: %s\n",
              op.dump().c_str(), dcp.dump().c_str(), scene.dump().c_str(), esg.dump().c_str());
  // Each process counted each kind it was sent, by reason.
  for (const auto& [name, c] :
       {std::pair{"dynamics_proc", dcp}, {"scene_proc", scene}, {"esg_renderer", esg}}) {
    for (const char* k : {"dropped.wrong_type", "dropped.truncated", "dropped.bad_word",
                          "dropped.stale", "dropped.bad_frame"}) {
      if (std::string(name) != "dynamics_proc" && std::string(k) == "dropped.bad_frame") continue;
      EXPECT_GT(Get(c, k), 0) << name << " " << k;
    }
  }
  EXPECT_GT(Get(dcp, "dropped.bad_word"), 0);
  EXPECT_GT(Get(esg, "dropped.word_count") + Get(esg, "dropped.too_large"), 0);
  EXPECT_GT(Get(dcp, "dropped.control_malformed"), 0);
  for (const char* k : {"dropped.telemetry_wrong_type", "dropped.telemetry_truncated",
                        "dropped.telemetry_non_finite", "dropped.telemetry_mode",
                        "dropped.status_malformed", "dropped.control_malformed"}) {
    EXPECT_GT(Get(op, k), 0) << "operator_station " << k;
  }
  // It kept its frame rate: every operator frame became a DCP frame and an
  // ESG frame, or was counted missing (a flood can overrun a socket
  // buffer); at most 5 % lost.
  const std::int64_t published = Get(op, "published");
  EXPECT_GE(published, 170);  // 6 s at 30 Hz
  EXPECT_GE(Get(dcp, "published"), published * 95 / 100);
  EXPECT_GE(Get(esg, "rendered"), published * 95 / 100);
  EXPECT_GE(esg_frames, published * 95 / 100);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rms
