// A session across hosts: four network namespaces joined by veth pairs to a
// bridge (scripts/netns-lab) stand for a lab's machines; a lab file puts
// each process on its own host and scripts/lab demo runs the whole task
// across them over multicast with TTL 1.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "netns_lab.h"
#include "subprocess.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using testing::NetnsLab;
using testing::ReadFile;
using testing::SourcePath;
using testing::Subprocess;

// A lab file with one process a host (the recorder beside the operator
// station), on a group and port of its own, TTL 1.
std::string WriteLabFile(const NetnsLab& net, const std::string& dir) {
  std::string lab_file = dir + "/lab.toml";
  std::ofstream(lab_file) << "[hosts]\n"
                          << "operator_station = \"" << net.host(1) << "\"\n"
                          << "dynamics_proc = \"" << net.host(2) << "\"\n"
                          << "scene_proc = \"" << net.host(3) << "\"\n"
                          << "esg_renderer = \"" << net.host(4) << "\"\n"
                          << "recorder = \"" << net.host(1) << "\"\n"
                          << "[lcm]\ngroup = \"239.255.76.68\"\nport = 7668\nttl = "
                             "1\n[remote]\nroot = \"\"\nbuild = \"\"\n";
  return lab_file;
}

// scripts/lab demo across the lab's hosts: the autopilot at 4x, small frames.
Subprocess FlyAcross(const std::string& lab_file, const std::string& dir) {
  return Subprocess({SourcePath("scripts/lab"), "demo", "--no-build", "--lab", lab_file, "--out",
                     dir + "/session", "--speed", "4", "--png-every", "0", "--no-video", "--width",
                     "160", "--height", "120"},
                    dir + "/lab.log", {std::string("RMSLAB_BUILD=") + RMSLAB_BUILD_DIR});
}

TEST(MultiHost, ASessionRunsAcrossNamespaceHosts) {
  const std::string dir = testing::MakeTempDir("hosts");
  NetnsLab net("rt" + std::to_string(getpid() % 100000), dir);
  ASSERT_TRUE(net.ok()) << "network namespaces could not be made (root, iproute2):\n"
                        << ReadFile(dir + "/netns.log");
  const std::string lab_file = WriteLabFile(net, dir);
  Subprocess lab = FlyAcross(lab_file, dir);
  ASSERT_EQ(lab.Wait(300), 0) << ReadFile(dir + "/lab.log");
  const auto m = nlohmann::json::parse(ReadFile(dir + "/session/manifest.json"));
  EXPECT_EQ(m["hosts"]["dynamics_proc"], net.host(2));
  EXPECT_EQ(m["hosts"]["esg_renderer"], net.host(4));
  EXPECT_NE(m["lcm"]["url"].get<std::string>().find("ttl=1"), std::string::npos);
  const auto s = nlohmann::json::parse(ReadFile(dir + "/session/summary.json"));
  EXPECT_TRUE(s["docked"].get<bool>());
  // Every frame crossed from host to host: published, received, rendered --
  // or, on a loaded machine, counted as too late to act on where it
  // arrived (never lost on the way: no host's link loses here).
  const int published = s["frames"]["operator_published"];
  EXPECT_GT(published, 1000);
  const auto& tm = s["timing"];
  const int dcp_late = tm["dynamics_proc"]["too_late_dropped"],
            scene_late = tm["scene_proc"]["too_late_dropped"],
            esg_late = tm["esg_renderer"]["too_late_dropped"];
  EXPECT_EQ(s["frames"]["dcp_published"].get<int>() + dcp_late, published) << tm.dump();
  EXPECT_EQ(s["frames"]["esg_published"].get<int>() + scene_late,
            s["frames"]["dcp_published"].get<int>())
      << tm.dump();
  EXPECT_EQ(s["frames"]["rendered"].get<int>() + s["frames"]["superseded"].get<int>() + esg_late,
            s["frames"]["esg_published"].get<int>())
      << tm.dump();
  EXPECT_LE(dcp_late + scene_late + esg_late, published / 100) << tm.dump();
  EXPECT_EQ(s["timing"]["dynamics_proc"]["dropped_frames"], 0);
  EXPECT_EQ(s["log"]["final_status_from"].size(), 4u);
  EXPECT_NE(ReadFile(dir + "/lab.log").find("hosts checked"), std::string::npos);
  // Each host's process journaled what it published into the session's
  // folder: the record lost nothing, it re-simulates, and another design of
  // it can be flown (docs/sessions.md "The record", "Re-simulation").
  EXPECT_EQ(s["record"]["source"], "journals");
  EXPECT_EQ(s["record"]["lost"], 0) << s["record"].dump();
  EXPECT_EQ(s["resimulation"]["verdict"], "identical") << s["resimulation"].dump();
  const auto other = testing::Script({SourcePath("scripts/lab"), "resim", dir + "/session",
                                      "--no-build", "--set", "dcp.tpob_ft=0.4"},
                                     dir + "/resim_set.log");
  EXPECT_EQ(other.rc, 0) << other.out;
  // A host that is not there is refused before anything starts.
  std::string bad = ReadFile(lab_file);
  bad.replace(bad.find(net.host(3)), net.host(3).size(), "netns:no-such-host");
  std::ofstream(dir + "/bad.toml") << bad;
  Subprocess refused({SourcePath("scripts/lab"), "demo", "--no-build", "--lab", dir + "/bad.toml",
                      "--out", dir + "/never"},
                     dir + "/bad.log", {std::string("RMSLAB_BUILD=") + RMSLAB_BUILD_DIR});
  EXPECT_NE(refused.Wait(60), 0);
  EXPECT_NE(ReadFile(dir + "/bad.log").find("netns:no-such-host: no such network namespace"),
            std::string::npos)
      << ReadFile(dir + "/bad.log");
  EXPECT_FALSE(fs::exists(dir + "/never/lcmlog"));
  net.Down();
  fs::remove_all(dir);
}

// Lossy links (docs/sessions.md "Lossy links"): the DCP's host loses 5 % of
// what it sends and of what it receives and duplicates 1 % (scripts/netns-lab
// impair: tc netem, or nftables where the kernel has no netem). Frame
// numbers detect every frame lost; duplicates are dropped; the scene and the
// ESG carry on from the last good frame; the autopilot still docks.
TEST(MultiHost, OverALossyLinkEveryGapIsCountedAndTheAutopilotStillDocks) {
  const std::string dir = testing::MakeTempDir("lossy");
  NetnsLab net("ls" + std::to_string(getpid() % 100000), dir);
  ASSERT_TRUE(net.ok()) << ReadFile(dir + "/netns.log");
  const std::string prefix = net.host(1).substr(6, net.host(1).size() - 8);
  Subprocess impair({SourcePath("scripts/netns-lab"), "impair", prefix, "2", "loss=5", "dup=1"},
                    dir + "/impair.log");
  ASSERT_EQ(impair.Wait(30), 0) << ReadFile(dir + "/impair.log");
  std::printf("%s", ReadFile(dir + "/impair.log").c_str());
  const std::string lab_file = WriteLabFile(net, dir);
  Subprocess lab = FlyAcross(lab_file, dir);
  ASSERT_EQ(lab.Wait(300), 0) << ReadFile(dir + "/lab.log");
  const auto s = nlohmann::json::parse(ReadFile(dir + "/session/summary.json"));
  EXPECT_TRUE(s["docked"].get<bool>()) << ReadFile(dir + "/lab.log");
  const auto dcp =
      nlohmann::json::parse(ReadFile(dir + "/session/stats/dynamics_proc.json"))["counters"];
  const auto scene =
      nlohmann::json::parse(ReadFile(dir + "/session/stats/scene_proc.json"))["counters"];
  const long op_sent = s["frames"]["operator_published"], dcp_sent = s["frames"]["dcp_published"],
             scene_sent = s["frames"]["esg_published"];
  const long dcp_missing = dcp.value("input.missing", 0L),
             scene_missing = scene.value("dcp.missing", 0L);
  const long dups = dcp.value("dropped.duplicate", 0L) + scene.value("dropped.duplicate", 0L);
  std::printf(
      "operator frames %ld -> DCP processed %ld (counted missing %ld); DCP frames %ld -> scene %ld "
      "(counted "
      "missing %ld); duplicates dropped %ld\n",
      op_sent, dcp_sent, dcp_missing, dcp_sent, scene_sent, scene_missing, dups);
  // Frames were lost both ways, and every one was seen missing (but the
  // last ones, which no later frame reveals).
  EXPECT_GT(op_sent - dcp_sent, 0);
  EXPECT_GT(dcp_sent - scene_sent, 0);
  EXPECT_NEAR(static_cast<double>(dcp_missing), static_cast<double>(op_sent - dcp_sent), 2.0);
  // A DCP frame that reached the scene too late to act on (a loaded
  // machine) makes no ESG frame either, and is counted as such.
  const long scene_late = scene.value("dropped.late", 0L) + scene.value("dropped.far_ahead", 0L);
  EXPECT_NEAR(static_cast<double>(scene_missing + scene_late),
              static_cast<double>(dcp_sent - scene_sent), 2.0)
      << "scene_proc's counters: " << scene.dump();
  EXPECT_GT(dups, 0);
  // The ESG drew every frame the scene sent (the picture stays on the last
  // good frame through a gap), or counted it: superseded, or too late to
  // draw on a loaded machine. (Its own count of missing frames holds the
  // DCP frames the scene never had: an ESG frame is numbered as its DCP frame.)
  const auto& esg = s["timing"]["esg_renderer"];
  EXPECT_EQ(s["frames"]["rendered"].get<long>() + s["frames"]["superseded"].get<long>() +
                esg["too_late_dropped"].get<long>(),
            scene_sent)
      << esg.dump();
  // Losses on the wire are the wire's: the record holds every frame sent,
  // and the DCP's answers to the inputs that reached it re-simulate.
  EXPECT_EQ(s["record"]["lost"], 0) << s["record"].dump();
  EXPECT_EQ(s["resimulation"]["verdict"], "identical") << s["resimulation"].dump();
  net.Down();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rms
