// The instructor station's library (docs/instructor.md): its options and the
// lab file's [instructor] section are checked; what it knows of the session
// comes from the session's own messages (events from telemetry, control and
// status, the essential contact not a collision); the views it draws are
// the chosen station's, only once watched.
#include <gtest/gtest.h>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_renderer/png_io.h"
#include "rms/instructor_station/instructor_station.h"
#include "rms/instructor_station/session_watch.h"
#include "rms/instructor_station/station_views.h"
#include "rms/instructor_station/web_server.h"
#include "rms/session/lab_file.h"
#include "rms/session_control_t.hpp"
#include "rms/wire/channels.h"
#include "rms/wire/collision_bits.h"
#include "rms/wire/message_io.h"

namespace rms::instructor_station {
namespace {

constexpr const char* kLab = R"(
[hosts]
operator_station = "localhost"
dynamics_proc = "localhost"
scene_proc = "localhost"
esg_renderer = "localhost"
recorder = "localhost"
[lcm]
group = "239.255.76.67"
port = 7667
ttl = 0
[remote]
root = ""
build = ""
)";

TEST(InstructorOptions, BeyondLoopbackNeedsATokenAndBadValuesAreRefusedByName) {
  InstructorOptions o;
  EXPECT_NO_THROW(CheckOptions(o));
  o.bind = "0.0.0.0";
  try {
    CheckOptions(o);
    ADD_FAILURE() << "no token beyond loopback was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--token"), std::string::npos) << e.what();
  }
  o.token = "0123456789abcdef0123";
  EXPECT_NO_THROW(CheckOptions(o));
  o.token = "short";
  EXPECT_THROW(CheckOptions(o), InputError);
  o.token = "0123456789abcdef/123";
  EXPECT_THROW(CheckOptions(o), InputError);
  o = InstructorOptions{};
  o.view_width = 17;
  EXPECT_THROW(CheckOptions(o), InputError);
  o = InstructorOptions{};
  o.view_rate_hz = 0;
  EXPECT_THROW(CheckOptions(o), InputError);
}

TEST(InstructorLabFile, TheBindIsOptionalAndCheckedByKey) {
  EXPECT_EQ(session::ParseLabFile(kLab, "lab.toml").instructor_bind, "");
  EXPECT_EQ(
      session::ParseLabFile(std::string(kLab) + "[instructor]\nbind = \"0.0.0.0\"\n", "lab.toml")
          .instructor_bind,
      "0.0.0.0");
  try {
    session::ParseLabFile(std::string(kLab) + "[instructor]\nbind = \"everywhere\"\n", "lab.toml");
    ADD_FAILURE() << "a bind that is no address was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("instructor.bind"), std::string::npos) << e.what();
  }
  EXPECT_THROW(
      session::ParseLabFile(std::string(kLab) + "[instructor]\nbnd = \"0.0.0.0\"\n", "lab.toml"),
      InputError);
}

class Watch : public ::testing::Test {
 protected:
  Watch() : lcm("", ""), watch(config, &lcm, &counters) {}
  void Telemetry(std::int64_t frame, int mode, bool acquired, std::uint32_t collisions,
                 bool finger_held = false, double master_finger = 0, double slave_finger = 0) {
    dcp_telemetry_t t{};
    t.frame = frame;
    t.mode = static_cast<std::int8_t>(mode);
    t.acquired = acquired;
    t.collisions = static_cast<std::int32_t>(collisions);
    t.finger_held = finger_held;
    t.master_finger = master_finger;
    t.slave_finger = slave_finger;
    t.p_RoA_R_ft[0] = frame * 0.1;
    transport::PublishMessage(lcm, wire::channels::kDcpTelemetry, t);
    Drain();
  }
  void Drain() {
    while (lcm.HandleSubscriptions(0) > 0) {
    }
  }
  std::string EventText() {
    std::string s;
    for (const auto& e : watch.EventsJson(0, 1000)) s += e["text"].get<std::string>() + "\n";
    return s;
  }
  LabConfig config = LoadConfig(DefaultConfigPath());
  transport::LogLcm lcm;
  Counters counters;
  SessionWatch watch;
};

TEST_F(Watch, EventsComeFromTheSessionsMessagesAndALateReaderGetsThemAll) {
  Telemetry(1, 1, false, 0);
  // The finger closing onto the BAR: the essential contact, not a collision.
  Telemetry(2, 1, false, wire::collision_bits::kEffHexRecpt << 2, true, 1.0, 0.5);
  Telemetry(3, 2, true, 0);
  Telemetry(4, 2, true, 1u << 6);  // payload against the bay
  session_control_t c;
  c.command = session_control_t::FREEZE;
  transport::PublishMessage(lcm, wire::channels::kControl, c);
  Drain();
  const std::string text = EventText();
  EXPECT_NE(text.find("Mode 1"), std::string::npos) << text;
  EXPECT_NE(text.find("Mode 2"), std::string::npos) << text;
  EXPECT_NE(text.find("ACQUIRED"), std::string::npos) << text;
  EXPECT_EQ(text.find("recpt"), std::string::npos) << "the essential contact is no collision\n"
                                                   << text;
  EXPECT_NE(text.find("COLLISION " + std::string(wire::kCollisionNames[6])), std::string::npos)
      << text;
  EXPECT_NE(text.find("freeze (from"), std::string::npos) << text;
  // A reader from event 2 on gets the rest, in order.
  const auto later = watch.EventsJson(2, 1000);
  ASSERT_FALSE(later.empty());
  EXPECT_EQ(later[0]["seq"], 2);
  EXPECT_EQ(later.back()["seq"].get<std::int64_t>() + 1, watch.events_seen());
  // The status says the latest.
  const auto s = watch.StatusJson();
  EXPECT_EQ(s["dcp"]["frame"], 4);
  EXPECT_EQ(s["dcp"]["mode"], 2);
  EXPECT_TRUE(s["dcp"]["acquired"].get<bool>());
  EXPECT_EQ(s["dcp"]["collisions"], wire::kCollisionNames[6]);
  // Old or repeated telemetry changes nothing; malformed is counted.
  Telemetry(3, 1, false, 0);
  EXPECT_EQ(watch.StatusJson()["dcp"]["frame"], 4);
  const char junk[3] = {1, 2, 3};
  lcm.Publish(wire::channels::kDcpTelemetry, junk, 3);
  Drain();
  std::int64_t dropped = 0;
  for (int i = static_cast<int>(kDroppedFirst); i <= static_cast<int>(kDroppedLast); ++i)
    dropped += counters.Get(static_cast<Counter>(i));
  EXPECT_EQ(dropped, 1);
}

TEST(InstructorViews, OnlyWatchedViewsAreDrawnEachFromItsOwnStation) {
  const LabConfig config = LoadConfig(DefaultConfigPath());
  Counters counters;
  StationViews views(config, 64, 48, 120.0, &counters);
  wire::DcpFrameData d;
  d.arm = arm::SinCosFromDegrees({0, 30, -60, -60, 0, 0});
  d.control.camera_station = 4;
  d.shoulder_height_ft = 3.0;
  d.finger_gap_ft = 1.0;
  d.p_RoPo_R_ft = config.payload.p_RoPo_R_ft;
  d.R_RP = config.payload.R_RP;
  d.frame = 1;
  views.Update(d);
  EXPECT_EQ(counters.Get(Counter::kViewsRendered), 0);  // nobody watches
  views.Request(3);
  views.Request(kOperatorView);
  d.frame = 2;
  views.Update(d);
  EXPECT_EQ(counters.Get(Counter::kViewsRendered), 2);
  const ViewImage three = views.Latest(3), op = views.Latest(kOperatorView);
  EXPECT_EQ(three.frame, 2);
  ASSERT_FALSE(three.png.empty());
  ASSERT_FALSE(op.png.empty());
  EXPECT_NE(three.png, op.png);  // station 3 is not the operator's station 4
  EXPECT_TRUE(views.Latest(5).png.empty());
  views.Update(d);  // the same frame: not drawn again
  EXPECT_EQ(counters.Get(Counter::kViewsRendered), 2);
  // Frozen (no new frame), a view first asked for now is drawn all the same.
  views.Request(5);
  views.Update(d);
  EXPECT_EQ(views.Latest(5).frame, 2);
  EXPECT_EQ(counters.Get(Counter::kViewsRendered), 3);
  EXPECT_THROW(views.Request(9), std::out_of_range);
}

TEST(InstructorMap, OutlinesTheOrbiterAndTheCaeFromAbove) {
  const nlohmann::json m = MapJson(LoadConfig(DefaultConfigPath()));
  int cae = 0, orbiter = 0;
  for (const auto& o : m["outlines"]) {
    EXPECT_GE(o["points"].size(), 2u) << o["name"];  // a wall seen from above: a line
    (o["group"] == "cae" ? cae : orbiter)++;
  }
  EXPECT_GT(cae, 0);
  EXPECT_GT(orbiter, 0);
  EXPECT_EQ(m["stations"].size(), static_cast<std::size_t>(kNumCameraStations));
}

}  // namespace
}  // namespace rms::instructor_station
