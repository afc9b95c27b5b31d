// The word codec: exhaustive over the 2^24 words where the space allows,
// property tests (fixed, printed seeds) elsewhere.
#include "rms/wire/word_codec.h"

#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>
#include <limits>
#include <random>
#include <vector>

#include "rms/base/check.h"

namespace rms::wire {
namespace {

constexpr std::uint32_t kWords = 1u << 24;

void ExhaustiveRoundTrip(const wire::FixedFormat& f) {
  std::int64_t valid = 0;
  double prev = -std::numeric_limits<double>::infinity();
  // Walk raw values in increasing order: patterns 0x800000..0xFFFFFF are the
  // negatives for signed formats.
  for (std::uint32_t i = 0; i < kWords; ++i) {
    const wire::Word w = f.is_signed ? (i ^ 0x800000u) : i;
    const std::int32_t raw = wire::RawUnchecked(f, w);
    const bool in_range = raw >= f.raw_min && raw <= f.raw_max;
    if (!in_range) {
      // Refusal throws; check the words next to the range and a stride of the
      // rest (16 million exceptions would take most of a minute).
      if (raw == f.raw_min - 1 || raw == f.raw_max + 1 || i % 4099 == 0) {
        ASSERT_THROW(wire::Decode(f, static_cast<std::int32_t>(w)), InputError)
            << wire::FormatWord(w);
      }
      continue;
    }
    ++valid;
    const double v = wire::Decode(f, static_cast<std::int32_t>(w));
    ASSERT_GT(v, prev) << "decode must be strictly increasing in raw, word " << wire::FormatWord(w);
    prev = v;
    const wire::Encoded e = wire::Encode(f, v);
    ASSERT_EQ(e.word, w) << f.name << " word " << wire::FormatWord(w) << " value " << v;
    ASSERT_FALSE(e.saturated);
  }
  EXPECT_EQ(valid, static_cast<std::int64_t>(f.raw_max) - f.raw_min + 1);
}

TEST(WordCodec, Sc22ExhaustiveRoundTrip) { ExhaustiveRoundTrip(wire::kSC22); }
TEST(WordCodec, Ft12ExhaustiveRoundTrip) { ExhaustiveRoundTrip(wire::kFT12); }
TEST(WordCodec, U24ExhaustiveRoundTrip) { ExhaustiveRoundTrip(wire::kU24); }
TEST(WordCodec, Adc16ExhaustiveRoundTripAndRangeCheck) { ExhaustiveRoundTrip(wire::kADC16); }

TEST(WordCodec, SignExtensionExhaustive) {
  for (std::uint32_t w = 0; w < kWords; ++w) {
    const std::int32_t s = wire::ToSigned(w);
    ASSERT_GE(s, wire::kSignedMin);
    ASSERT_LE(s, wire::kSignedMax);
    ASSERT_EQ(wire::FromSigned(s), w);
  }
  EXPECT_EQ(wire::ToSigned(0xFFFFFFu), -1);
  EXPECT_EQ(wire::ToSigned(0x800000u), wire::kSignedMin);
  EXPECT_EQ(wire::ToSigned(0x7FFFFFu), wire::kSignedMax);
}

TEST(WordCodec, BamExhaustiveRoundTrip) {
  for (std::uint32_t w = 0; w < kWords; ++w) {
    const double a = wire::DecodeAngleBam(static_cast<std::int32_t>(w));
    ASSERT_GE(a, -180.0);
    ASSERT_LT(a, 180.0);
    ASSERT_EQ(wire::EncodeAngleBam(a), w) << wire::FormatWord(w);
  }
}

TEST(WordCodec, BitsAboveBit23MakeAWordInvalid) {
  const std::uint64_t seed = 20261122;
  std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
  std::mt19937_64 rng(seed);
  for (int i = 0; i < 100000; ++i) {
    std::int32_t carried = static_cast<std::int32_t>(rng());
    if ((static_cast<std::uint32_t>(carried) >> 24) == 0) carried |= 1 << 24;
    ASSERT_FALSE(wire::IsValidWord(carried));
    try {
      wire::Decode(wire::kFT12, carried);
      FAIL() << "no error for " << wire::FormatWord(carried);
    } catch (const InputError& e) {
      ASSERT_NE(std::string(e.what()).find("bits above bit 23"), std::string::npos) << e.what();
    }
    ASSERT_THROW(wire::DecodeAngleBam(carried), InputError);
  }
  const std::int32_t words[] = {1, 2, 0x1000000, 4};
  EXPECT_EQ(wire::FirstInvalidWord(words), 2);
  EXPECT_TRUE(wire::IsValidWord(0xFFFFFF));
  EXPECT_FALSE(wire::IsValidWord(-1));
}

TEST(WordCodec, RandomValuesRoundToNearestWithinHalfLsb) {
  const std::uint64_t seed = 7;
  std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
  std::mt19937_64 rng(seed);
  for (const wire::FixedFormat* f : {&wire::kSC22, &wire::kFT12, &wire::kADC16, &wire::kU24}) {
    std::uniform_real_distribution<double> in(f->min_value(), f->max_value());
    for (int i = 0; i < 200000; ++i) {
      const double v = in(rng);
      const wire::Encoded e = wire::Encode(*f, v);
      ASSERT_FALSE(e.saturated) << f->name << " " << v;
      const double back = wire::Decode(*f, static_cast<std::int32_t>(e.word));
      ASSERT_LE(std::abs(back - v), 0.5 * f->lsb() * (1 + 1e-12)) << f->name << " " << v;
    }
  }
}

TEST(WordCodec, OutOfRangeSaturatesAndIsReported) {
  const std::uint64_t seed = 99;
  std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> mag(0.0, 40.0);
  for (const wire::FixedFormat* f : {&wire::kSC22, &wire::kFT12, &wire::kADC16, &wire::kU24}) {
    for (int i = 0; i < 10000; ++i) {
      const double over = f->max_value() + f->lsb() + std::pow(2.0, mag(rng));
      const double under = f->min_value() - f->lsb() - std::pow(2.0, mag(rng));
      const wire::Encoded hi = wire::Encode(*f, over), lo = wire::Encode(*f, under);
      ASSERT_TRUE(hi.saturated);
      ASSERT_TRUE(lo.saturated);
      ASSERT_EQ(wire::Decode(*f, static_cast<std::int32_t>(hi.word)), f->max_value());
      ASSERT_EQ(wire::Decode(*f, static_cast<std::int32_t>(lo.word)), f->min_value());
      ASSERT_THROW(wire::EncodeExact(*f, over), InputError);
    }
  }
  EXPECT_TRUE(wire::Encode(wire::kSC22, 1e300).saturated);
  EXPECT_TRUE(wire::Encode(wire::kSC22, -1e300).saturated);
}

TEST(WordCodec, ExactEncodeErrorNamesTheFormatAndRange) {
  try {
    wire::EncodeExact(wire::kFT12, 5000.0);
    FAIL();
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("5000"), std::string::npos) << m;
    EXPECT_NE(m.find("FT12"), std::string::npos) << m;
    EXPECT_NE(m.find("-2048"), std::string::npos) << m;
  }
  // Within half an LSB of the end rounds to the end and is accepted.
  EXPECT_EQ(wire::EncodeExact(wire::kSC22, wire::kSC22.max_value() + 0.49 * wire::kSC22.lsb()),
            0x7FFFFFu);
}

TEST(WordCodec, NonFiniteInputIsAnError) {
  for (double bad : {std::nan(""), std::numeric_limits<double>::infinity(),
                     -std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(wire::Encode(wire::kSC22, bad), InputError);
    EXPECT_THROW(wire::EncodeExact(wire::kFT12, bad), InputError);
    EXPECT_THROW(wire::EncodeAngleBam(bad), InputError);
  }
}

TEST(WordCodec, TiesRoundAwayFromZero) {
  EXPECT_EQ(
      wire::RawUnchecked(wire::kFT12, wire::Encode(wire::kFT12, 0.5 * wire::kFT12.lsb()).word), 1);
  EXPECT_EQ(
      wire::RawUnchecked(wire::kFT12, wire::Encode(wire::kFT12, -0.5 * wire::kFT12.lsb()).word),
      -1);
  EXPECT_EQ(
      wire::RawUnchecked(wire::kFT12, wire::Encode(wire::kFT12, 0.4999 * wire::kFT12.lsb()).word),
      0);
}

// Encode rounds as std::llround does, to the bit: random values over each
// format's range and past its ends, every tie k + 1/2 LSB near zero, the
// range's ends and the doubles either side of each.
TEST(WordCodec, RoundsAsLlroundToTheBit) {
  const std::uint64_t seed = 1972;
  std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
  std::mt19937_64 rng(seed);
  for (const wire::FixedFormat* f : {&wire::kSC22, &wire::kFT12, &wire::kADC16, &wire::kU24}) {
    auto expect_llround = [&](double v) {
      const double scaled = v * static_cast<double>(std::int64_t{1} << f->frac_bits);
      const std::int64_t want =
          std::clamp<std::int64_t>(std::llround(scaled), f->raw_min, f->raw_max);
      ASSERT_EQ(wire::RawUnchecked(*f, wire::Encode(*f, v).word), want) << f->name << " " << v;
    };
    std::vector<double> values;
    std::uniform_real_distribution<double> in(f->min_value() - 3 * f->lsb(),
                                              f->max_value() + 3 * f->lsb());
    for (int i = 0; i < 200000; ++i) values.push_back(in(rng));
    for (std::int64_t k = -2000; k <= 2000; ++k) values.push_back((k + 0.5) * f->lsb());
    for (const double end : {f->min_value(), f->max_value()})
      for (const double d : {-0.5, 0.0, 0.5}) values.push_back(end + d * f->lsb());
    for (const double v : values) {
      expect_llround(v);
      expect_llround(std::nextafter(v, -1e300));
      expect_llround(std::nextafter(v, 1e300));
    }
  }
}

TEST(WordCodec, BamWrapsAnyAngle) {
  EXPECT_EQ(wire::EncodeAngleBam(180.0), 0x800000u);
  EXPECT_EQ(wire::EncodeAngleBam(-180.0), 0x800000u);
  EXPECT_EQ(wire::EncodeAngleBam(360.0), 0u);
  EXPECT_EQ(wire::EncodeAngleBam(90.0), 0x400000u);
  EXPECT_EQ(wire::EncodeAngleBam(-90.0), 0xC00000u);
  const std::uint64_t seed = 3;
  std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ang(-5000.0, 5000.0);
  for (int i = 0; i < 100000; ++i) {
    const double a = ang(rng);
    const double back = wire::DecodeAngleBam(static_cast<std::int32_t>(wire::EncodeAngleBam(a)));
    double d = std::remainder(back - a, 360.0);
    ASSERT_LE(std::abs(d), 0.5 * wire::kBamLsbDeg + 1e-9) << a;
  }
}

TEST(WordCodec, FormatsHaveTheDocumentedRanges) {
  EXPECT_DOUBLE_EQ(wire::kSC22.min_value(), -2.0);
  EXPECT_DOUBLE_EQ(wire::kSC22.lsb(), std::ldexp(1.0, -22));
  EXPECT_DOUBLE_EQ(wire::kFT12.min_value(), -2048.0);
  EXPECT_DOUBLE_EQ(wire::kFT12.max_value(), 2048.0 - std::ldexp(1.0, -12));
  EXPECT_EQ(wire::kADC16.raw_min, -32768);
  EXPECT_EQ(wire::kADC16.raw_max, 32767);
  EXPECT_EQ(wire::kU24.raw_max, 0xFFFFFF);
}

}  // namespace
}  // namespace rms::wire
