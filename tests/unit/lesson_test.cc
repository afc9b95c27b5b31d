// A lesson's file (docs/lessons.md): refused naming the key, and each event
// fired once, when its trigger first holds.
#include "rms/lesson/lesson.h"

#include <gtest/gtest.h>
#include <string>

#include "rms/base/check.h"
#include "rms/session_control_t.hpp"

namespace rms::lesson {
namespace {

const char* kLesson = R"(
[[events]]
at_s = 2.5
do = "malfunction Joint 2   STUCK"
[[events]]
on_mode = 2
do = "repair joint 2"
[[events]]
when = "dock_distance_ft < 5"
do = "freeze"
for_s = 3
)";

dcp_telemetry_t Telemetry(int mode, double dock_distance_ft = 50) {
  dcp_telemetry_t t{};
  t.mode = static_cast<std::int8_t>(mode);
  t.dock_distance_ft = dock_distance_ft;
  return t;
}

TEST(Lesson, EachEventFiresOnceWhenItsTriggerFirstHolds) {
  Lesson l = Lesson::Parse(kLesson, "lesson.toml");
  ASSERT_EQ(l.events().size(), 3u);
  EXPECT_EQ(l.events()[0].command, session_control_t::MALFUNCTION);
  EXPECT_EQ(l.events()[0].name, "joint 2 stuck");  // the canonical text
  EXPECT_EQ(l.events()[1].command, session_control_t::REPAIR);
  EXPECT_EQ(l.events()[2].command, session_control_t::FREEZE);
  EXPECT_DOUBLE_EQ(l.events()[2].for_s, 3.0);
  dcp_telemetry_t t = Telemetry(1, 1.0);  // Mode 1: a docking distance means nothing yet
  EXPECT_TRUE(l.Due(0.0, nullptr).empty());
  EXPECT_TRUE(l.Due(2.4, &t).empty());
  EXPECT_EQ(l.Due(2.5, &t), std::vector<std::size_t>{0});
  EXPECT_TRUE(l.Due(3.0, &t).empty()) << "an event fired twice";
  t = Telemetry(2);
  EXPECT_EQ(l.Due(10.0, &t), std::vector<std::size_t>{1});
  t = Telemetry(3, 6.0);
  EXPECT_TRUE(l.Due(20.0, &t).empty());
  t = Telemetry(3, 4.9);
  EXPECT_EQ(l.Due(30.0, &t), std::vector<std::size_t>{2});
  t = Telemetry(3, 1.0);
  EXPECT_TRUE(l.Due(31.0, &t).empty());
  EXPECT_EQ(l.fired(), 3u);
}

TEST(Lesson, ModeOneIsEnteredOnlyAfterAnotherMode) {
  Lesson l =
      Lesson::Parse("[[events]]\non_mode = 1\ndo = \"malfunction finger jammed open\"\n", "l.toml");
  dcp_telemetry_t t = Telemetry(1);
  EXPECT_TRUE(l.Due(0.0, &t).empty()) << "the start is not an entry into Mode 1";
  t = Telemetry(2);
  EXPECT_TRUE(l.Due(1.0, &t).empty());
  t = Telemetry(1);  // a reset
  EXPECT_EQ(l.Due(2.0, &t).size(), 1u);
}

TEST(Lesson, ABadFileIsRefusedNamingTheKey) {
  struct Case {
    std::string text, message;
  };
  const Case cases[] = {
      {"", "key 'events': missing"},
      {"[[events]]\ndo = \"freeze\"\n", "events[0]: no trigger: give exactly one of"},
      {"[[events]]\nat_s = 1\non_mode = 2\ndo = \"freeze\"\n", "events[0]: more than one trigger"},
      {"[[events]]\nat_s = -1\ndo = \"freeze\"\n", "key 'events[0].at_s': must be >= 0"},
      {"[[events]]\non_mode = 4\ndo = \"freeze\"\n", "key 'events[0].on_mode': must be <= 3"},
      {"[[events]]\nat_s = 1\ndo = \"malfunction joint 9 stuck\"\n", "key 'events[0].do':"},
      {"[[events]]\nat_s = 1\ndo = \"explode\"\n",
       "key 'events[0].do': must be \"malfunction WHAT\""},
      {"[[events]]\nwhen = \"speed < 5\"\ndo = \"freeze\"\n",
       "key 'events[0].when': 'speed' is not a quantity"},
      {"[[events]]\nwhen = \"dock_distance_ft five\"\ndo = \"freeze\"\n",
       "key 'events[0].when': must be QUANTITY OP NUMBER"},
      {"[[events]]\nat_s = 1\ndo = \"repair all\"\nfor_s = 2\n",
       "key 'events[0].for_s': is for a freeze only"},
      {"[[events]]\nat_s = 1\ndo = \"freeze\"\nat = 2\n", "key 'events[0].at'"},
  };
  for (const Case& c : cases) {
    try {
      (void)Lesson::Parse(c.text, "lesson.toml");
      ADD_FAILURE() << "accepted: " << c.text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("lesson.toml: " + c.message), std::string::npos)
          << c.text << "\n"
          << e.what();
    }
  }
}

}  // namespace
}  // namespace rms::lesson
