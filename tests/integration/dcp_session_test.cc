// The Dynamic Collision Program through the four real processes over real
// LCM, flown by scripts/lab as a user would: the mission acquires, extracts
// and docks; a collision holds the arm and then releases it; reset returns
// to Mode 1. The session's LCM log and summary.json show each mode change and
// collision as it happened.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "rms/base/config.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/mission/arm_ik.h"
#include "rms/mission/mission_plan.h"
#include "rms/scene_model/scene_model.h"
#include "rms/wire/channels.h"
#include "rms/wire/control_word.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/message_io.h"

#include "session_files.h"
#include "subprocess.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using testing::SourcePath;
using testing::Subprocess;

struct Session {
  ~Session() {
    if (!dir.empty()) fs::remove_all(fs::path(dir).parent_path());
  }
  std::string dir;
  nlohmann::json summary;
  std::vector<dcp_telemetry_t> telemetry;
  std::vector<dcp_frame_t> dcp_frames;
};

// Runs scripts/lab demo (on a timeline, or the autopilot when `timeline` is
// empty); reads back the summary and the log.
Session RunLab(const std::string& timeline, double speed, const std::string& tag, int port_base) {
  Session s;
  s.dir = testing::MakeTempDir(tag) + "/session";
  const std::string log = s.dir + ".lab.log";
  std::vector<std::string> argv = {SourcePath("scripts/lab"),
                                   "demo",
                                   "--no-build",
                                   "--out",
                                   s.dir,
                                   "--speed",
                                   std::to_string(speed),
                                   "--lcm-url",
                                   testing::UniqueLcmUrl(port_base),
                                   "--png-every",
                                   "0",
                                   "--width",
                                   "160",
                                   "--height",
                                   "120"};
  if (!timeline.empty()) {
    argv.push_back("--timeline");
    argv.push_back(timeline);
  }
  Subprocess lab(argv, log, {std::string("RMSLAB_BUILD=") + RMSLAB_BUILD_DIR});
  EXPECT_EQ(lab.Wait(300), 0) << testing::ReadFile(log);
  s.summary = nlohmann::json::parse(testing::ReadFile(s.dir + "/summary.json"));
  lcm::LogFile f(s.dir + "/lcmlog", "r");
  // Each message ends in its tag (docs/protocol.md "Message authentication").
  const int tag_bytes = testing::SessionTagsMessages(s.dir) ? wire::kMacBytes : 0;
  while (const lcm::LogEvent* ev = f.readNextEvent()) {
    if (ev->channel == wire::channels::kDcpTelemetry) {
      dcp_telemetry_t m;
      EXPECT_EQ(wire::SafeDecode(ev->data, ev->datalen - tag_bytes, &m), wire::DecodeError::kNone);
      s.telemetry.push_back(m);
    } else if (ev->channel == wire::channels::kDcpFrame) {
      dcp_frame_t m;
      EXPECT_EQ(wire::SafeDecode(ev->data, ev->datalen - tag_bytes, &m), wire::DecodeError::kNone);
      s.dcp_frames.push_back(m);
    }
  }
  return s;
}

TEST(DcpSession, TheMissionAcquiresExtractsAndDocks) {
  const LabConfig config = LoadConfig(DefaultConfigPath());
  const Session s = RunLab(SourcePath("scripts/timelines/mission.tl"), 3.0, "mission", 8200);
  const auto& mc = s.summary["mode_changes"];
  ASSERT_EQ(mc.size(), 2u) << s.summary.dump(2);
  EXPECT_EQ(mc[0]["from"], 1);
  EXPECT_EQ(mc[0]["to"], 2);
  EXPECT_EQ(mc[1]["from"], 2);
  EXPECT_EQ(mc[1]["to"], 3);
  EXPECT_LT(mc[0]["time_s"].get<double>(), mc[1]["time_s"].get<double>());
  EXPECT_TRUE(s.summary["acquired"].get<bool>());
  ASSERT_TRUE(s.summary["docked"].get<bool>());
  EXPECT_LE(s.summary["docking"]["distance_ft"].get<double>(), config.dcp.dock_distance_ft);
  EXPECT_LE(s.summary["docking"]["angle_deg"].get<double>(), config.dcp.dock_angle_deg);
  EXPECT_EQ(s.summary["final_mode"], 3);
  EXPECT_EQ(s.summary["held_frames"], 0);  // the planned path never collides
  // The ESG's control words carry it too: the last DCP frames say Mode 3, docked.
  ASSERT_FALSE(s.dcp_frames.empty());
  const wire::ControlWord last = wire::UnpackControlWord(s.dcp_frames.back().control_word);
  EXPECT_EQ(last.mode, wire::DcpMode::kManoeuvring);
  EXPECT_TRUE(last.docked);
  EXPECT_TRUE(last.acquired);
  // Telemetry and DCP frames pair up one to one, in order.
  ASSERT_EQ(s.telemetry.size(), s.dcp_frames.size());
  for (std::size_t i = 0; i < s.telemetry.size(); ++i) {
    ASSERT_EQ(s.telemetry[i].frame, s.dcp_frames[i].frame);
    EXPECT_EQ(s.telemetry[i].slave_collisions, 0);
  }
}

TEST(DcpSession, ACollisionHoldsThenReleasesAndResetReturnsToMode1) {
  const LabConfig config = LoadConfig(DefaultConfigPath());
  const mission::MissionGeometry g = mission::PlanGeometry(config);
  auto at = [&](const Eigen::Vector3d& d) {
    Eigen::Isometry3d X = g.X_RS2_grasp;
    X.translation() += d;
    return X;
  };
  std::vector<mission::Keyframe> keys;
  auto key = [&](double t, const Eigen::Isometry3d& X, double finger, const std::string& note) {
    const auto s = mission::SolveArmIk(config.arm, X, g.shoulder_height_ft);
    ASSERT_TRUE(s.has_value()) << note;
    keys.push_back({t, s->angles_deg, g.shoulder_height_ft, finger, t == 0 ? 8 : 0, note, ""});
  };
  const Eigen::Vector3d over_body(-6.0, 0, 3.0);
  key(0, at(over_body), 0, "over the body, away from the bar");
  key(2, at(over_body), 0, "hold");
  key(5, at(over_body + Eigen::Vector3d(0, 0, -5)), 0, "down into the body: held at contact");
  key(8, at(over_body), 0, "back up: released");
  key(11, at(Eigen::Vector3d(0, 0, 2)), 0, "over the receptacle");
  key(14, at(Eigen::Vector3d::Zero()), 0, "grasp position");
  key(15, at(Eigen::Vector3d::Zero()), 0, "finger open");
  key(17, at(Eigen::Vector3d::Zero()), 1, "finger closed: acquisition");
  key(19, at(Eigen::Vector3d(0, 0, 3)), 1, "lift");
  std::string text = mission::FormatTimeline(keys, "# hold, release, acquire, reset\n");
  text.replace(text.rfind('\n', text.size() - 2) + 1, std::string::npos, "19.5 reset\n21 end\n");
  const std::string tl_dir = testing::MakeTempDir("tl");
  const std::string path = tl_dir + "/hold.tl";
  std::ofstream(path) << text;
  struct Cleanup {
    std::string d;
    ~Cleanup() { fs::remove_all(d); }
  } cleanup{tl_dir};

  const Session s = RunLab(path, 2.0, "hold", 8300);
  // The collision: an end effector hexahedron against the payload's body.
  bool body_collision = false;
  for (const auto& c : s.summary["collisions"]) {
    const std::string kind = c["kind"];
    if (kind.find("-payload") != std::string::npos) {
      body_collision = true;
      EXPECT_GT(c["duration_s"].get<double>(), 0.1);
    }
  }
  EXPECT_TRUE(body_collision) << s.summary["collisions"].dump();
  EXPECT_GT(s.summary["held_frames"].get<int>(), 10);
  // Held, then released: after the last held frame the slave follows the master.
  int last_held = -1, held = 0;
  for (std::size_t i = 0; i < s.telemetry.size(); ++i) {
    if (s.telemetry[i].held) {
      last_held = static_cast<int>(i);
      ++held;
      EXPECT_TRUE(s.telemetry[i].collisions != 0);
      // Never below the body's top: the fingers' tips stay above it.
      const double tip = s.telemetry[i].p_RoA_R_ft[2] - config.end_effector.palm_length_ft -
                         config.end_effector.finger_length_ft;
      EXPECT_GT(tip, config.payload.p_RoPo_R_ft.z() +
                         scene_model::PayloadTopFlat_P(config.payload));  // the 16-gon's top flat
    }
  }
  ASSERT_GT(held, 10);
  ASSERT_LT(last_held + 30, static_cast<int>(s.telemetry.size()));
  const dcp_telemetry_t& after = s.telemetry[last_held + 30];
  EXPECT_FALSE(after.held);
  for (int k = 0; k < 6; ++k)
    EXPECT_DOUBLE_EQ(after.slave_angles_deg[k], after.master_angles_deg[k]);
  // Acquired, then reset: 1 -> 2 -> 1, payload back in the bay.
  const auto& mc = s.summary["mode_changes"];
  ASSERT_EQ(mc.size(), 2u) << mc.dump();
  EXPECT_EQ(mc[0]["to"], 2);
  EXPECT_EQ(mc[1]["from"], 2);
  EXPECT_EQ(mc[1]["to"], 1);
  EXPECT_EQ(s.summary["final_mode"], 1);
  const dcp_telemetry_t& end = s.telemetry.back();
  EXPECT_FALSE(end.acquired);
  EXPECT_NEAR(end.p_RoPo_R_ft[2], config.payload.p_RoPo_R_ft.z(), 1e-9);
}

TEST(DcpSession, TheLabDemosAutopilotAcquiresExtractsAndDocks) {
  // scripts/lab demo as the README runs it (at 4x, small frames): the
  // autopilot flies the task from the initial state, closing the loop on
  // the DCP's telemetry.
  const LabConfig config = LoadConfig(DefaultConfigPath());
  const Session s = RunLab("", 4.0, "autopilot", 8400);
  EXPECT_EQ(s.summary["pilot"], "autopilot");
  ASSERT_TRUE(s.summary["docked"].get<bool>()) << s.summary.dump(2);
  EXPECT_TRUE(s.summary["docking"]["within_tolerance"].get<bool>());
  EXPECT_LE(s.summary["docking"]["distance_ft"].get<double>(), config.dcp.dock_distance_ft);
  EXPECT_LE(s.summary["docking"]["angle_deg"].get<double>(), config.dcp.dock_angle_deg);
  EXPECT_EQ(s.summary["final_mode"], 3);
  const auto& pd = s.summary["phase_durations_s"];
  for (const char* phase : {"acquisition", "extraction", "maneuvering", "docking"}) {
    ASSERT_TRUE(pd[phase].is_number()) << phase << ": " << pd.dump();
    EXPECT_GT(pd[phase].get<double>(), 0.5) << phase;
  }
  // Session time, not wall time: the whole task in about a minute of it
  // (the 4x run took a quarter of that).
  const double total = pd["acquisition"].get<double>() + pd["extraction"].get<double>() +
                       pd["maneuvering"].get<double>() + pd["docking"].get<double>();
  EXPECT_GT(total, 30.0);
  EXPECT_LT(total, 180.0);
  EXPECT_EQ(s.summary["held_frames"], 0);
  for (const auto& [kind, c] : s.summary["collisions_by_kind"].items())
    EXPECT_EQ(c["events"], 0) << kind;
  // The telemetry agrees: the last frames say docked, and the autopilot's
  // command is what the slave did all along.
  ASSERT_FALSE(s.telemetry.empty());
  EXPECT_TRUE(s.telemetry.back().docked);
  for (const auto& t : s.telemetry) ASSERT_FALSE(t.held);
}

}  // namespace
}  // namespace rms
