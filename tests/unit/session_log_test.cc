// SessionLog reads a log as liblcm does (docs/sessions.md "The log"): the
// same events, in order, from clean logs and from damaged ones (garbage
// between events, a length out of range, a log cut short: each ends the
// log where liblcm ends it), and the same count of bytes at the end that
// are no whole event. liblcm's own reader is
// the oracle.
#include "rms/session/session_log.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <random>
#include <string>
#include <vector>

namespace rms::session {
namespace {

namespace fs = std::filesystem;

struct Event {
  std::int64_t t = 0;
  std::string channel;
  std::string data;
  bool operator==(const Event&) const = default;
};

void PutBig(std::string* out, std::uint64_t v, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

// One event in the LCM log format, with the lengths given (possibly wrong).
std::string EventBytes(std::int64_t n, const Event& e, std::int32_t channel_len,
                       std::int32_t data_len) {
  std::string b;
  PutBig(&b, 0xEDA1DA01u, 4);
  PutBig(&b, static_cast<std::uint64_t>(n), 8);
  PutBig(&b, static_cast<std::uint64_t>(e.t), 8);
  PutBig(&b, static_cast<std::uint32_t>(channel_len), 4);
  PutBig(&b, static_cast<std::uint32_t>(data_len), 4);
  return b + e.channel + e.data;
}

// liblcm's reading: the events, and where the last whole one ends.
std::vector<Event> ReadWithLiblcm(const std::string& path, long* good_end) {
  std::vector<Event> out;
  lcm::LogFile log(path, "r");
  *good_end = 0;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    *good_end = std::ftell(log.getFilePtr());
    out.push_back(
        {ev->timestamp, ev->channel, std::string(static_cast<const char*>(ev->data), ev->datalen)});
  }
  return out;
}

enum class Damage {
  kNone,
  kGarbageFirst,
  kTwoBytesAfter,
  kGarbageBetween,
  kCutShort,
  kBadChannelLength,
  kNegativeDataLength
};

class SessionLogRead : public ::testing::TestWithParam<Damage> {};

TEST_P(SessionLogRead, GivesLiblcmsEventsAndUnreadBytes) {
  const std::uint64_t seed = 1000 + static_cast<int>(GetParam());
  std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
  std::mt19937_64 rng(seed);
  const fs::path dir =
      fs::temp_directory_path() /
      ("rms_session_log_test_" + std::to_string(::getpid()) + "_" + std::to_string(seed));
  fs::create_directories(dir);
  std::string bytes;
  const char* channels[] = {"RMS_DCP_FRAME", "RMS_ESG_FRAME", "RMS_OPERATOR_INPUT", "X"};
  std::uniform_int_distribution<int> size(0, 3000), pick(0, 3), byte(0, 255);
  if (GetParam() == Damage::kGarbageFirst)
    bytes = "\x12\xED\xA1\xDA garbage before the first event";
  for (int n = 0; n < 300; ++n) {
    Event e{1'700'000'000'000'000 + n * 33'333, channels[pick(rng)], ""};
    for (int k = size(rng); k > 0; --k) e.data.push_back(static_cast<char>(byte(rng)));
    if (n == 150) e.data.append(100'000, 'x');  // larger than the reader's buffer
    const auto c = static_cast<std::int32_t>(e.channel.size());
    const auto d = static_cast<std::int32_t>(e.data.size());
    if (GetParam() == Damage::kGarbageBetween && n % 7 == 3) {
      for (int k = size(rng) % 50; k > 0; --k) bytes.push_back(static_cast<char>(byte(rng)));
    }
    if (GetParam() == Damage::kBadChannelLength && n == 200) {
      bytes += EventBytes(n, e, 1000, d);
    } else if (GetParam() == Damage::kNegativeDataLength && n == 200) {
      bytes += EventBytes(n, e, c, -5);
    } else {
      bytes += EventBytes(n, e, c, d);
    }
  }
  if (GetParam() == Damage::kCutShort) bytes.resize(bytes.size() - 1234);
  if (GetParam() == Damage::kTwoBytesAfter) bytes += "\xED\xA1";  // less than a sync word
  const std::string path = (dir / "lcmlog").string();
  std::ofstream(path, std::ios::binary) << bytes;

  long good_end = 0;
  const std::vector<Event> expected = ReadWithLiblcm(path, &good_end);
  SessionLog log(dir.string());
  std::vector<Event> got;
  log.Read({}, [&](const LogMessage& m) {
    got.push_back(
        {m.log_us, std::string(m.channel), std::string(static_cast<const char*>(m.data), m.size)});
  });
  EXPECT_EQ(got.size(), expected.size());
  EXPECT_TRUE(got == expected);
  EXPECT_EQ(log.events(), static_cast<std::int64_t>(expected.size()));
  EXPECT_EQ(log.unread_bytes(), static_cast<std::int64_t>(bytes.size()) - good_end);
  if (GetParam() == Damage::kNone || GetParam() == Damage::kGarbageFirst ||
      GetParam() == Damage::kTwoBytesAfter) {
    EXPECT_EQ(got.size(), 300u);
    EXPECT_EQ(log.unread_bytes(), 0);  // liblcm reads past up to three bytes after the last event
  } else {
    EXPECT_LT(got.size(), 300u);
    EXPECT_GT(log.unread_bytes(), 0);
  }
  // Only the channels asked for (and, whatever is asked, nothing else).
  int frames = 0;
  log.Read({"RMS_DCP_FRAME"}, [&](const LogMessage& m) {
    EXPECT_EQ(m.base, "RMS_DCP_FRAME");
    ++frames;
  });
  int expected_frames = 0;
  for (const Event& e : expected) expected_frames += e.channel == "RMS_DCP_FRAME";
  EXPECT_EQ(frames, expected_frames);
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Damages, SessionLogRead,
                         ::testing::Values(Damage::kNone, Damage::kGarbageFirst,
                                           Damage::kTwoBytesAfter, Damage::kGarbageBetween,
                                           Damage::kCutShort, Damage::kBadChannelLength,
                                           Damage::kNegativeDataLength));

TEST(SessionLogRead, AnEmptyLogHasNoEventsAndAMissingOneIsRefusedByName) {
  const fs::path dir =
      fs::temp_directory_path() / ("rms_session_log_empty_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "lcmlog").close();
  SessionLog log(dir.string());
  int n = 0;
  log.Read({}, [&](const LogMessage&) { ++n; });
  EXPECT_EQ(n, 0);
  EXPECT_EQ(log.unread_bytes(), 0);
  fs::remove(dir / "lcmlog");
  try {
    SessionLog gone(dir.string());
    ADD_FAILURE() << "a folder without lcmlog was taken";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("lcmlog"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rms::session
