// scripts/lab demo as a user runs it (a short timeline): the session folder
// holds an LCM log of every channel that lcm-logplayer plays, each process's
// log, PNG frames, the session's video and summary.json.
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <nlohmann/json.hpp>

#include "rms/base/cpu_wake_latency.h"
#include "rms/esg_frame_t.hpp"
#include "rms/sender_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/channels.h"
#include "rms/wire/message_auth.h"
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
  // While it runs, the renderer holds the CPUs' wake latency the launcher
  // asked for by default (0 us) open -- where this machine lets it
  // (docs/performance.md "Wake latency").
  const bool device_writable = access(kCpuWakeLatencyDevice, W_OK) == 0;
  std::printf("%s is %swritable here\n", kCpuWakeLatencyDevice, device_writable ? "" : "not ");
  bool seen_open = false;
  if (testing::WaitForFile(out + "/run/esg_renderer.ready", 60)) {
    const auto ready = nlohmann::json::parse(testing::ReadFile(out + "/run/esg_renderer.ready"));
    const std::string fds = "/proc/" + std::to_string(ready["pid"].get<int>()) + "/fd";
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(fds, ec))
      seen_open = seen_open || fs::read_symlink(e.path(), ec) == kCpuWakeLatencyDevice;
  }
  ASSERT_EQ(lab.Wait(120), 0) << testing::ReadFile(tmp + "/lab.log");
  const std::string lab_log = testing::ReadFile(tmp + "/lab.log");
  for (const char* p : {"dynamics_proc", "scene_proc", "esg_renderer", "operator_station"}) {
    const auto ready =
        nlohmann::json::parse(testing::ReadFile(out + "/run/" + std::string(p) + ".ready"));
    const std::string state = ready["cpu_wake_latency"];
    if (device_writable) {
      EXPECT_EQ(state, "held at 0 us (/dev/cpu_dma_latency)") << p;
    } else {
      EXPECT_EQ(state.rfind("not held at 0 us: /dev/cpu_dma_latency: ", 0), 0u)
          << p << ": " << state;
    }
  }
  // The summary says it, by process, and after the latency.
  const auto summary = nlohmann::json::parse(testing::ReadFile(out + "/summary.json"));
  for (const char* p : {"dynamics_proc", "scene_proc", "esg_renderer", "operator_station"}) {
    const auto ready =
        nlohmann::json::parse(testing::ReadFile(out + "/run/" + std::string(p) + ".ready"));
    EXPECT_EQ(summary["timing"]["cpu_wake_latency"][p], ready["cpu_wake_latency"]) << p;
  }
  if (device_writable) {
    EXPECT_NE(lab_log.find(" ms; the CPUs' wake latency held at 0 us\n"), std::string::npos)
        << lab_log;
    EXPECT_TRUE(seen_open) << "esg_renderer did not hold " << kCpuWakeLatencyDevice << " open";
    EXPECT_EQ(lab_log.find("wake latency is not held"), std::string::npos) << lab_log;
  } else {
    EXPECT_NE(lab_log.find("the CPUs' wake latency is not held at 0 us on this host ("),
              std::string::npos)
        << lab_log;
  }

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
  // Every ESG frame rendered, or accounted for: superseded by a newer one,
  // too late to draw, or never received (a loaded machine's renderer
  // supersedes some; most are drawn).
  const auto& esg = s["timing"]["esg_renderer"];
  EXPECT_GE(s["frames"]["rendered"].get<int>() + s["frames"]["superseded"].get<int>() +
                esg["too_late_dropped"].get<int>() + esg["dropped_frames"].get<int>(),
            s["frames"]["esg_published"].get<int>())
      << s["frames"].dump() << esg.dump();
  EXPECT_GE(s["frames"]["rendered"].get<int>(), 45) << s["frames"].dump();
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
  // As one of the session's tools: its id, and its key to check each tag.
  lcm.SetSender({transport::ParseSessionId(
                     nlohmann::json::parse(testing::ReadFile(out + "/manifest.json"))["session_id"],
                     "session_id"),
                 sender_t::PROCESS_TOOL, 1});
  lcm.SetKey(wire::ReadSessionKeyFile(out + "/run/session.key"));
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

// --cpu-wake-latency-us: off leaves the processes' idle CPUs to the system
// (their ready files say so); a bad value is refused before anything starts;
// a process given a bad request by hand says which variable is wrong.
TEST(LabDemo, TheWakeLatencyRequestIsOffWhenAskedAndABadOneIsRefusedNamingIt) {
  const std::string tmp = testing::MakeTempDir("lab_wake");
  // Runs argv to its end: its exit code, and its output in `*output`.
  const auto run = [&](const std::vector<std::string>& argv, const std::string& name,
                       const std::vector<std::string>& env, std::string* output) {
    Subprocess p(argv, tmp + "/" + name + ".log", env);
    const int rc = p.Wait(120);
    *output = testing::ReadFile(tmp + "/" + name + ".log");
    return rc;
  };
  const std::vector<std::string> env = {std::string("RMSLAB_BUILD=") + RMSLAB_BUILD_DIR};
  std::string output;
  // Not ASCII digits (an Arabic-Indic three, a superscript two, 5,000 digits), or out of range.
  for (const std::string& bad : std::vector<std::string>{"12us", "\xd9\xa3", "\xc2\xb2",
                                                         std::string(5000, '1'), "1000001"}) {
    EXPECT_EQ(run({SourcePath("scripts/lab"), "demo", "--no-build", "--out", tmp + "/refused",
                   "--cpu-wake-latency-us", bad},
                  "refused", env, &output),
              2)
        << output;
    // A long value is shown cut to its first 40 characters.
    const std::string shown = bad.size() > 40 ? bad.substr(0, 40) + "..." : bad;
    EXPECT_NE(output.find("--cpu-wake-latency-us '" + shown +
                          "': \"off\" or whole microseconds, at most 7 digits"),
              std::string::npos)
        << output;
    EXPECT_FALSE(fs::exists(tmp + "/refused"));
  }

  // A request left in the shell is the launcher's to set, not the session's.
  std::vector<std::string> with_leftover = env;
  with_leftover.push_back("RMSLAB_CPU_WAKE_LATENCY_US=abc");
  const std::string out = tmp + "/session";
  ASSERT_EQ(run({SourcePath("scripts/lab"), "demo", "--no-build", "--out", out, "--timeline",
                 SourcePath("scripts/timelines/short.tl"), "--lcm-url", testing::UniqueLcmUrl(8200),
                 "--png-every", "0", "--no-video", "--width", "320", "--height", "240",
                 "--cpu-wake-latency-us", "off"},
                "off", with_leftover, &output),
            0)
      << output;
  for (const char* p : {"dynamics_proc", "scene_proc", "esg_renderer"}) {
    const auto ready =
        nlohmann::json::parse(testing::ReadFile(out + "/run/" + std::string(p) + ".ready"));
    EXPECT_EQ(ready["cpu_wake_latency"], "off") << p;
  }
  EXPECT_EQ(output.find("wake latency is"), std::string::npos) << output;
  EXPECT_NE(output.find(" ms; the CPUs' wake latency off\n"), std::string::npos) << output;
  const auto off_summary = nlohmann::json::parse(testing::ReadFile(out + "/summary.json"));
  EXPECT_EQ(off_summary["timing"]["cpu_wake_latency"]["esg_renderer"], "off");

  // A process whose user may not write the device runs on and says why
  // (as root, this test runs one as nobody to see it).
  if (geteuid() == 0 && access("/usr/bin/setpriv", X_OK) == 0) {
    fs::permissions(tmp, fs::perms::all);
    // The configuration from where nobody may read it (a checkout under
    // /root, as in a container, is not).
    const std::string config = tmp + "/rmslab.toml";
    fs::copy_file(SourcePath("config/rmslab.toml"), config);
    fs::permissions(config, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
    const std::string ready = tmp + "/scene_proc.ready";
    Subprocess p({"/usr/bin/setpriv", "--reuid=65534", "--regid=65534", "--clear-groups",
                  std::string(RMSLAB_BUILD_DIR) + "/scene_proc/scene_proc", "--config", config,
                  "--lcm-url", testing::UniqueLcmUrl(8300), "--ready-file", ready},
                 tmp + "/nobody.log", {"RMSLAB_CPU_WAKE_LATENCY_US=0"});
    ASSERT_TRUE(testing::WaitForFile(ready, 30)) << testing::ReadFile(tmp + "/nobody.log");
    const auto said = nlohmann::json::parse(testing::ReadFile(ready));
    EXPECT_EQ(said["cpu_wake_latency"],
              "not held at 0 us: /dev/cpu_dma_latency: Permission denied");
    p.Signal(SIGINT);
    EXPECT_EQ(p.Wait(30), 0);
    EXPECT_NE(testing::ReadFile(tmp + "/nobody.log")
                  .find("[warning] cpu wake latency: not held at 0 us: /dev/cpu_dma_latency: "
                        "Permission denied: frames reach the pixels later"),
              std::string::npos)
        << testing::ReadFile(tmp + "/nobody.log");
  }

  EXPECT_EQ(run({std::string(RMSLAB_BUILD_DIR) + "/scene_proc/scene_proc", "--check"}, "check",
                {"RMSLAB_CPU_WAKE_LATENCY_US=-5"}, &output),
            2)
      << output;
  EXPECT_NE(output.find("RMSLAB_CPU_WAKE_LATENCY_US='-5': must be \"off\" or a whole number"),
            std::string::npos)
      << output;
  fs::remove_all(tmp);
}

}  // namespace
}  // namespace rms
