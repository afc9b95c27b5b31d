// The four real executables over real LCM (UDP multicast on loopback): ESG
// frames arrive in order, each at most 64 valid 24-bit words, and the
// renderer's images show the arm where the kinematics put it.
#include <signal.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <map>

#include "rms/arm/kinematics.h"
#include "rms/base/config.h"
#include "rms/esg_frame_t.hpp"
#include "rms/esg_renderer/png_io.h"
#include "rms/esg_renderer/renderer.h"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/channels.h"
#include "rms/wire/message_io.h"
#include "rms/wire/word_blocks.h"

#include "pinhole.h"
#include "subprocess.h"

namespace rms {
namespace {

using testing::BuildPath;
using testing::SourcePath;
using testing::Subprocess;

using testing::Project;

class Session : public ::testing::Test {
 protected:
  Session() : dir(testing::MakeTempDir("session")), url(testing::UniqueLcmUrl(7900)) {}
  ~Session() override { std::filesystem::remove_all(dir); }

  std::unique_ptr<Subprocess> Start(const std::string& name, std::vector<std::string> args) {
    std::vector<std::string> argv = {BuildPath(name + "/" + name),
                                     "--lcm-url",
                                     url,
                                     "--stats",
                                     dir + "/" + name + ".json",
                                     "--ready-file",
                                     dir + "/" + name + ".ready"};
    argv.insert(argv.end(), args.begin(), args.end());
    return std::make_unique<Subprocess>(argv, dir + "/" + name + ".log");
  }

  std::string dir;
  std::string url;
  LabConfig config = LoadConfig(DefaultConfigPath());
};

TEST_F(Session, FourProcessesOverLcmRenderTheArmWhereTheKinematicsPutIt) {
  constexpr int kW = 320, kH = 240;
  auto esg = Start("esg_renderer", {"--png-dir", dir + "/png", "--png-every", "10", "--id-colors",
                                    "--width", std::to_string(kW), "--height", std::to_string(kH)});
  auto scene = Start("scene_proc", {});
  auto dcp = Start("dynamics_proc", {});
  for (const char* p : {"esg_renderer", "scene_proc", "dynamics_proc"}) {
    ASSERT_TRUE(testing::WaitForFile(dir + "/" + p + ".ready", 15))
        << p << ":\n"
        << testing::ReadFile(dir + "/" + p + ".log");
  }

  // This test listens to the ESG frames too, over the same real LCM.
  transport::LcmOptions o;
  o.url = url;
  transport::UdpLcm lcm(o);
  std::vector<esg_frame_t> frames;
  int malformed = 0;
  lcm.Subscribe(wire::channels::kEsgFrame, [&](const void* d, int n, std::int64_t) {
    esg_frame_t m;
    if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone) {
      frames.push_back(std::move(m));
    } else {
      ++malformed;
    }
  });
  lcm.HandleSubscriptions(0);

  Subprocess op(
      {BuildPath("operator_station/operator_station"), "--lcm-url", url, "--timeline",
       SourcePath("scripts/timelines/short.tl"), "--stats", dir + "/operator_station.json"},
      dir + "/operator_station.log");
  while (op.Running()) lcm.HandleSubscriptions(20);
  ASSERT_EQ(op.Wait(1), 0) << testing::ReadFile(dir + "/operator_station.log");
  for (int i = 0; i < 25; ++i) lcm.HandleSubscriptions(20);  // the last frames in flight
  for (auto* p : {dcp.get(), scene.get(), esg.get()}) p->Signal(SIGINT);
  EXPECT_EQ(dcp->Wait(10), 0) << testing::ReadFile(dir + "/dynamics_proc.log");
  EXPECT_EQ(scene->Wait(10), 0) << testing::ReadFile(dir + "/scene_proc.log");
  EXPECT_EQ(esg->Wait(10), 0) << testing::ReadFile(dir + "/esg_renderer.log");

  // 3 s at 30 Hz: 91 frames (t = 0 .. 3.0 s). Loopback multicast loses none
  // in practice; allow a few rather than fail on a hiccup.
  EXPECT_EQ(malformed, 0);
  ASSERT_GE(frames.size(), 85u);
  std::map<std::int64_t, wire::EsgFrameData> by_frame;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const esg_frame_t& m = frames[i];
    if (i > 0) {
      ASSERT_GT(m.frame, frames[i - 1].frame) << "ESG frames out of order";
    }
    ASSERT_GE(m.num_words, 1);
    ASSERT_LE(m.num_words, 64);
    ASSERT_EQ(static_cast<std::size_t>(m.num_words), m.words.size());
    for (std::int32_t w : m.words) ASSERT_EQ(static_cast<std::uint32_t>(w) >> 24, 0u);
    by_frame[m.frame] = wire::UnpackEsgWords(m.words);
  }

  // Every PNG: the booms' midpoints, projected from the frame's own words,
  // land on pixels of the booms' identity colours.
  int checked = 0;
  std::vector<std::pair<int, int>> boom_pixels;
  for (const auto& entry : std::filesystem::directory_iterator(dir + "/png")) {
    const std::string name = entry.path().filename().string();
    const std::int64_t frame = std::stoll(name.substr(6, 6));
    auto it = by_frame.find(frame);
    if (it == by_frame.end()) continue;  // this test missed that frame on the wire
    const wire::EsgFrameData& f = it->second;
    const esg_renderer::Image img = esg_renderer::ReadPng(entry.path().string());
    ASSERT_EQ(img.width, kW);
    ASSERT_EQ(img.height, kH);
    const arm::ArmPose arm = arm::ComputeArmPose(config.arm, f.arm, f.shoulder_height_ft);
    for (const auto& [p, id] :
         {std::pair{0.5 * (arm.p_RoS_R + arm.p_RoE_R), scene_model::kUpperBoom},
          std::pair{0.5 * (arm.p_RoE_R + arm.p_RoW_R), scene_model::kLowerBoom}}) {
      int x = 0, y = 0;
      ASSERT_TRUE(Project(f, p, kW, kH, &x, &y)) << name;
      const std::uint8_t* px = img.at(x, y);
      const scene_model::Rgb want = esg_renderer::IdColor(id);
      EXPECT_TRUE(px[0] == want[0] && px[1] == want[1] && px[2] == want[2])
          << name << ": " << scene_model::ClusterName(id) << " expected at (" << x << ", " << y
          << "), found rgb " << int(px[0]) << "," << int(px[1]) << "," << int(px[2]);
      if (id == scene_model::kLowerBoom) boom_pixels.emplace_back(x, y);
    }
    ++checked;
  }
  EXPECT_GE(checked, 8);
  // The timeline swings the arm: the lower boom's pixel moves.
  ASSERT_GE(boom_pixels.size(), 2u);
  const auto [x0, y0] = boom_pixels.front();
  bool moved = false;
  double farthest = 0;
  for (const auto& [x, y] : boom_pixels) farthest = std::max(farthest, std::hypot(x - x0, y - y0));
  moved = farthest > 5;
  std::printf("lower boom midpoint moved up to %.1f px over %d images\n", farthest, checked);
  EXPECT_TRUE(moved);
}

TEST_F(Session, EveryExecutableExplainsItselfAndRefusesABadConfig) {
  const std::string bad = dir + "/bad.toml";
  {
    std::ofstream f(bad);
    f << testing::ReadFile(DefaultConfigPath());
    f << "\n[extra]\nvalue = 1\n";
  }
  for (const char* exe : {"operator_station", "dynamics_proc", "scene_proc", "esg_renderer"}) {
    Subprocess help({BuildPath(std::string(exe) + "/" + exe), "--help"}, dir + "/help.log");
    EXPECT_EQ(help.Wait(10), 0) << exe;
    const std::string h = testing::ReadFile(dir + "/help.log");
    EXPECT_NE(h.find("--lcm-url"), std::string::npos) << exe << h;
    EXPECT_NE(h.find("--config"), std::string::npos) << exe << h;

    std::vector<std::string> argv = {BuildPath(std::string(exe) + "/" + exe), "--config", bad,
                                     "--lcm-url", url};
    if (std::string(exe) == "operator_station") {
      argv.insert(argv.end(), {"--timeline", SourcePath("scripts/timelines/short.tl")});
    }
    Subprocess p(argv, dir + "/bad.log");
    EXPECT_EQ(p.Wait(10), 2) << exe;
    const std::string log = testing::ReadFile(dir + "/bad.log");
    EXPECT_NE(log.find("key 'extra': unknown key"), std::string::npos) << exe << ": " << log;
  }
}

}  // namespace
}  // namespace rms
