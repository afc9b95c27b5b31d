// SessionLog reads a log as docs/sessions.md "The log" says: liblcm's
// events from a clean log (liblcm's own reader the oracle), and from a
// damaged one (garbage between events, a length out of range, a log cut
// short) every event a byte-by-byte reading of the documented rule finds,
// reading past the damage where liblcm ends the log; the bytes passed over
// and those at the end that are no whole event counted as that reading
// counts them.
#include "rms/session/session_log.h"

#include <algorithm>
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

// The documented reading, byte by byte: at each place, a sync word whose
// lengths are in range (channel 1..999, data 0..64 MiB) and whose event
// fits in the file is an event, taken, and the next place is its end;
// anything else is passed over a byte at a time. *skipped: the bytes passed
// over before and between events; *good_end: where the last event ends,
// or the file's end when fewer than four bytes follow it.
std::vector<Event> ReadAsDocumented(const std::string& b, long* good_end, long* skipped) {
  auto big = [&](std::size_t at, int n) {
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v = (v << 8) | static_cast<unsigned char>(b[at + i]);
    return v;
  };
  std::vector<Event> out;
  std::size_t p = 0, end = 0;
  *skipped = 0;
  while (p + 28 <= b.size()) {
    const auto c = static_cast<std::int32_t>(big(p + 20, 4));
    const auto d = static_cast<std::int32_t>(big(p + 24, 4));
    const bool whole = big(p, 4) == 0xEDA1DA01u && c > 0 && c < 1000 && d >= 0 && d <= (64 << 20) &&
                       p + 28 + c + d <= b.size();
    if (!whole) {
      ++p;
      continue;
    }
    *skipped += static_cast<long>(p - end);
    out.push_back(
        {static_cast<std::int64_t>(big(p + 12, 8)), b.substr(p + 28, c), b.substr(p + 28 + c, d)});
    p += 28 + c + d;
    end = b.size() - p < 4 ? b.size() : p;
  }
  *good_end = static_cast<long>(end);
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

constexpr int kEvents = 800;  // about 1.3 MB: past ReadInTwo's 1 MiB

// ReadInTwo, cut at shares of the log, at events' starts and just before
// sync words inside events' data, on another core that always takes its
// part: part 0 and then, when it stands, part 1 are the expected events, and
// the events, skipped and unread bytes counted are as one reading's. A cut at an event's
// start of an undamaged log stands; one before a false sync word never.
void ExpectReadInTwoReadsAsOne(const std::string& dir, std::size_t size,
                               const std::vector<Event>& expected, long good_end, long skipped,
                               const std::vector<std::size_t>& event_starts,
                               const std::vector<std::size_t>& false_syncs, bool undamaged) {
  struct Cut {
    double share;
    int stands;  // 1 must, 0 must not, -1 either
  };
  std::vector<Cut> cuts = {{0.5, -1}, {0.3, -1}, {0.77, -1}};
  auto share_cutting_at = [&](std::size_t at) {  // the middle lands at `at`
    return 1.0 - (static_cast<double>(at) + 0.5) / static_cast<double>(size);
  };
  for (const double f : {0.35, 0.5, 0.65}) {
    const auto near = static_cast<std::size_t>(f * static_cast<double>(size));
    const auto e = std::lower_bound(event_starts.begin(), event_starts.end(), near);
    if (e != event_starts.end()) cuts.push_back({share_cutting_at(*e), undamaged ? 1 : -1});
    const auto s = std::lower_bound(false_syncs.begin(), false_syncs.end(), near);
    if (s != false_syncs.end()) cuts.push_back({share_cutting_at(*s - 2), 0});
  }
  ASSERT_GE(cuts.size(), 8u);
  OtherCore other(true);
  for (const Cut& cut : cuts) {
    SCOPED_TRACE("second share " + std::to_string(cut.share));
    SessionLog log(dir);
    std::vector<Event> parts[2];
    const bool stands = log.ReadInTwo(
        {},
        [&](int part, const LogMessage& m) {
          parts[part].push_back({m.log_us, std::string(m.channel),
                                 std::string(static_cast<const char*>(m.data), m.size)});
        },
        {&other, {}, cut.share});
    std::vector<Event> got = parts[0];
    if (stands) got.insert(got.end(), parts[1].begin(), parts[1].end());
    EXPECT_TRUE(got == expected) << got.size() << " events against " << expected.size();
    EXPECT_EQ(log.events(), static_cast<std::int64_t>(expected.size()));
    EXPECT_EQ(log.unread_bytes(), static_cast<std::int64_t>(size) - good_end);
    EXPECT_EQ(log.skipped_bytes(), skipped);
    if (cut.stands >= 0) {
      EXPECT_EQ(stands, cut.stands == 1);
    }
  }
}

class SessionLogRead : public ::testing::TestWithParam<Damage> {};

TEST_P(SessionLogRead, ReadsAsDocumentedPastDamageCountingWhatItSkips) {
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
  // Where events start, and where a sync word stands inside an event's data
  // (every fifth event has one): places to cut the log for ReadInTwo.
  std::vector<std::size_t> event_starts, false_syncs;
  for (int n = 0; n < kEvents; ++n) {
    Event e{1'700'000'000'000'000 + n * 33'333, channels[pick(rng)], ""};
    for (int k = size(rng); k > 0; --k) e.data.push_back(static_cast<char>(byte(rng)));
    if (n == 150) e.data.append(100'000, 'x');  // larger than the reader's buffer
    // A whole event, followed by a sync word, inside the data: what a reader
    // that begins there takes for events.
    std::size_t sync_at = std::string::npos;
    const std::string fake = EventBytes(9, {7, "F", "ab"}, 1, 2) + "\xED\xA1\xDA\x01";
    if (n % 5 == 0 && e.data.size() >= fake.size()) {
      sync_at = static_cast<std::size_t>(size(rng)) % (e.data.size() - fake.size() + 1);
      e.data.replace(sync_at, fake.size(), fake);
    }
    const auto c = static_cast<std::int32_t>(e.channel.size());
    const auto d = static_cast<std::int32_t>(e.data.size());
    if (GetParam() == Damage::kGarbageBetween && n % 7 == 3) {
      for (int k = size(rng) % 50; k > 0; --k) bytes.push_back(static_cast<char>(byte(rng)));
    }
    event_starts.push_back(bytes.size());
    if (sync_at != std::string::npos)
      false_syncs.push_back(bytes.size() + 28 + e.channel.size() + sync_at);
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

  long good_end = 0, skipped = 0;
  const std::vector<Event> expected = ReadAsDocumented(bytes, &good_end, &skipped);
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
  EXPECT_EQ(log.skipped_bytes(), skipped);
  const Damage d = GetParam();
  if (d == Damage::kNone || d == Damage::kGarbageFirst || d == Damage::kTwoBytesAfter) {
    // A log liblcm reads whole: the same events.
    long liblcm_end = 0;
    EXPECT_TRUE(got == ReadWithLiblcm(path, &liblcm_end));
    EXPECT_EQ(got.size(), static_cast<std::size_t>(kEvents));
    EXPECT_EQ(log.unread_bytes(), 0);  // liblcm reads past up to three bytes after the last event
    EXPECT_EQ(log.skipped_bytes(), d == Damage::kGarbageFirst ? 35 : 0);
  } else if (d == Damage::kCutShort) {
    EXPECT_GT(log.unread_bytes(), 0);
  } else {
    // Read past the damage, where liblcm ends the log: every event but the
    // damaged one (and perhaps an event-like stretch inside it).
    long liblcm_end = 0;
    EXPECT_LT(ReadWithLiblcm(path, &liblcm_end).size(), static_cast<std::size_t>(kEvents - 100));
    EXPECT_GE(got.size(), static_cast<std::size_t>(kEvents - 1));
    EXPECT_GT(log.skipped_bytes(), 0);
    EXPECT_EQ(log.unread_bytes(), 0);
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
  ExpectReadInTwoReadsAsOne(dir.string(), bytes.size(), expected, good_end, skipped, event_starts,
                            false_syncs, GetParam() == Damage::kNone);
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
