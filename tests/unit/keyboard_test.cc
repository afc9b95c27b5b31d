#include <gtest/gtest.h>

#include "keyboard.h"
#include "rms/config.h"

namespace rms::op {
namespace {

TEST(Keyboard, KeysStepInputsWithinTheirRanges) {
  const LabConfig config = LoadConfig(DefaultConfigPath());
  OperatorInputs in = InitialInputs(config.inputs);
  bool quit = false;
  ASSERT_TRUE(ApplyKey('q', config.inputs, &in, &quit));
  EXPECT_GT(in.value[kShoulderYaw], 0.0);
  ASSERT_TRUE(ApplyKey('5', config.inputs, &in, &quit));
  EXPECT_EQ(in.camera_station, 5);
  ASSERT_TRUE(ApplyKey(kKeyUp, config.inputs, &in, &quit));
  EXPECT_GT(in.value[kCameraTilt], 0.0);
  for (int i = 0; i < 100; ++i) ApplyKey('u', config.inputs, &in, &quit);
  EXPECT_DOUBLE_EQ(in.value[kFinger], config.inputs[kFinger].max);  // clamped, not beyond
  for (int i = 0; i < 200; ++i) ApplyKey('k', config.inputs, &in, &quit);
  EXPECT_DOUBLE_EQ(in.value[kShoulderHeight], config.inputs[kShoulderHeight].min);
  ASSERT_TRUE(ApplyKey(' ', config.inputs, &in, &quit));
  EXPECT_TRUE(in.reset);
  EXPECT_FALSE(ApplyKey('Z', config.inputs, &in, &quit));
  EXPECT_FALSE(quit);
  ApplyKey('x', config.inputs, &in, &quit);
  EXPECT_TRUE(quit);
}

}  // namespace
}  // namespace rms::op
