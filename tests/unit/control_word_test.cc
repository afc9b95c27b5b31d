#include "rms/wire/control_word.h"

#include <gtest/gtest.h>

#include "rms/base/check.h"

namespace rms {
namespace {

TEST(ControlWord, ExhaustiveEveryValidWordRoundTripsAndEveryOtherIsRefused) {
  std::int64_t valid = 0, refused_checked = 0;
  for (std::uint32_t w = 0; w < (1u << 24); ++w) {
    const bool reserved = (w & wire::control_bits::kReservedMask) != 0;
    const bool mode0 = ((w >> wire::control_bits::kModeShift) & wire::control_bits::kModeMask) == 0;
    if (reserved || mode0) {
      // Refusal throws: check a stride of the 14.7 million refused words
      // (both kinds occur in it), not each one.
      if (w % 1021 == 0) {
        ASSERT_THROW(wire::UnpackControlWord(static_cast<std::int32_t>(w)), InputError) << w;
        ++refused_checked;
      }
      continue;
    }
    ++valid;
    const wire::ControlWord cw = wire::UnpackControlWord(static_cast<std::int32_t>(w));
    ASSERT_EQ(wire::PackControlWord(cw), w);
  }
  // 2^24 words; reserved bit 7 must be 0 (1/2) and mode 1-3 (3/4).
  EXPECT_EQ(valid, (1 << 24) / 2 * 3 / 4);
  EXPECT_GT(refused_checked, 10000);
}

TEST(ControlWord, FieldsLandInTheDocumentedBits) {
  wire::ControlWord cw;
  cw.camera_station = 8;
  cw.mode = 3;
  EXPECT_EQ(wire::PackControlWord(cw), 0x7u | (3u << 8));
  cw = {};
  cw.no_video = true;
  EXPECT_EQ(wire::PackControlWord(cw), (1u << 8) | (1u << 6));
  cw = {};
  cw.docked = true;
  EXPECT_EQ(wire::PackControlWord(cw), (1u << 8) | (1u << 13));
  cw = {};
  cw.priority_fixed = 0x7F;
  cw.priority_dynamic = 0x5;
  EXPECT_EQ(wire::PackControlWord(cw), (1u << 8) | (0x5u << 14) | (0x7Fu << 17));
  cw = {};
  cw.collision = cw.receptacle_collision = cw.acquired = cw.reset = cw.overlay = true;
  EXPECT_EQ(wire::PackControlWord(cw),
            (1u << 8) | (1u << 10) | (1u << 11) | (1u << 12) | (1u << 3) | (1u << 4));
  cw = {};
  cw.crosshairs = true;
  EXPECT_EQ(wire::PackControlWord(cw), (1u << 8) | (1u << 5));
}

TEST(ControlWord, BitsAbove23AreRefused) {
  EXPECT_THROW(wire::UnpackControlWord(0x1000100), InputError);
}

}  // namespace
}  // namespace rms
