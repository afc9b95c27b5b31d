#include <gtest/gtest.h>

#include "rms/counters.h"

namespace rms {
namespace {

TEST(SequenceTracker, GapsDuplicatesAndStaleFrames) {
  SequenceTracker t;
  EXPECT_EQ(t.Accept(5), SequenceTracker::Verdict::kFirst);
  EXPECT_EQ(t.Accept(6), SequenceTracker::Verdict::kNext);
  EXPECT_EQ(t.Accept(9), SequenceTracker::Verdict::kGap);
  EXPECT_EQ(t.missing(), 2);
  EXPECT_EQ(t.Accept(9), SequenceTracker::Verdict::kDuplicate);
  EXPECT_EQ(t.Accept(7), SequenceTracker::Verdict::kStale);
  EXPECT_EQ(t.received(), 3);
  EXPECT_EQ(t.duplicates(), 1);
  EXPECT_EQ(t.stale(), 1);
  EXPECT_EQ(t.last(), 9);
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

TEST(Counters, SumByPrefix) {
  Counters c;
  c.Add("dropped.truncated", 2);
  c.Add("dropped.wrong_type");
  c.Add("droppedX");
  c.Add("published", 10);
  EXPECT_EQ(c.SumPrefix("dropped."), 3);
  EXPECT_EQ(c.Get("nothing"), 0);
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
  SequenceTracker t;
  std::vector<SequenceTracker::Verdict> v;
  for (std::int64_t f : {10, 11, 13, 12, 14, 16, 15, 15, 17}) v.push_back(t.Accept(f));
  using V = SequenceTracker::Verdict;
  EXPECT_EQ(v, (std::vector<V>{V::kFirst, V::kNext, V::kGap, V::kStale, V::kNext, V::kGap, V::kStale, V::kStale,
                               V::kNext}));
  EXPECT_EQ(t.received(), 6);  // 10 11 13 14 16 17
  EXPECT_EQ(t.missing(), 2);   // 12 and 15, overtaken
  EXPECT_EQ(t.stale(), 3);
  EXPECT_EQ(t.previous(), 16);
}
}  // namespace rms
