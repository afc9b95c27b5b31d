// OtherCore (docs/performance.md "Two cores"): a share handed over is run
// once or, not started by the time its owner comes for it, never; what it
// throws is kept; with always_start it always runs. Nothing here may
// depend on an idle machine: whether a share starts in time is not asserted.
#include "rms/base/other_core.h"

#include <atomic>
#include <chrono>
#include <gtest/gtest.h>
#include <stdexcept>
#include <thread>

namespace rms {
namespace {

TEST(OtherCore, AShareRunsOnceOrNeverAndFinishSaysWhich) {
  OtherCore other;
  int ran_and_said = 0, not_run_and_said = 0;
  for (int i = 0; i < 200; ++i) {
    std::atomic<int> runs = 0;
    other.Start([&] { ++runs; });
    if (i % 2 == 0) std::this_thread::sleep_for(std::chrono::microseconds(200));
    const bool ran = other.Finish();
    if (!ran) std::this_thread::sleep_for(std::chrono::milliseconds(1));  // it must never start now
    ASSERT_EQ(runs.load(), ran ? 1 : 0) << "share " << i;
    ASSERT_FALSE(other.error());
    (ran ? ran_and_said : not_run_and_said)++;
  }
  std::printf("ran %d, taken back %d\n", ran_and_said, not_run_and_said);
}

TEST(OtherCore, WithAlwaysStartEveryShareRunsAndWhatItThrowsIsKept) {
  OtherCore other(true);
  for (int i = 0; i < 50; ++i) {
    std::atomic<int> runs = 0;
    other.Start([&] { ++runs; });
    ASSERT_TRUE(other.Finish());
    ASSERT_EQ(runs.load(), 1);
  }
  other.Start([] { throw std::runtime_error("the share failed"); });
  ASSERT_TRUE(other.Finish());
  ASSERT_TRUE(other.error());
  try {
    std::rethrow_exception(other.error());
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "the share failed");
  }
  // The next share starts clean.
  other.Start([] {});
  ASSERT_TRUE(other.Finish());
  EXPECT_FALSE(other.error());
}

TEST(OtherCore, NothingHandedOverIsNoShareAndARunningShareIsWaitedForAtTheEnd) {
  OtherCore other;
  EXPECT_FALSE(other.Finish());
  std::atomic<bool> started = false, finished = false;
  {
    OtherCore leaving;
    leaving.Start([&] {
      started = true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      finished = true;
    });
    while (!started) std::this_thread::yield();
  }  // destroyed with its share running: waited for
  EXPECT_TRUE(finished);
}

}  // namespace
}  // namespace rms
