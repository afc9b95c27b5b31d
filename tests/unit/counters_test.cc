#include "rms/base/counters.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <gtest/gtest.h>
#include <random>
#include <regex>
#include <set>
#include <sstream>

#include "rms/session/session_summary.h"
#include "rms/wire/collision_bits.h"
#include "rms/wire/frame_receiver.h"
#include "rms/wire/message_io.h"

namespace rms {
namespace {

TEST(SequenceTracker, GapsDuplicatesAndStaleFrames) {
  wire::SequenceTracker t;
  EXPECT_EQ(t.Accept(5), wire::SequenceTracker::Verdict::kFirst);
  EXPECT_EQ(t.Accept(6), wire::SequenceTracker::Verdict::kNext);
  EXPECT_EQ(t.Accept(9), wire::SequenceTracker::Verdict::kGap);
  EXPECT_EQ(t.missing(), 2);
  EXPECT_EQ(t.Accept(9), wire::SequenceTracker::Verdict::kDuplicate);
  EXPECT_EQ(t.Accept(7), wire::SequenceTracker::Verdict::kStale);
  EXPECT_EQ(t.received(), 3);
  EXPECT_EQ(t.duplicates(), 1);
  EXPECT_EQ(t.stale(), 1);
  EXPECT_EQ(t.last(), 9);
}

// One forged frame number far ahead (2^47) must not lock the stream: with
// the session's clock it is refused outright; with none it may be taken,
// and then the real stream is followed again after kResyncAfter refusals.
TEST(SequenceTracker, AFarFutureFrameCannotLockTheStream) {
  using V = wire::SequenceTracker::Verdict;
  const std::int64_t forged = std::int64_t{1} << 47;
  wire::FrameClock clock;
  clock.epoch_us = 1'000'000'000'000;
  clock.max_rate_hz = 30 * 100;
  wire::SequenceTracker with_clock;
  with_clock.SetClock(clock);
  const std::int64_t t0 = clock.epoch_us + 5'000'000;  // 5 s into the session
  EXPECT_EQ(with_clock.Accept(100, t0), V::kFirst);
  EXPECT_EQ(with_clock.Accept(forged, t0), V::kFarAhead);
  EXPECT_EQ(with_clock.Accept(clock.Limit(t0) + 1, t0), V::kFarAhead);
  EXPECT_EQ(with_clock.Accept(101, t0), V::kNext);
  EXPECT_EQ(with_clock.far_ahead(), 2);
  // A restarted sender's jump within the clock is a gap, as before.
  EXPECT_EQ(with_clock.Accept(400, t0 + 10'000'000), V::kGap);

  wire::SequenceTracker none;
  EXPECT_EQ(none.Accept(forged), V::kFirst);  // nothing to tell it by yet
  std::int64_t f = 200;
  for (int i = 1; i < wire::SequenceTracker::kResyncAfter; ++i)
    EXPECT_EQ(none.Accept(f++), V::kStale) << i;
  EXPECT_EQ(none.Accept(f), V::kResync);
  EXPECT_EQ(none.last(), f);
  EXPECT_EQ(none.Accept(f + 1), V::kNext);
  EXPECT_EQ(none.resyncs(), 1);
  // Far ahead of the last without a clock: refused, and followed only as a run.
  EXPECT_EQ(none.Accept(f + 2 + wire::SequenceTracker::kMaxJump), V::kFarAhead);
  EXPECT_EQ(none.Accept(f + 2), V::kNext);
  // Refusals that are not one run (stale frames of a reordering) never resync.
  wire::SequenceTracker reorder;
  reorder.Accept(1000);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(reorder.Accept(999 - (i % 2)), V::kStale);
  EXPECT_EQ(reorder.resyncs(), 0);
}

// A woken process's queue of old frames is dropped, not executed: a frame
// is late when its age exceeds the link's own delay by the limit.
TEST(LateFrameFilter, DropsWhatWaitedBeyondTheLinksDelayAndFollowsAClockOffset) {
  wire::LateFrameFilter off;
  EXPECT_FALSE(off.TooLate(0, 10'000'000));
  wire::LateFrameFilter late(30.0);
  EXPECT_EQ(late.limit_us(), 100000);
  const std::int64_t offset = 2'500'000;  // the sender's clock 2.5 s behind: ages read 2.5 s more
  std::int64_t now = 50'000'000;
  for (int i = 0; i < 60; ++i, now += 33333) EXPECT_FALSE(late.TooLate(now - offset - 1500, now));
  // Stopped for 8 s: the queued frames are 8 s (down to 0.2 s) old when handled.
  for (int i = 0; i < 234; ++i)
    EXPECT_TRUE(late.TooLate(now - offset - 8'000'000 + i * 33333, now)) << i;
  EXPECT_FALSE(late.TooLate(now - offset - 2000, now));
  // Jitter within the limit passes.
  EXPECT_FALSE(late.TooLate(now - offset - 90000, now));
}

TEST(LatencyHistogram, PercentilesAtEachResolution) {
  LatencyHistogram h;
  for (int i = 1; i <= 100; ++i) h.Add(i);  // 1..100 us
  EXPECT_DOUBLE_EQ(h.Percentile(0.5), 50);
  EXPECT_DOUBLE_EQ(h.Percentile(0.99), 99);
  EXPECT_DOUBLE_EQ(h.Percentile(1.0), 100);
  h.Reset();
  for (int i = 0; i < 99; ++i) h.Add(2000);
  h.Add(250000);
  EXPECT_NEAR(h.Percentile(0.5), 2000, 10);
  EXPECT_NEAR(h.Percentile(1.0), 250000, 1000);
  EXPECT_EQ(h.count(), 100);
  EXPECT_DOUBLE_EQ(h.max_us(), 250000);
}

TEST(Counters, AFamilySumsItsMembersAndOnlyTouchedCountersAreReported) {
  Counters c;
  c.Add(Counter::kDroppedTruncated, 2);
  c.Add(Counter::kDroppedWrongType);
  c.Add(Counter::kDroppedOperatorStateNonFinite);  // the family's last member
  c.Add(Counter::kPublished, 10);
  c.Set(Counter::kMode, 0);  // set to 0: touched, reported
  EXPECT_EQ(c.Sum(kDroppedFirst, kDroppedLast), 4);
  EXPECT_EQ(c.Get(Counter::kGaps), 0);
  const auto named = c.ByName();
  EXPECT_EQ(named.size(), 5u);
  EXPECT_EQ(named.at("dropped.truncated"), 2);
  EXPECT_EQ(named.at("mode"), 0);
  EXPECT_EQ(named.count("gaps"), 0u);
  Counters total;
  total.Add(Counter::kPublished, 1);
  total.AddAll(c);
  EXPECT_EQ(total.Get(Counter::kPublished), 11);
  EXPECT_EQ(total.ByName().size(), 5u);
}

// One table names every counter (docs/sessions.md "Process counters"): the
// names are unique and well formed, each family's members follow their own
// table (static_asserts in counters.h, message_io.h, collision_bits.h), and
// the docs list exactly this table.
TEST(Counters, TheTableNamesEveryCounterOnceAndTheDocsListIt) {
  std::set<std::string_view> names;
  for (const CounterInfo& info : kCounterTable) {
    EXPECT_TRUE(names.insert(info.name).second) << info.name;
    EXPECT_TRUE(std::regex_match(std::string(info.name), std::regex("[a-z_]+(\\.[a-z0-9_-]+)*")))
        << info.name;
    EXPECT_FALSE(info.processes.empty()) << info.name;
    EXPECT_FALSE(info.meaning.empty()) << info.name;
    EXPECT_EQ(CounterNamed(info.name), info.id);
  }
  EXPECT_FALSE(CounterNamed("dropped.reserved_bits").has_value());
  EXPECT_EQ(CounterName(wire::DroppedCounter(wire::DecodeError::kBadCount)), "dropped.bad_count");
  EXPECT_EQ(CounterName(wire::CollisionFramesCounter(12)), "collision_frames.payload-cae");
  EXPECT_EQ(CounterName(ClampedCounter(kCameraZoom)), "clamped.camera_zoom");
  std::ifstream f(std::string(RMSLAB_SOURCE_DIR) + "/docs/sessions.md");
  std::stringstream docs;
  docs << f.rdbuf();
  EXPECT_NE(docs.str().find(CounterTableMarkdown()), std::string::npos)
      << "docs/sessions.md \"Process counters\" is not the table: build/tools/rms_session counters "
         "prints it";
}

}  // namespace
}  // namespace rms

// Reordering (docs/sessions.md "Lossy links"; this machine's kernel has no
// tc netem to reorder a real link): a frame overtaken by a later one is
// counted missing when the later one arrives, then dropped as stale when it
// comes -- too late for a real-time frame; the count of frames used is
// exact.
namespace rms {
TEST(SequenceTracker, ReorderedFramesAreCountedMissingThenDroppedAsStale) {
  wire::SequenceTracker t;
  std::vector<wire::SequenceTracker::Verdict> v;
  for (std::int64_t f : {10, 11, 13, 12, 14, 16, 15, 15, 17}) v.push_back(t.Accept(f));
  using V = wire::SequenceTracker::Verdict;
  EXPECT_EQ(v, (std::vector<V>{V::kFirst, V::kNext, V::kGap, V::kStale, V::kNext, V::kGap,
                               V::kStale, V::kStale, V::kNext}));
  EXPECT_EQ(t.received(), 6);  // 10 11 13 14 16 17
  EXPECT_EQ(t.missing(), 2);   // 12 and 15, overtaken
  EXPECT_EQ(t.stale(), 3);
  EXPECT_EQ(t.previous(), 16);
}
}  // namespace rms

namespace rms {
namespace {

// The DCP frames a reader of a log believes (docs/security.md "What the
// summary trusts"): the longest increasing run, so forgeries far ahead or
// behind fall off it while gaps (frames lost) and restarts stay on it.
TEST(LongestIncreasingRun, KeepsTheRealSequenceAndDropsForgeriesAheadAndBehind) {
  const std::vector<std::int64_t> frames = {0, 1, 2, 500000, 500001, 3,  4, 7,
                                            8, 1, 2, 9,      10,     10, 11};
  const std::vector<std::size_t> run = session::LongestIncreasingRun(frames);
  std::vector<std::int64_t> kept;
  for (std::size_t i : run) kept.push_back(frames[i]);
  EXPECT_EQ(kept, (std::vector<std::int64_t>{0, 1, 2, 3, 4, 7, 8, 9, 10, 11}));
  EXPECT_EQ(run[8], 12u) << "of frame 10 logged twice, the first copy";
  EXPECT_TRUE(session::LongestIncreasingRun({}).empty());
  // Seeded random sequences: the run is increasing, and no increasing
  // subsequence found by brute force on short ones is longer.
  std::mt19937_64 rng(20261201);
  std::printf("seed 20261201\n");
  for (int t = 0; t < 200; ++t) {
    std::vector<std::int64_t> v(1 + rng() % 12);
    for (auto& x : v) x = static_cast<std::int64_t>(rng() % 20);
    const auto r = session::LongestIncreasingRun(v);
    for (std::size_t k = 1; k < r.size(); ++k) ASSERT_LT(v[r[k - 1]], v[r[k]]);
    for (std::size_t k = 1; k < r.size(); ++k) ASSERT_LT(r[k - 1], r[k]);
    std::size_t best = 0;
    for (std::uint32_t mask = 1; mask < (1u << v.size()); ++mask) {
      std::int64_t last = -1;
      std::size_t n = 0;
      bool ok = true;
      for (std::size_t i = 0; i < v.size() && ok; ++i) {
        if (!(mask & (1u << i))) continue;
        ok = v[i] > last;
        last = v[i];
        ++n;
      }
      if (ok) best = std::max(best, n);
    }
    ASSERT_EQ(r.size(), best);
  }
}

}  // namespace
}  // namespace rms
