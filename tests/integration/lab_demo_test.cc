// scripts/lab demo as a user runs it (a short timeline): the session folder
// holds an LCM log of every channel that lcm-logplayer plays, each process's
// log, PNG frames, the session's video and summary.json.
#include <filesystem>
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <nlohmann/json.hpp>

#include "rms/esg_frame_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/channels.h"
#include "rms/wire/message_io.h"

#include "subprocess.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using testing::SourcePath;
using testing::Subprocess;

TEST(LabDemo, TheSessionFolderHoldsLogVideoFramesProcessLogsAndSummary) {
  const std::string tmp = testing::MakeTempDir("lab");
  const std::string out = tmp + "/session";
  const std::string url = testing::UniqueLcmUrl(8000);
  Subprocess lab({SourcePath("scripts/lab"), "demo", "--no-build", "--out", out, "--timeline",
                  SourcePath("scripts/timelines/short.tl"), "--lcm-url", url, "--png-every", "30",
                  "--width", "320", "--height", "240"},
                 tmp + "/lab.log", {std::string("RMSLAB_BUILD=") + RMSLAB_BUILD_DIR});
  ASSERT_EQ(lab.Wait(120), 0) << testing::ReadFile(tmp + "/lab.log");

  // Process logs.
  for (const char* p :
       {"operator_station", "dynamics_proc", "scene_proc", "esg_renderer", "lcm-logger"}) {
    EXPECT_TRUE(fs::exists(out + "/logs/" + p + ".log")) << p;
  }
  EXPECT_NE(testing::ReadFile(out + "/logs/esg_renderer.log").find("rendered"), std::string::npos);

  // PNG frames: 91 frames, every 30th -> frames 0, 30, 60, 90.
  int pngs = 0;
  for (const auto& e : fs::directory_iterator(out + "/frames"))
    pngs += e.path().extension() == ".png";
  EXPECT_GE(pngs, 3);

  // The session's video: one frame per frame number, at the render size.
  ASSERT_TRUE(fs::exists(out + "/session.mp4"));
  {
    Subprocess probe({"/usr/bin/ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0",
                      "-show_entries", "stream=nb_read_frames,width,height", "-of", "csv=p=0",
                      out + "/session.mp4"},
                     tmp + "/ffprobe.log");
    ASSERT_EQ(probe.Wait(60), 0) << testing::ReadFile(tmp + "/ffprobe.log");
    EXPECT_EQ(testing::ReadFile(tmp + "/ffprobe.log"), "320,240,91\n");
  }

  // The LCM log holds every channel.
  std::map<std::string, int> by_channel;
  {
    lcm::LogFile log(out + "/lcmlog", "r");
    ASSERT_TRUE(log.good());
    while (const lcm::LogEvent* ev = log.readNextEvent()) ++by_channel[ev->channel];
  }
  EXPECT_GE(by_channel[wire::channels::kOperatorInput], 85);
  EXPECT_GE(by_channel[wire::channels::kDcpFrame], 85);
  EXPECT_GE(by_channel[wire::channels::kEsgFrame], 85);
  EXPECT_GE(by_channel[wire::channels::kStatus], 4);  // at least every process's final report

  // summary.json
  const auto s = nlohmann::json::parse(testing::ReadFile(out + "/summary.json"));
  EXPECT_EQ(s["final_mode"], 1);
  EXPECT_EQ(s["frames"]["operator_published"], 91);
  EXPECT_GE(s["frames"]["rendered"].get<int>(), 85);
  EXPECT_EQ(s["frames"]["png_written"], pngs);
  EXPECT_EQ(s["frames"]["video_frames"], 91);
  EXPECT_EQ(s["frames"]["video_dropped"], 0);
  EXPECT_EQ(s["frames"]["scenes_drawn"].get<int>() + s["frames"]["skipped_unchanged"].get<int>(),
            s["frames"]["rendered"].get<int>());
  EXPECT_EQ(s["log"]["esg_frames"], by_channel[wire::channels::kEsgFrame]);
  EXPECT_TRUE(s["frames"]["dropped"].contains("scene_to_esg"));
  EXPECT_TRUE(s["latency"].contains("input_to_render"));
  EXPECT_EQ(s["log"]["final_status_from"].size(), 4u);

  // lcm-logplayer plays the log: a listener on another port receives the ESG frames.
  const std::string play_url = testing::UniqueLcmUrl(8100);
  transport::LcmOptions o;
  o.url = play_url;
  transport::UdpLcm lcm(o);
  int esg_frames = 0;
  lcm.Subscribe(wire::channels::kEsgFrame, [&](const void* d, int n, std::int64_t) {
    esg_frame_t m;
    esg_frames += wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone;
  });
  Subprocess player({"/usr/bin/lcm-logplayer", "-s", "10", "-l", play_url, out + "/lcmlog"},
                    tmp + "/player.log");
  while (player.Running()) lcm.HandleSubscriptions(20);
  for (int i = 0; i < 10; ++i) lcm.HandleSubscriptions(20);
  EXPECT_EQ(player.Wait(1), 0) << testing::ReadFile(tmp + "/player.log");
  EXPECT_GE(esg_frames, by_channel[wire::channels::kEsgFrame] - 2);
  fs::remove_all(tmp);
}

}  // namespace
}  // namespace rms
