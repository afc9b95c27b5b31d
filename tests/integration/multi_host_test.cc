// A session across hosts: four network namespaces joined by veth pairs to a
// bridge (scripts/netns-lab) stand for a lab's machines; a lab file puts
// each process on its own host and scripts/lab demo runs the whole task
// across them over multicast with TTL 1.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "subprocess.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using testing::ReadFile;
using testing::SourcePath;
using testing::Subprocess;

class NetnsLab {
 public:
  NetnsLab(std::string prefix, std::string dir) : prefix_(std::move(prefix)), dir_(std::move(dir)) {
    Subprocess up({SourcePath("scripts/netns-lab"), "up", prefix_, "4"}, dir_ + "/netns.log");
    ok_ = up.Wait(60) == 0;
  }
  ~NetnsLab() { Down(); }
  void Down() {
    if (down_) return;
    down_ = true;
    Subprocess down({SourcePath("scripts/netns-lab"), "down", prefix_}, "/dev/null");
    down.Wait(60);
  }
  bool ok() const { return ok_; }
  std::string host(int i) const { return "netns:" + prefix_ + "-" + std::to_string(i); }

 private:
  std::string prefix_, dir_;
  bool ok_ = false, down_ = false;
};

TEST(MultiHost, ASessionRunsAcrossNamespaceHosts) {
  const std::string dir = testing::MakeTempDir("hosts");
  NetnsLab net("rt" + std::to_string(getpid() % 100000), dir);
  ASSERT_TRUE(net.ok()) << "network namespaces could not be made (root, iproute2):\n" << ReadFile(dir + "/netns.log");
  const std::string lab_file = dir + "/lab.toml";
  std::ofstream(lab_file) << "[hosts]\n"
                          << "operator_station = \"" << net.host(1) << "\"\n"
                          << "dynamics_proc = \"" << net.host(2) << "\"\n"
                          << "scene_proc = \"" << net.host(3) << "\"\n"
                          << "esg_renderer = \"" << net.host(4) << "\"\n"
                          << "recorder = \"" << net.host(1) << "\"\n"
                          << "[lcm]\nttl = 1\n[remote]\nroot = \"\"\nbuild = \"\"\n";
  Subprocess lab({SourcePath("scripts/lab"), "demo", "--no-build", "--lab", lab_file, "--out", dir + "/session", "--speed",
                  "4", "--png-every", "0", "--no-video", "--width", "160", "--height", "120"},
                 dir + "/lab.log", {std::string("RMSLAB_BUILD=") + RMSLAB_BUILD_DIR});
  ASSERT_EQ(lab.Wait(300), 0) << ReadFile(dir + "/lab.log");
  const auto m = nlohmann::json::parse(ReadFile(dir + "/session/manifest.json"));
  EXPECT_EQ(m["hosts"]["dynamics_proc"], net.host(2));
  EXPECT_EQ(m["hosts"]["esg_renderer"], net.host(4));
  EXPECT_NE(m["lcm"]["url"].get<std::string>().find("ttl=1"), std::string::npos);
  const auto s = nlohmann::json::parse(ReadFile(dir + "/session/summary.json"));
  EXPECT_TRUE(s["docked"].get<bool>());
  // Every frame crossed from host to host: published, received, rendered.
  const int published = s["frames"]["operator_published"];
  EXPECT_GT(published, 1000);
  EXPECT_EQ(s["frames"]["dcp_published"], published);
  EXPECT_EQ(s["frames"]["esg_published"], published);
  EXPECT_EQ(s["frames"]["rendered"].get<int>() + s["frames"]["superseded"].get<int>(), published);
  EXPECT_EQ(s["timing"]["dynamics_proc"]["dropped_frames"], 0);
  EXPECT_EQ(s["log"]["final_status_from"].size(), 4u);
  EXPECT_NE(ReadFile(dir + "/lab.log").find("hosts checked"), std::string::npos);
  // A host that is not there is refused before anything starts.
  std::string bad = ReadFile(lab_file);
  bad.replace(bad.find(net.host(3)), net.host(3).size(), "netns:no-such-host");
  std::ofstream(dir + "/bad.toml") << bad;
  Subprocess refused({SourcePath("scripts/lab"), "demo", "--no-build", "--lab", dir + "/bad.toml", "--out",
                      dir + "/never"},
                     dir + "/bad.log", {std::string("RMSLAB_BUILD=") + RMSLAB_BUILD_DIR});
  EXPECT_NE(refused.Wait(60), 0);
  EXPECT_NE(ReadFile(dir + "/bad.log").find("netns:no-such-host: no such network namespace"), std::string::npos)
      << ReadFile(dir + "/bad.log");
  EXPECT_FALSE(fs::exists(dir + "/never/lcmlog"));
  net.Down();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rms
