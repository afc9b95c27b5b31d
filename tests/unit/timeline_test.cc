#include "rms/operator_station/timeline.h"

#include <gtest/gtest.h>

#include "rms/base/check.h"
#include "rms/base/config.h"

namespace rms::operator_station {
namespace {

class TimelineTest : public ::testing::Test {
 protected:
  LabConfig config = LoadConfig(DefaultConfigPath());
  Timeline Parse(const std::string& text) { return Timeline::Parse(text, "t.tl", config.inputs); }
  std::string ErrorOf(const std::string& text) {
    try {
      Parse(text);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
};

TEST_F(TimelineTest, AnalogKeysInterpolateLinearlyFromTheirInitialValues) {
  const Timeline tl = Parse(
      "# a comment\n"
      "0 shoulder_yaw=10\n"
      "2.0 shoulder_yaw=30 elbow_pitch=-40   # trailing comment\n"
      "4 finger=1\n");
  EXPECT_DOUBLE_EQ(tl.end_time(), 4.0);
  EXPECT_DOUBLE_EQ(tl.Sample(0).value[kShoulderYaw], 10.0);
  EXPECT_DOUBLE_EQ(tl.Sample(1).value[kShoulderYaw], 20.0);
  EXPECT_DOUBLE_EQ(tl.Sample(3).value[kShoulderYaw], 30.0);  // holds after its last keyframe
  EXPECT_DOUBLE_EQ(tl.Sample(1).value[kElbowPitch], -20.0);  // from initial 0 at t=0
  EXPECT_DOUBLE_EQ(tl.Sample(2).value[kFinger], 0.5);        // 0 -> 1 over 0..4 s
  EXPECT_DOUBLE_EQ(tl.Sample(1).value[kShoulderHeight], config.inputs[kShoulderHeight].initial);
}

TEST_F(TimelineTest, DiscreteKeysStepAndResetIsOneFrame) {
  const Timeline tl = Parse("0 camera=2 overlay=off\n1.5 camera=7\n2 reset\n3 overlay=on end\n");
  EXPECT_EQ(tl.Sample(1.49).camera_station, 2);
  EXPECT_EQ(tl.Sample(1.5).camera_station, 7);
  EXPECT_FALSE(tl.Sample(2.5).overlay);
  EXPECT_TRUE(tl.Sample(3).overlay);
  EXPECT_FALSE(tl.ResetIn(1.9, 1.99));
  EXPECT_TRUE(tl.ResetIn(1.99, 2.0));
  EXPECT_FALSE(tl.ResetIn(2.0, 2.1));  // only once
  EXPECT_DOUBLE_EQ(tl.end_time(), 3.0);
}

TEST_F(TimelineTest, ErrorsNameTheLineAndTheProblem) {
  EXPECT_NE(ErrorOf("0 camera=1\n1 sholder_yaw=3\n").find("t.tl:2: unknown key 'sholder_yaw'"),
            std::string::npos);
  EXPECT_NE(ErrorOf("2 camera=1\n1 camera=2\n").find("t.tl:2:"), std::string::npos);
  EXPECT_NE(ErrorOf("2 camera=1\n1 camera=2\n").find("time order"), std::string::npos);
  EXPECT_NE(ErrorOf("0 finger=lots\n").find("not a number"), std::string::npos);
  EXPECT_NE(ErrorOf("0 camera=9\n").find("1-8"), std::string::npos);
  EXPECT_NE(ErrorOf("x camera=1\n").find("not a time"), std::string::npos);
  EXPECT_NE(ErrorOf("1 end\n2 camera=3\n").find("follow the 'end'"), std::string::npos);
  EXPECT_NE(ErrorOf("1 finger\n").find("not key=value"), std::string::npos);
  EXPECT_NE(ErrorOf("0 camera=1\n").find("longer than 0"), std::string::npos);
  EXPECT_NE(ErrorOf("1 shoulder_yaw=nan\n").find("not a number"), std::string::npos);
}

TEST_F(TimelineTest, OutOfRangeValuesAreAcceptedWithAWarning) {
  const Timeline tl = Parse("1 shoulder_height=50\n");
  ASSERT_EQ(tl.warnings().size(), 1u);
  EXPECT_NE(tl.warnings()[0].find("clamped"), std::string::npos);
}

TEST_F(TimelineTest, TheShippedTimelinesParse) {
  for (const char* name : {"mission.tl", "tour.tl", "short.tl"}) {
    const Timeline tl = Timeline::Load(
        std::string(RMSLAB_SOURCE_DIR) + "/scripts/timelines/" + name, config.inputs);
    EXPECT_GT(tl.end_time(), 0.0);
    EXPECT_TRUE(tl.warnings().empty()) << name;
  }
}

}  // namespace
}  // namespace rms::operator_station
