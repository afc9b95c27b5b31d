// The transport interface: the log-backed implementation is deterministic and
// network-free; the UDP one is real LCM on loopback; SafeDecode classifies
// hostile bytes without throwing.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <thread>
#include <unistd.h>

#include "rms/channels.h"
#include "rms/check.h"
#include "rms/esg_frame_t.hpp"
#include "rms/lcm_interface.h"
#include "rms/message_io.h"
#include "rms/operator_input_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/sender_t.hpp"

namespace rms {
namespace {

std::string TempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("rmslab_" + std::to_string(getpid()) + "_" + name)).string();
}

TEST(LogLcm, RecordsAndReplaysInOrderWithTimestampsAndSuffix) {
  const std::string path = TempPath("a.lcmlog");
  {
    LogLcm out("", path, "_BAY2");
    for (int i = 0; i < 5; ++i) {
      out.SetNowUs(1000 + i * 33333);
      operator_input_t m{};
      m.frame = i;
      ASSERT_TRUE(PublishMessage(out, channels::kOperatorInput, m));
    }
  }
  {
    lcm::LogFile raw(path, "r");
    const lcm::LogEvent* ev = raw.readNextEvent();
    ASSERT_NE(ev, nullptr);
    EXPECT_EQ(ev->channel, "RMS_OPERATOR_INPUT_BAY2");
    EXPECT_EQ(ev->timestamp, 1000);
  }
  LogLcm in(path, "", "_BAY2");
  std::vector<std::pair<std::int64_t, std::int64_t>> got;  // frame, time
  in.Subscribe(channels::kOperatorInput, [&](const void* d, int n, std::int64_t t) {
    operator_input_t m;
    ASSERT_EQ(SafeDecode(d, n, 1000, &m), DecodeError::kNone);
    got.emplace_back(m.frame, t);
  });
  while (in.HandleSubscriptions(0) > 0) {
  }
  EXPECT_TRUE(in.at_end());
  ASSERT_EQ(got.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(got[i].first, i);
    EXPECT_EQ(got[i].second, 1000 + i * 33333);
  }
  std::filesystem::remove(path);
}

TEST(LogLcm, PublishedMessagesReachLocalSubscribersLikeMulticastLoopback) {
  LogLcm lcm("", "");
  int n = 0;
  lcm.Subscribe(channels::kStatus, [&](const void*, int, std::int64_t) { ++n; });
  const char bytes[3] = {1, 2, 3};
  lcm.Publish(channels::kStatus, bytes, 3);
  lcm.Publish(channels::kEsgFrame, bytes, 3);
  EXPECT_EQ(lcm.HandleSubscriptions(0), 2);
  EXPECT_EQ(n, 1);
}

TEST(ChannelSuffix, OnlyLettersDigitsAndUnderscore) {
  EXPECT_NO_THROW(ValidateChannelSuffix("_BAY_2"));
  EXPECT_THROW(ValidateChannelSuffix("_B.*"), InputError);
  EXPECT_THROW(ValidateChannelSuffix("a b"), InputError);
}

TEST(UdpLcm, RealMulticastOnLoopbackDeliversToASecondInstance) {
  LcmOptions o;
  o.url = "udpm://239.255.76.67:" + std::to_string(7800 + getpid() % 150) + "?ttl=0";
  o.channel_suffix = "_T";
  UdpLcm a(o), b(o);
  std::vector<std::int64_t> frames;
  b.Subscribe(channels::kOperatorInput, [&](const void* d, int n, std::int64_t) {
    operator_input_t m;
    if (SafeDecode(d, n, 1000, &m) == DecodeError::kNone) frames.push_back(m.frame);
  });
  for (int i = 0; i < 50; ++i) {
    operator_input_t m{};
    m.frame = i;
    ASSERT_TRUE(PublishMessage(a, channels::kOperatorInput, m));
  }
  for (int k = 0; k < 50 && frames.size() < 50; ++k) b.HandleSubscriptions(20);
  ASSERT_EQ(frames.size(), 50u);
  for (int i = 0; i < 50; ++i) EXPECT_EQ(frames[i], i);
}

// Every message carries its sender (docs/protocol.md "Senders"); a process
// of a session takes only its own session's messages and counts the others;
// one of no session takes all.
TEST(UdpLcm, MessagesAreStampedWithTheirSenderAndOtherSessionsAreDropped) {
  LcmOptions o;
  o.url = "udpm://239.255.76.67:" + std::to_string(7950 + getpid() % 40) + "?ttl=0";
  o.channel_suffix = "_SID";
  UdpLcm a(o), b(o), mine(o), none(o);
  a.SetSender({0x1111, sender_t::PROCESS_OPERATOR_STATION, 4242});
  b.SetSender({0x2222, sender_t::PROCESS_OPERATOR_STATION, 4343});
  mine.SetSender({0x1111, sender_t::PROCESS_DYNAMICS, 1});
  std::vector<sender_t> got_mine, got_none;
  auto collect = [](std::vector<sender_t>* into) {
    return [into](const void* d, int n, std::int64_t) {
      operator_input_t m;
      if (SafeDecode(d, n, 1000, &m) == DecodeError::kNone) into->push_back(m.sender);
    };
  };
  mine.Subscribe(channels::kOperatorInput, collect(&got_mine));
  none.Subscribe(channels::kOperatorInput, collect(&got_none));
  for (int i = 0; i < 10; ++i) {
    operator_input_t m{};
    m.frame = i;
    m.sender.session_id = 0x7777;  // whatever the caller left there, the transport's sender goes out
    ASSERT_TRUE(PublishMessage(a, channels::kOperatorInput, m));
    ASSERT_TRUE(PublishMessage(b, channels::kOperatorInput, m));
  }
  for (int k = 0; k < 50 && (got_mine.size() < 10 || got_none.size() < 20); ++k) {
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
  a.Publish(channels::kOperatorInput, junk, sizeof junk);
  int raw = 0;
  mine.Subscribe(channels::kStatus, [&](const void*, int, std::int64_t) { ++raw; });
  a.Publish(channels::kStatus, junk, sizeof junk);
  for (int k = 0; k < 20 && raw == 0; ++k) mine.HandleSubscriptions(20);
  EXPECT_EQ(raw, 1);
  EXPECT_EQ(mine.other_session_dropped(), 10);
}

// docs/security.md "One publisher a channel": on a channel one process
// publishes, another pid of the same session is dropped while the
// publisher sends, and taken once it has been silent (a restart); RMS_STATUS
// takes every process.
TEST(SessionSenders, AnImpostorIsDroppedWhileThePublisherSendsAndARestartIsTaken) {
  LcmOptions o;
  o.url = "udpm://239.255.76.67:" + std::to_string(7990 + getpid() % 40) + "?ttl=0";
  UdpLcm real(o), impostor(o), restarted(o), rx(o);
  real.SetSender({0x1111, sender_t::PROCESS_OPERATOR_STATION, 4242});
  impostor.SetSender({0x1111, sender_t::PROCESS_OPERATOR_STATION, 9999});
  restarted.SetSender({0x1111, sender_t::PROCESS_OPERATOR_STATION, 4343});
  rx.SetSender({0x1111, sender_t::PROCESS_DYNAMICS, 1});
  std::vector<std::int32_t> inputs, statuses;
  rx.Subscribe(channels::kOperatorInput, [&](const void* d, int n, std::int64_t) {
    operator_input_t m;
    if (SafeDecode(d, n, 1000, &m) == DecodeError::kNone) inputs.push_back(m.sender.pid);
  });
  rx.Subscribe(channels::kStatus, [&](const void* d, int n, std::int64_t) {
    process_status_t m;
    if (SafeDecode(d, n, 1 << 20, &m) == DecodeError::kNone) statuses.push_back(m.sender.pid);
  });
  auto drain = [&](std::size_t want) {
    for (int k = 0; k < 50 && inputs.size() < want; ++k) rx.HandleSubscriptions(20);
  };
  operator_input_t m{};
  process_status_t st{};
  st.process = "x";
  ASSERT_TRUE(PublishMessage(real, channels::kOperatorInput, m));
  drain(1);
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(PublishMessage(impostor, channels::kOperatorInput, m));
    ASSERT_TRUE(PublishMessage(real, channels::kOperatorInput, m));
    ASSERT_TRUE(PublishMessage(impostor, channels::kStatus, st));
  }
  drain(6);
  for (int k = 0; k < 5; ++k) rx.HandleSubscriptions(10);
  EXPECT_EQ(inputs, std::vector<std::int32_t>(6, 4242));
  EXPECT_EQ(rx.other_sender_dropped(), 5);
  EXPECT_EQ(statuses.size(), 5u);
  // The publisher falls silent (it ended); its restart is taken.
  std::this_thread::sleep_for(std::chrono::microseconds(LcmInterface::kPublisherSilenceUs + 100000));
  ASSERT_TRUE(PublishMessage(restarted, channels::kOperatorInput, m));
  drain(7);
  ASSERT_EQ(inputs.size(), 7u);
  EXPECT_EQ(inputs.back(), 4343);
}

TEST(SessionId, ParsedFromDecimalOrHexAndMalformedOnesAreRefused) {
  EXPECT_EQ(ParseSessionId("0x00000000000000ff", "x"), 255);
  EXPECT_EQ(ParseSessionId("12", "x"), 12);
  EXPECT_EQ(ParseSessionId(FormatSessionId(-2), "x"), -2);
  EXPECT_THROW(ParseSessionId("0x", "x"), InputError);
  EXPECT_THROW(ParseSessionId("12a", "x"), InputError);
  EXPECT_THROW(ParseSessionId("0x1234567890abcdef0", "x"), InputError);
}

TEST(UdpLcm, ABadUrlIsRefusedWithTheFix) {
  LcmOptions o;
  o.url = "udpm://not-an-address:99999";
  try {
    UdpLcm l(o);
    FAIL();
  } catch (const TransportError& e) {
    EXPECT_NE(std::string(e.what()).find("ip route add 224.0.0.0/4 dev lo"), std::string::npos);
  }
}

TEST(SafeDecode, ClassifiesHostileBytesWithoutThrowing) {
  esg_frame_t m{};
  m.num_words = 3;
  m.words = {1, 2, 3};
  std::vector<std::uint8_t> good = EncodeMessage(m);
  esg_frame_t out;
  EXPECT_EQ(SafeDecode(good.data(), static_cast<int>(good.size()), 400, &out), DecodeError::kNone);
  // Wrong type: an operator input block on the ESG channel.
  operator_input_t other{};
  std::vector<std::uint8_t> o = EncodeMessage(other);
  EXPECT_EQ(SafeDecode(o.data(), static_cast<int>(o.size()), 400, &out), DecodeError::kWrongType);
  // Truncated.
  EXPECT_EQ(SafeDecode(good.data(), static_cast<int>(good.size()) - 1, 400, &out), DecodeError::kTruncated);
  EXPECT_EQ(SafeDecode(good.data(), 4, 400, &out), DecodeError::kTruncated);
  // Trailing bytes.
  std::vector<std::uint8_t> longer = good;
  longer.push_back(0);
  EXPECT_EQ(SafeDecode(longer.data(), static_cast<int>(longer.size()), 400, &out), DecodeError::kTrailingBytes);
  // Too large.
  EXPECT_EQ(SafeDecode(good.data(), static_cast<int>(good.size()), 10, &out), DecodeError::kTooLarge);
  // A negative word count (int16 after the fingerprint, the sender and five
  // int64s) makes lcm-gen's decoder throw.
  constexpr int kCountAt = 8 + kSenderBytes + 40;
  std::vector<std::uint8_t> neg = good;
  neg[kCountAt] = 0xFF;
  neg[kCountAt + 1] = 0xFE;
  EXPECT_EQ(SafeDecode(neg.data(), static_cast<int>(neg.size()), 400, &out), DecodeError::kBadCount);
  // A string length of zero in a status report.
  process_status_t s{};
  s.process = "x";
  std::vector<std::uint8_t> sb = EncodeMessage(s);
  sb[8 + kSenderBytes + 8 + 3] = 0;  // length of "process" (4-byte big-endian after the sender and send_time_us) -> 0
  process_status_t so;
  const DecodeError e = SafeDecode(sb.data(), static_cast<int>(sb.size()), 4000, &so);
  EXPECT_NE(e, DecodeError::kNone);
}

}  // namespace
}  // namespace rms
