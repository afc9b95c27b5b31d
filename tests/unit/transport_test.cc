// The transport interface: the log-backed implementation is deterministic and
// network-free (the UDP one: tests/network/udp_lcm_test.cc); SafeDecode classifies
// hostile bytes without throwing.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <iostream>
#include <lcm/lcm-cpp.hpp>
#include <random>
#include <sys/stat.h>
#include <thread>

#include "rms/base/check.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_state_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/operator_input_t.hpp"
#include "rms/operator_state_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/sender_t.hpp"
#include "rms/session_control_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/window_keys_t.hpp"
#include "rms/wire/channels.h"
#include "rms/wire/message_auth.h"
#include "rms/wire/message_io.h"

namespace rms {
namespace {

std::string TempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("rmslab_" + std::to_string(getpid()) + "_" + name))
      .string();
}

// docs/security.md "Authenticated messages": a tag depends on every byte,
// the channel and the key.
TEST(MessageAuth, ATagChangesWithEveryByteTheChannelAndTheKey) {
  wire::SessionKey key;
  for (int i = 0; i < wire::kSessionKeyBytes; ++i) key.bytes[static_cast<std::size_t>(i)] = 3 * i;
  std::vector<std::uint8_t> msg(120);
  for (std::size_t i = 0; i < msg.size(); ++i) msg[i] = static_cast<std::uint8_t>(i);
  const int n = static_cast<int>(msg.size());
  const auto tag = wire::MessageMac(key, "RMS_DCP_FRAME", msg.data(), n);
  std::vector<std::uint8_t> tagged = msg;
  tagged.insert(tagged.end(), tag.begin(), tag.end());
  EXPECT_TRUE(wire::VerifyMessageMac(key, "RMS_DCP_FRAME", tagged.data(), n + wire::kMacBytes));
  EXPECT_FALSE(wire::VerifyMessageMac(key, "RMS_DCP_FRAME_B", tagged.data(), n + wire::kMacBytes));
  EXPECT_FALSE(wire::VerifyMessageMac(key, "RMS_DCP_FRAME", tagged.data(), n));
  EXPECT_FALSE(wire::VerifyMessageMac(key, "RMS_DCP_FRAME", tagged.data(), 3));
  for (std::size_t i = 0; i < tagged.size(); ++i) {
    std::vector<std::uint8_t> bad = tagged;
    bad[i] ^= 0x40;
    EXPECT_FALSE(wire::VerifyMessageMac(key, "RMS_DCP_FRAME", bad.data(), n + wire::kMacBytes))
        << "byte " << i;
  }
  wire::SessionKey other = key;
  other.bytes[31] ^= 1;
  EXPECT_FALSE(wire::VerifyMessageMac(other, "RMS_DCP_FRAME", tagged.data(), n + wire::kMacBytes));
}

// Every message type of the session is one the session filter and the
// tags apply to (an RMS_DCP_STATE left out took other sessions' states and
// kept its tag on: docs/protocol.md "Senders").
TEST(MessageAuth, EverySessionMessageTypeIsKnownAsTheSessions) {
  for (const std::int64_t fp :
       {operator_input_t::getHash(), dcp_frame_t::getHash(), dcp_state_t::getHash(),
        dcp_telemetry_t::getHash(), esg_frame_t::getHash(), operator_state_t::getHash(),
        process_status_t::getHash(), session_control_t::getHash(), window_keys_t::getHash()})
    EXPECT_TRUE(wire::IsRmslabFingerprint(fp)) << fp;
  EXPECT_FALSE(wire::IsRmslabFingerprint(0x1234));
}

// The key file: 64 hex digits, its owner's only, no link followed; each
// refusal names the file and what is wrong.
TEST(MessageAuth, AKeyFileIsReadOnlyWhenItIsTheOwnersAloneAndWellFormed) {
  const std::string dir = TempPath("keys");
  std::filesystem::create_directories(dir);
  auto write = [&](const std::string& name, const std::string& text, mode_t mode) {
    std::string p = dir + "/" + name;
    { std::ofstream(p) << text; }
    chmod(p.c_str(), mode);
    return p;
  };
  const std::string hex(64, 'a');
  const wire::SessionKey k = wire::ReadSessionKeyFile(write("good", hex + "\n", 0600));
  EXPECT_EQ(k.bytes[0], 0xaa);
  EXPECT_EQ(k.bytes[31], 0xaa);
  auto refused = [&](const std::string& path, const std::string& says) {
    try {
      (void)wire::ReadSessionKeyFile(path);
      ADD_FAILURE() << path << " taken";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  };
  refused(write("open", hex + "\n", 0644), "readable or writable by others");
  refused(write("short", hex.substr(2) + "\n", 0600), "not 64 hex digits");
  refused(write("nothex", std::string(63, 'a') + "g\n", 0600), "not 64 hex digits");
  refused(dir + "/missing", "cannot be opened");
  std::filesystem::create_symlink(dir + "/good", dir + "/link");
  refused(dir + "/link", "a link is not followed");
  refused(dir, "not a regular file");
  std::filesystem::remove_all(dir);
}

TEST(LogLcm, RecordsAndReplaysInOrderWithTimestampsAndSuffix) {
  const std::string path = TempPath("a.lcmlog");
  {
    transport::LogLcm out("", path, "_BAY2");
    for (int i = 0; i < 5; ++i) {
      out.SetNowUs(1000 + i * 33333);
      operator_input_t m{};
      m.frame = i;
      ASSERT_TRUE(transport::PublishMessage(out, wire::channels::kOperatorInput, m));
    }
  }
  {
    lcm::LogFile raw(path, "r");
    const lcm::LogEvent* ev = raw.readNextEvent();
    ASSERT_NE(ev, nullptr);
    EXPECT_EQ(ev->channel, "RMS_OPERATOR_INPUT_BAY2");
    EXPECT_EQ(ev->timestamp, 1000);
  }
  transport::LogLcm in(path, "", "_BAY2");
  std::vector<std::pair<std::int64_t, std::int64_t>> got;  // frame, time
  in.Subscribe(wire::channels::kOperatorInput, [&](const void* d, int n, std::int64_t t) {
    operator_input_t m;
    ASSERT_EQ(wire::SafeDecode(d, n, &m), wire::DecodeError::kNone);
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
  transport::LogLcm lcm("", "");
  int n = 0;
  lcm.Subscribe(wire::channels::kStatus, [&](const void*, int, std::int64_t) { ++n; });
  const char bytes[3] = {1, 2, 3};
  lcm.Publish(wire::channels::kStatus, bytes, 3);
  lcm.Publish(wire::channels::kEsgFrame, bytes, 3);
  EXPECT_EQ(lcm.HandleSubscriptions(0), 2);
  EXPECT_EQ(n, 1);
}

TEST(ChannelSuffix, OnlyLettersDigitsAndUnderscore) {
  EXPECT_NO_THROW(transport::ValidateChannelSuffix("_BAY_2"));
  EXPECT_THROW(transport::ValidateChannelSuffix("_B.*"), InputError);
  EXPECT_THROW(transport::ValidateChannelSuffix("a b"), InputError);
}

TEST(SessionId, ParsedFromDecimalOrHexAndMalformedOnesAreRefused) {
  EXPECT_EQ(transport::ParseSessionId("0x00000000000000ff", "x"), 255);
  EXPECT_EQ(transport::ParseSessionId("12", "x"), 12);
  EXPECT_EQ(transport::ParseSessionId(wire::FormatSessionId(-2), "x"), -2);
  EXPECT_THROW(transport::ParseSessionId("0x", "x"), InputError);
  EXPECT_THROW(transport::ParseSessionId("12a", "x"), InputError);
  EXPECT_THROW(transport::ParseSessionId("0x1234567890abcdef0", "x"), InputError);
}

TEST(SafeDecode, ClassifiesHostileBytesWithoutThrowing) {
  esg_frame_t m{};
  m.num_words = 3;
  m.words = {1, 2, 3};
  std::vector<std::uint8_t> good = wire::EncodeMessage(m);
  esg_frame_t out;
  EXPECT_EQ(wire::SafeDecode(good.data(), static_cast<int>(good.size()), &out),
            wire::DecodeError::kNone);
  // Wrong type: an operator input block on the ESG channel.
  operator_input_t other{};
  std::vector<std::uint8_t> o = wire::EncodeMessage(other);
  EXPECT_EQ(wire::SafeDecode(o.data(), static_cast<int>(o.size()), &out),
            wire::DecodeError::kWrongType);
  // Truncated.
  EXPECT_EQ(wire::SafeDecode(good.data(), static_cast<int>(good.size()) - 1, &out),
            wire::DecodeError::kTruncated);
  EXPECT_EQ(wire::SafeDecode(good.data(), 4, &out), wire::DecodeError::kTruncated);
  // Trailing bytes.
  std::vector<std::uint8_t> longer = good;
  longer.push_back(0);
  EXPECT_EQ(wire::SafeDecode(longer.data(), static_cast<int>(longer.size()), &out),
            wire::DecodeError::kTrailingBytes);
  // Too large: beyond the type's largest encoding (64 words, from
  // esg_frame_t.lcm's MAX_WORDS), refused before decoding.
  EXPECT_EQ(lcm_limits::kMaxEncodedSize<esg_frame_t>, 8 + wire::kSenderBytes + 40 + 2 + 4 * 64);
  esg_frame_t big{};
  big.num_words = 65;
  big.words.assign(65, 0);
  std::vector<std::uint8_t> b = wire::EncodeMessage(big);
  EXPECT_EQ(wire::SafeDecode(b.data(), static_cast<int>(b.size()), &out),
            wire::DecodeError::kTooLarge);
  // Within the size limit but beyond a count's bound: a status report with
  // more counters than MAX_COUNTERS, each name empty.
  process_status_t many{};
  many.num_counters = process_status_t::MAX_COUNTERS + 1;
  many.counter_names.assign(many.num_counters, "");
  many.counter_values.assign(many.num_counters, 0);
  std::vector<std::uint8_t> mb = wire::EncodeMessage(many);
  ASSERT_LE(static_cast<int>(mb.size()), lcm_limits::kMaxEncodedSize<process_status_t>);
  process_status_t many_out;
  EXPECT_EQ(wire::SafeDecode(mb.data(), static_cast<int>(mb.size()), &many_out),
            wire::DecodeError::kBadCount);
  // The same at its bound decodes.
  many.num_counters = process_status_t::MAX_COUNTERS;
  many.counter_names.resize(many.num_counters);
  many.counter_values.resize(many.num_counters);
  mb = wire::EncodeMessage(many);
  EXPECT_EQ(wire::SafeDecode(mb.data(), static_cast<int>(mb.size()), &many_out),
            wire::DecodeError::kNone);
  // A negative word count (int16 after the fingerprint, the sender and five
  // int64s) makes lcm-gen's decoder throw.
  constexpr int kCountAt = 8 + wire::kSenderBytes + 40;
  std::vector<std::uint8_t> neg = good;
  neg[kCountAt] = 0xFF;
  neg[kCountAt + 1] = 0xFE;
  EXPECT_EQ(wire::SafeDecode(neg.data(), static_cast<int>(neg.size()), &out),
            wire::DecodeError::kBadCount);
  // A string length of zero in a status report.
  process_status_t s{};
  s.process = "x";
  std::vector<std::uint8_t> sb = wire::EncodeMessage(s);
  sb[8 + wire::kSenderBytes + 8 + 3] =
      0;  // length of "process" (4-byte big-endian after the sender and send_time_us) -> 0
  process_status_t so;
  const wire::DecodeError e = wire::SafeDecode(sb.data(), static_cast<int>(sb.size()), &so);
  EXPECT_NE(e, wire::DecodeError::kNone);
}

// The frame number and the send time sit where wire::kFrameAt and
// wire::kSendTimeAt say, in each type that has them there.
template <class Msg>
void ExpectFrameAndSendTimeAt() {
  Msg m{};
  m.frame = 0x0102030405060708;
  m.send_time_us = 0x1112131415161718;
  const std::vector<std::uint8_t> b = wire::EncodeMessage(m);
  std::int64_t frame = 0;
  ASSERT_TRUE(wire::ReadFrameNumber(b.data(), static_cast<int>(b.size()), &frame));
  EXPECT_EQ(frame, m.frame);
  std::int64_t t = 0;
  ASSERT_TRUE(wire::ReadInt64At(b.data(), static_cast<int>(b.size()), wire::kSendTimeAt, &t));
  EXPECT_EQ(t, m.send_time_us);
  EXPECT_FALSE(wire::ReadFrameNumber(b.data(), wire::kFrameAt + 7, &frame));
}

TEST(ReadFrameNumber, TheFrameAndSendTimeFollowTheSender) {
  ExpectFrameAndSendTimeAt<operator_input_t>();
  ExpectFrameAndSendTimeAt<dcp_frame_t>();
  ExpectFrameAndSendTimeAt<dcp_telemetry_t>();
  dcp_frame_t m{};
  m.input_frame = -0x0102030405060708;
  const std::vector<std::uint8_t> b = wire::EncodeMessage(m);
  std::int64_t input_frame = 0;
  ASSERT_TRUE(wire::ReadInt64At(b.data(), static_cast<int>(b.size()), wire::kDcpFrameInputFrameAt,
                                &input_frame));
  EXPECT_EQ(input_frame, m.input_frame);
  EXPECT_FALSE(wire::ReadInt64At(b.data(), wire::kDcpFrameInputFrameAt + 7,
                                 wire::kDcpFrameInputFrameAt, &input_frame));
}

// CheckEncoded says of a fixed-size type's raw bytes what SafeDecode says,
// on random sizes around the type's, its fingerprint or another, random
// contents.
template <class Msg>
void ExpectCheckEncodedIsSafeDecode(std::mt19937* rng) {
  constexpr int kSize = lcm_limits::kMaxEncodedSize<Msg>;
  std::uniform_int_distribution<int> size(0, kSize + 16), byte(0, 255), coin(0, 3);
  int valid = 0;
  for (int i = 0; i < 20000; ++i) {
    const int n = coin(*rng) == 0 ? kSize : size(*rng);
    std::vector<std::uint8_t> b(static_cast<std::size_t>(n) + 1);
    for (auto& x : b) x = static_cast<std::uint8_t>(byte(*rng));
    if (coin(*rng) != 0) {
      const auto h = static_cast<std::uint64_t>(Msg::getHash());
      for (int k = 0; k < 8 && k < n; ++k)
        b[static_cast<std::size_t>(k)] = (h >> (56 - 8 * k)) & 0xFF;
    }
    Msg m;
    const wire::DecodeError want = wire::SafeDecode(b.data(), n, &m);
    ASSERT_EQ(wire::CheckEncoded<Msg>(b.data(), n), want) << "size " << n << ", try " << i;
    valid += want == wire::DecodeError::kNone;
  }
  EXPECT_GT(valid, 1000);
}

TEST(CheckEncoded, SaysOfFixedSizeMessagesWhatSafeDecodeSays) {
  static_assert(lcm_limits::Bounds<dcp_frame_t>::kFixedSize);
  static_assert(lcm_limits::Bounds<dcp_telemetry_t>::kFixedSize);
  static_assert(!lcm_limits::Bounds<esg_frame_t>::kFixedSize);       // a count of words
  static_assert(!lcm_limits::Bounds<process_status_t>::kFixedSize);  // strings
  constexpr unsigned kSeed = 19721122;
  std::cout << "seed " << kSeed << "\n";
  std::mt19937 rng(kSeed);
  ExpectCheckEncodedIsSafeDecode<dcp_frame_t>(&rng);
  ExpectCheckEncodedIsSafeDecode<dcp_telemetry_t>(&rng);
}

}  // namespace
}  // namespace rms
