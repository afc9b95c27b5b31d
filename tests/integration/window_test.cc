// The operator's live window under Xvfb: esg_renderer --window opens a
// window on the X display and shows the frame it rendered. The window's
// pixels are read back from the X server (xwd) and compared with the PNG of
// the same frame.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "lab_processes.h"
#include "rms/lcm_interface.h"
#include "subprocess.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using testing::Subprocess;

// A private X server on a display number nobody holds.
class Xvfb {
 public:
  explicit Xvfb(const std::string& dir) {
    for (int n = 100 + getpid() % 400; n < 1000; ++n) {
      if (fs::exists("/tmp/.X11-unix/X" + std::to_string(n)) || fs::exists("/tmp/.X" + std::to_string(n) + "-lock")) {
        continue;
      }
      display_ = std::string(":").append(std::to_string(n));
      server_ = std::make_unique<Subprocess>(
          std::vector<std::string>{"/usr/bin/Xvfb", display_, "-screen", "0", "640x480x24", "-nolisten", "tcp"},
          dir + "/xvfb.log");
      if (testing::WaitForFile("/tmp/.X11-unix/X" + std::to_string(n), 10)) return;
      server_.reset();
    }
    display_.clear();
  }
  const std::string& display() const { return display_; }

 private:
  std::string display_;
  std::unique_ptr<Subprocess> server_;
};

// An image file (PNG or XWD) as rgb24 bytes, decoded by ffmpeg.
std::vector<unsigned char> DecodeRgb(const std::string& path, const std::string& tmp) {
  const std::string raw = tmp + "/" + fs::path(path).filename().string() + ".rgb";
  Subprocess ff({"/usr/bin/ffmpeg", "-v", "error", "-y", "-i", path, "-f", "rawvideo", "-pix_fmt", "rgb24", raw},
                raw + ".log");
  EXPECT_EQ(ff.Wait(30), 0) << testing::ReadFile(raw + ".log");
  std::ifstream in(raw, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

TEST(LiveWindow, OpensUnderXvfbAndShowsTheRenderedFrame) {
  const std::string dir = testing::MakeTempDir("window");
  Xvfb x(dir);
  ASSERT_FALSE(x.display().empty()) << "Xvfb did not start:\n" << testing::ReadFile(dir + "/xvfb.log");

  const int w = 160, h = 120;
  testing::LabProcesses lab(dir, testing::UniqueLcmUrl(8700),
                            {"--width", std::to_string(w), "--height", std::to_string(h), "--window", "--png-dir",
                             dir + "/frames", "--png-every", "1"});
  lab.set_esg_env({"DISPLAY=" + x.display()});
  std::string error;
  ASSERT_TRUE(lab.Start(&error)) << error;
  LcmOptions o;
  o.url = lab.url();
  UdpLcm lcm(o);
  ASSERT_EQ(lab.Fly(lcm, testing::SourcePath("scripts/timelines/short.tl")), 0);

  // The window, by its title, read from the X server while it still shows
  // the session's last frame.
  Subprocess xwd({"/usr/bin/xwd", "-display", x.display(), "-name", "rmslab ESG", "-silent", "-out", dir + "/window.xwd"},
                 dir + "/xwd.log");
  ASSERT_EQ(xwd.Wait(20), 0) << testing::ReadFile(dir + "/xwd.log");
  ASSERT_TRUE(lab.Stop(&error)) << error;

  // The last frame written as PNG is the one on screen.
  std::string last_png;
  for (const auto& e : fs::directory_iterator(dir + "/frames")) {
    if (e.path().string() > last_png) last_png = e.path().string();
  }
  ASSERT_FALSE(last_png.empty());
  const auto shown = DecodeRgb(dir + "/window.xwd", dir);
  const auto rendered = DecodeRgb(last_png, dir);
  ASSERT_EQ(shown.size(), static_cast<std::size_t>(w * h * 3)) << "the window is not " << w << "x" << h;
  ASSERT_EQ(rendered.size(), shown.size());
  int differing = 0, lit = 0;
  for (std::size_t i = 0; i < shown.size(); i += 3) {
    differing += shown[i] != rendered[i] || shown[i + 1] != rendered[i + 1] || shown[i + 2] != rendered[i + 2];
    lit += shown[i] + shown[i + 1] + shown[i + 2] > 0;
  }
  EXPECT_EQ(differing, 0) << "pixels where the window differs from " << last_png;
  EXPECT_GT(lit, w * h / 4) << "the window is mostly black";

  const auto stats = nlohmann::json::parse(testing::ReadFile(dir + "/esg_renderer.json"));
  EXPECT_GE(stats["counters"]["window.frames"].get<int>(), 85);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rms
