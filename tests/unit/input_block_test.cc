#include "rms/wire/input_block.h"

#include <cmath>
#include <gtest/gtest.h>
#include <random>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/wire/word_codec.h"

namespace rms {
namespace {

class InputBlock : public ::testing::Test {
 protected:
  LabConfig config = LoadConfig(DefaultConfigPath());
};

TEST_F(InputBlock, RandomInputsRoundTripWithinHalfACount) {
  const std::uint64_t seed = 11;
  std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
  std::mt19937_64 rng(seed);
  for (int n = 0; n < 20000; ++n) {
    wire::OperatorInputs in;
    for (int i = 0; i < kNumAnalogInputs; ++i) {
      std::uniform_real_distribution<double> d(config.inputs[i].min, config.inputs[i].max);
      in.value[i] = d(rng);
    }
    in.camera_station = 1 + static_cast<int>(rng() % 8);
    in.reset = rng() & 1;
    in.overlay = rng() & 1;
    Counters c;
    const auto words = wire::EncodeInputs(in, config.inputs, &c);
    for (std::int32_t w : words) ASSERT_TRUE(wire::IsValidWord(w));
    const wire::OperatorInputs out = wire::DecodeInputs(words, config.inputs, &c);
    for (int i = 0; i < kNumAnalogInputs; ++i) {
      ASSERT_LE(std::abs(out.value[i] - in.value[i]),
                0.5 * std::abs(config.inputs[i].units_per_count) + 1e-12)
          << kAnalogInputNames[i];
    }
    ASSERT_EQ(out.camera_station, in.camera_station);
    ASSERT_EQ(out.reset, in.reset);
    ASSERT_EQ(out.overlay, in.overlay);
    ASSERT_EQ(c.Sum(kClampedFirst, kClampedLast), 0);
  }
}

TEST_F(InputBlock, OutOfRangeInputsAreClampedAndReported) {
  wire::OperatorInputs in = wire::InitialInputs(config.inputs);
  in.value[kShoulderHeight] = 55.0;  // max 20 ft
  in.value[kFinger] = -3.0;          // min 0
  in.camera_station = 11;
  Counters c;
  const auto words = wire::EncodeInputs(in, config.inputs, &c);
  EXPECT_EQ(c.Get(Counter::kClampedShoulderHeight), 1);
  EXPECT_EQ(c.Get(Counter::kClampedFinger), 1);
  EXPECT_EQ(c.Get(Counter::kClampedCameraStation), 1);
  const wire::OperatorInputs out = wire::DecodeInputs(words, config.inputs, &c);
  EXPECT_NEAR(out.value[kShoulderHeight], 20.0, 1e-3);
  EXPECT_NEAR(out.value[kFinger], 0.0, 1e-4);
  EXPECT_EQ(out.camera_station, 8);
}

TEST_F(InputBlock, CountsBeyondTheConverterAndBeyondTheRangeAreClampedAtTheDcp) {
  std::array<std::int32_t, wire::kInputWords> w{};
  w[kShoulderHeight] = static_cast<std::int32_t>(wire::FromSigned(100000));  // beyond ADC16
  w[kFinger] = static_cast<std::int32_t>(wire::FromSigned(-5000));           // finger < 0
  Counters c;
  const wire::OperatorInputs in = wire::DecodeInputs(w, config.inputs, &c);
  EXPECT_EQ(c.Get(Counter::kClampedAdcShoulderHeight), 1);
  EXPECT_EQ(c.Get(Counter::kClampedShoulderHeight), 1);  // 32.767 ft > 20 ft
  EXPECT_EQ(c.Get(Counter::kClampedFinger), 1);
  EXPECT_DOUBLE_EQ(in.value[kShoulderHeight], 20.0);
  EXPECT_DOUBLE_EQ(in.value[kFinger], 0.0);
}

TEST_F(InputBlock, MalformedBlocksAreRefusedWithTheWordNamed) {
  std::array<std::int32_t, wire::kInputWords> w{};
  w[3] = 0x1000000;
  try {
    wire::DecodeInputs(w, config.inputs, nullptr);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("input word 3"), std::string::npos) << e.what();
  }
  w[3] = 0;
  w[wire::kDiscreteWordIndex] = 1 << 7;  // reserved bit
  EXPECT_THROW(wire::DecodeInputs(w, config.inputs, nullptr), InputError);
}

TEST_F(InputBlock, NonFiniteOperatorValuesAreAnError) {
  wire::OperatorInputs in = wire::InitialInputs(config.inputs);
  in.value[kElbowPitch] = std::nan("");
  EXPECT_THROW(wire::EncodeInputs(in, config.inputs, nullptr), InputError);
}

}  // namespace
}  // namespace rms
