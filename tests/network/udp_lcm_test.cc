// The UDP transport: real LCM multicast on the machine's loopback (label
// network): delivery, senders stamped, other sessions and impostors dropped,
// a bad URL refused with the fix.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <thread>

#include "rms/base/check.h"
#include "rms/esg_frame_t.hpp"
#include "rms/operator_input_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/sender_t.hpp"
#include "rms/session_control_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/channels.h"
#include "rms/wire/message_auth.h"
#include "rms/wire/message_io.h"

namespace rms {
namespace {

TEST(UdpLcm, RealMulticastOnLoopbackDeliversToASecondInstance) {
  transport::LcmOptions o;
  o.url = "udpm://239.255.76.67:" + std::to_string(7800 + getpid() % 150) + "?ttl=0";
  o.channel_suffix = "_T";
  transport::UdpLcm a(o), b(o);
  std::vector<std::int64_t> frames;
  b.Subscribe(wire::channels::kOperatorInput, [&](const void* d, int n, std::int64_t) {
    operator_input_t m;
    if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone) frames.push_back(m.frame);
  });
  for (int i = 0; i < 50; ++i) {
    operator_input_t m{};
    m.frame = i;
    ASSERT_TRUE(transport::PublishMessage(a, wire::channels::kOperatorInput, m));
  }
  for (int k = 0; k < 50 && frames.size() < 50; ++k) b.HandleSubscriptions(20);
  ASSERT_EQ(frames.size(), 50u);
  for (int i = 0; i < 50; ++i) EXPECT_EQ(frames[i], i);
}

// Every message carries its sender (docs/protocol.md "Senders"); a process
// of a session takes only its own session's messages and counts the others;
// one of no session takes all.
TEST(UdpLcm, MessagesAreStampedWithTheirSenderAndOtherSessionsAreDropped) {
  transport::LcmOptions o;
  o.url = "udpm://239.255.76.67:" + std::to_string(7950 + getpid() % 40) + "?ttl=0";
  o.channel_suffix = "_SID";
  transport::UdpLcm a(o), b(o), mine(o), none(o);
  a.SetSender({0x1111, sender_t::PROCESS_OPERATOR_STATION, 4242});
  b.SetSender({0x2222, sender_t::PROCESS_OPERATOR_STATION, 4343});
  mine.SetSender({0x1111, sender_t::PROCESS_DYNAMICS, 1});
  std::vector<sender_t> got_mine, got_none;
  auto collect = [](std::vector<sender_t>* into) {
    return [into](const void* d, int n, std::int64_t) {
      operator_input_t m;
      if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone) into->push_back(m.sender);
    };
  };
  mine.Subscribe(wire::channels::kOperatorInput, collect(&got_mine));
  none.Subscribe(wire::channels::kOperatorInput, collect(&got_none));
  for (int i = 0; i < 10; ++i) {
    operator_input_t m{};
    m.frame = i;
    m.sender.session_id =
        0x7777;  // whatever the caller left there, the transport's sender goes out
    ASSERT_TRUE(transport::PublishMessage(a, wire::channels::kOperatorInput, m));
    ASSERT_TRUE(transport::PublishMessage(b, wire::channels::kOperatorInput, m));
  }
  // Until every message has reached both (B's to `mine` are only counted).
  for (int k = 0; k < 50 && (got_mine.size() < 10 || got_none.size() < 20 ||
                             mine.other_session_dropped() < 10);
       ++k) {
    mine.HandleSubscriptions(20);
    none.HandleSubscriptions(0);
  }
  ASSERT_EQ(got_mine.size(), 10u);
  for (const sender_t& s : got_mine) {
    EXPECT_EQ(s.session_id, 0x1111);
    EXPECT_EQ(s.process, sender_t::PROCESS_OPERATOR_STATION);
    EXPECT_EQ(s.pid, 4242);
  }
  EXPECT_EQ(mine.other_session_dropped(), 10);
  EXPECT_EQ(got_none.size(), 20u);
  EXPECT_EQ(none.other_session_dropped(), 0);
  // Something that is not an rmslab message is left to the decoder to refuse.
  const char junk[40] = {1, 2, 3};
  a.Publish(wire::channels::kOperatorInput, junk, sizeof junk);
  int raw = 0;
  mine.Subscribe(wire::channels::kStatus, [&](const void*, int, std::int64_t) { ++raw; });
  a.Publish(wire::channels::kStatus, junk, sizeof junk);
  for (int k = 0; k < 20 && raw == 0; ++k) mine.HandleSubscriptions(20);
  EXPECT_EQ(raw, 1);
  EXPECT_EQ(mine.other_session_dropped(), 10);
}

// docs/security.md "Sessions know each other": on a channel one process
// publishes, another pid of the same session is dropped while the
// publisher sends, and taken once it has been silent (a restart); RMS_STATUS
// takes every process.
TEST(SessionSenders, AnImpostorIsDroppedWhileThePublisherSendsAndARestartIsTaken) {
  transport::LcmOptions o;
  o.url = "udpm://239.255.76.67:" + std::to_string(7990 + getpid() % 40) + "?ttl=0";
  transport::UdpLcm real(o), impostor(o), restarted(o), rx(o);
  real.SetSender({0x1111, sender_t::PROCESS_OPERATOR_STATION, 4242});
  impostor.SetSender({0x1111, sender_t::PROCESS_OPERATOR_STATION, 9999});
  restarted.SetSender({0x1111, sender_t::PROCESS_OPERATOR_STATION, 4343});
  rx.SetSender({0x1111, sender_t::PROCESS_DYNAMICS, 1});
  std::vector<std::int32_t> inputs, statuses;
  rx.Subscribe(wire::channels::kOperatorInput, [&](const void* d, int n, std::int64_t) {
    operator_input_t m;
    if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone) inputs.push_back(m.sender.pid);
  });
  rx.Subscribe(wire::channels::kStatus, [&](const void* d, int n, std::int64_t) {
    process_status_t m;
    if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone) statuses.push_back(m.sender.pid);
  });
  auto drain = [&](std::size_t want) {
    for (int k = 0; k < 50 && inputs.size() < want; ++k) rx.HandleSubscriptions(20);
  };
  operator_input_t m{};
  process_status_t st{};
  st.process = "x";
  ASSERT_TRUE(transport::PublishMessage(real, wire::channels::kOperatorInput, m));
  drain(1);
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(transport::PublishMessage(impostor, wire::channels::kOperatorInput, m));
    ASSERT_TRUE(transport::PublishMessage(real, wire::channels::kOperatorInput, m));
    ASSERT_TRUE(transport::PublishMessage(impostor, wire::channels::kStatus, st));
  }
  drain(6);
  for (int k = 0; k < 5; ++k) rx.HandleSubscriptions(10);
  EXPECT_EQ(inputs, std::vector<std::int32_t>(6, 4242));
  EXPECT_EQ(rx.other_sender_dropped(), 5);
  EXPECT_EQ(statuses.size(), 5u);
  // The publisher falls silent (it ended); its restart is taken.
  std::this_thread::sleep_for(
      std::chrono::microseconds(transport::LcmInterface::kPublisherSilenceUs + 100000));
  ASSERT_TRUE(transport::PublishMessage(restarted, wire::channels::kOperatorInput, m));
  drain(7);
  ASSERT_EQ(inputs.size(), 7u);
  EXPECT_EQ(inputs.back(), 4343);
}

// docs/security.md "Authenticated messages": with the session's key, what
// a process sends ends in its tag, and a receiver takes only what carries
// a good one -- not a stranger's message with the session's id and the
// real pid, not a real message altered, not one of another channel; a real
// command recorded and sent again is dropped as a replay.
TEST(SessionSenders, WithTheSessionsKeyOnlyTaggedMessagesAreTakenAndACommandOnlyOnce) {
  transport::LcmOptions o;
  o.url = "udpm://239.255.76.67:" + std::to_string(8030 + getpid() % 40) + "?ttl=0";
  wire::SessionKey key, other;
  for (int i = 0; i < wire::kSessionKeyBytes; ++i) {
    key.bytes[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(i * 7 + 1);
    other.bytes[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(i * 7 + 2);
  }
  const std::int64_t before_rx_us = transport::WallTimeUs();
  transport::UdpLcm real(o), forger(o), control(o), rx(o);
  lcm::LCM raw(o.url);
  real.SetSender({0x1111, sender_t::PROCESS_OPERATOR_STATION, 4242});
  forger.SetSender({0x1111, sender_t::PROCESS_OPERATOR_STATION, 4242});  // the real pid
  control.SetSender({0x1111, sender_t::PROCESS_CONTROL, 77});
  rx.SetSender({0x1111, sender_t::PROCESS_DYNAMICS, 1});
  real.SetKey(key);
  control.SetKey(key);
  rx.SetKey(key);
  forger.SetKey(other);  // a key, not the session's
  std::vector<std::int64_t> frames, commands;
  std::vector<std::vector<std::uint8_t>> sent_control;
  rx.Subscribe(wire::channels::kOperatorInput, [&](const void* d, int n, std::int64_t) {
    operator_input_t m;
    if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone) frames.push_back(m.frame);
  });
  rx.Subscribe(wire::channels::kControl, [&](const void* d, int n, std::int64_t) {
    session_control_t m;
    if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone) commands.push_back(m.sequence);
  });
  // What the network carries of the real control messages, to send again.
  raw.subscribeFunction(
      wire::channels::kControl,
      +[](const lcm::ReceiveBuffer* b, const std::string&,
          std::vector<std::vector<std::uint8_t>>* v) {
        const auto* p = static_cast<const std::uint8_t*>(b->data);
        v->emplace_back(p, p + b->data_size);
      },
      &sent_control);
  auto pump = [&](auto done) {
    for (int k = 0; k < 100 && !done(); ++k) {
      rx.HandleSubscriptions(10);
      raw.handleTimeout(0);
    }
  };
  operator_input_t m{};
  m.frame = 1;
  ASSERT_TRUE(transport::PublishMessage(real, wire::channels::kOperatorInput, m));
  m.frame = 2;
  ASSERT_TRUE(transport::PublishMessage(forger, wire::channels::kOperatorInput, m));
  // Untagged, and tagged for another channel.
  transport::UdpLcm untagged(o);
  untagged.SetSender({0x1111, sender_t::PROCESS_OPERATOR_STATION, 4242});
  m.frame = 3;
  ASSERT_TRUE(transport::PublishMessage(untagged, wire::channels::kOperatorInput, m));
  {
    m.frame = 4;
    m.sender = {};
    m.sender.session_id = 0x1111;
    m.sender.process = sender_t::PROCESS_OPERATOR_STATION;
    m.sender.pid = 4242;
    std::vector<std::uint8_t> b = wire::EncodeMessage(m);
    const auto tag =
        wire::MessageMac(key, wire::channels::kStatus, b.data(), static_cast<int>(b.size()));
    b.insert(b.end(), tag.begin(), tag.end());
    raw.publish(wire::channels::kOperatorInput, b.data(), static_cast<unsigned>(b.size()));
    // A real message with one byte changed.
    m.frame = 5;
    b = wire::EncodeMessage(m);
    const auto good =
        wire::MessageMac(key, wire::channels::kOperatorInput, b.data(), static_cast<int>(b.size()));
    b.insert(b.end(), good.begin(), good.end());
    b[wire::kFrameAt + 7] ^= 0x01;
    raw.publish(wire::channels::kOperatorInput, b.data(), static_cast<unsigned>(b.size()));
  }
  m.frame = 6;
  ASSERT_TRUE(transport::PublishMessage(real, wire::channels::kOperatorInput, m));
  session_control_t c{};
  c.send_time_us = transport::WallTimeUs();
  c.sequence = 1;
  c.command = session_control_t::FREEZE;
  ASSERT_TRUE(transport::PublishMessage(control, wire::channels::kControl, c));
  pump([&] { return frames.size() >= 2 && commands.size() >= 1 && !sent_control.empty(); });
  EXPECT_EQ(frames, (std::vector<std::int64_t>{1, 6}));
  EXPECT_EQ(rx.bad_mac_dropped(), 4);
  ASSERT_EQ(commands, (std::vector<std::int64_t>{1}));
  ASSERT_EQ(sent_control.size(), 1u);
  // The recorded command, sent again as it was: a replay.
  raw.publish(wire::channels::kControl, sent_control[0].data(),
              static_cast<unsigned>(sent_control[0].size()));
  // A real command sent long ago (its tag good, its time 60 s old).
  c.send_time_us = transport::WallTimeUs() - 60'000'000;
  c.sequence = 2;
  ASSERT_TRUE(transport::PublishMessage(control, wire::channels::kControl, c));
  // A real command sent before the receiver began (a process restarted
  // after a crash has not seen the tags its predecessor took).
  c.send_time_us = before_rx_us - 1000;
  c.sequence = 3;
  ASSERT_TRUE(transport::PublishMessage(control, wire::channels::kControl, c));
  c.send_time_us = transport::WallTimeUs();
  c.sequence = 4;
  ASSERT_TRUE(transport::PublishMessage(control, wire::channels::kControl, c));
  pump([&] { return commands.size() >= 2 && rx.replayed_dropped() >= 3; });
  EXPECT_EQ(commands, (std::vector<std::int64_t>{1, 4}));
  EXPECT_EQ(rx.replayed_dropped(), 3);
}

TEST(UdpLcm, ABadUrlIsRefusedWithTheFix) {
  transport::LcmOptions o;
  o.url = "udpm://not-an-address:99999";
  try {
    transport::UdpLcm l(o);
    FAIL();
  } catch (const transport::TransportError& e) {
    EXPECT_NE(std::string(e.what()).find("ip route add 224.0.0.0/4 dev lo"), std::string::npos);
  }
}

}  // namespace
}  // namespace rms
