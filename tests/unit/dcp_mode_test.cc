// The DCP's modes (rms/wire/dcp_mode.h): one table in the enumeration's
// order, and comparisons only between a wire number and a DcpMode.
#include "rms/wire/dcp_mode.h"

#include <cstdint>
#include <gtest/gtest.h>
#include <string>

namespace rms::wire {
namespace {

// What must not build: a DcpMode against a bare number, a double or a bool
// against a DcpMode.
template <typename A, typename B>
concept Comparable = requires(A a, B b) {
  a == b;
};
template <typename A, typename B>
concept Ordered = requires(A a, B b) {
  a < b;
};
static_assert(Comparable<std::int8_t, DcpMode> && Comparable<int, DcpMode>);
static_assert(Ordered<std::int8_t, DcpMode> && Ordered<DcpMode, DcpMode>);
static_assert(!Comparable<DcpMode, int> && !Ordered<DcpMode, int>);
static_assert(!Comparable<double, DcpMode> && !Comparable<bool, DcpMode>);
static_assert(!Ordered<double, DcpMode>);

TEST(DcpMode, AWireNumberComparesWithItsModeAndEveryModeHasItsName) {
  const std::int8_t wire_mode = 2;
  EXPECT_TRUE(wire_mode == DcpMode::kExtraction);
  EXPECT_TRUE(wire_mode >= DcpMode::kExtraction && wire_mode < DcpMode::kManoeuvring);
  EXPECT_FALSE(0 >= DcpMode::kAcquisition) << "0: not yet known, before every mode";
  for (int n = 1; n <= kNumDcpModes; ++n) {
    ASSERT_NE(DcpModeOf(n), nullptr);
    EXPECT_EQ(ModeNumber(DcpModeOf(n)->mode), n);
    EXPECT_EQ(std::string(DcpModeOf(n)->upper).size(), std::string(DcpModeOf(n)->name).size());
  }
  EXPECT_EQ(DcpModeOf(0), nullptr);
  EXPECT_EQ(DcpModeOf(kNumDcpModes + 1), nullptr);
}

}  // namespace
}  // namespace rms::wire
