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
#include "rms/transport/lcm_interface.h"
#include "rms/wire/channels.h"
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
