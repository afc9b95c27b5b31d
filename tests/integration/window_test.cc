// The operator's live window under Xvfb: esg_renderer --window opens a
// window on the X display and shows the frame it rendered (the window's
// pixels are read back from the X server with xwd and compared with the PNG
// of the same frame); and a person flies from it: keys held down in the
// window (synthetic key down / up through XTEST, xdotool) move the arm while
// held, and it stops within one frame of the release.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "rms/dcp_telemetry_t.hpp"
#include "rms/operator_input_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/window_keys_t.hpp"
#include "rms/wire/channels.h"
#include "rms/wire/message_io.h"

#include "lab_processes.h"
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
      if (fs::exists("/tmp/.X11-unix/X" + std::to_string(n)) ||
          fs::exists("/tmp/.X" + std::to_string(n) + "-lock")) {
        continue;
      }
      display_ = std::string(":").append(std::to_string(n));
      server_ = std::make_unique<Subprocess>(
          std::vector<std::string>{"/usr/bin/Xvfb", display_, "-screen", "0", "640x480x24",
                                   "-nolisten", "tcp"},
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
  Subprocess ff({"/usr/bin/ffmpeg", "-v", "error", "-y", "-i", path, "-f", "rawvideo", "-pix_fmt",
                 "rgb24", raw},
                raw + ".log");
  EXPECT_EQ(ff.Wait(30), 0) << testing::ReadFile(raw + ".log");
  std::ifstream in(raw, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

TEST(LiveWindow, OpensUnderXvfbAndShowsTheRenderedFrame) {
  const std::string dir = testing::MakeTempDir("window");
  Xvfb x(dir);
  ASSERT_FALSE(x.display().empty()) << "Xvfb did not start:\n"
                                    << testing::ReadFile(dir + "/xvfb.log");

  const int w = 160, h = 120;
  testing::LabProcesses lab(dir, testing::UniqueLcmUrl(8700),
                            {"--width", std::to_string(w), "--height", std::to_string(h),
                             "--window", "--png-dir", dir + "/frames", "--png-every", "1"});
  lab.set_esg_env({"DISPLAY=" + x.display()});
  std::string error;
  ASSERT_TRUE(lab.Start(&error)) << error;
  transport::LcmOptions o;
  o.url = lab.url();
  transport::UdpLcm lcm(o);
  ASSERT_EQ(lab.Fly(lcm, testing::SourcePath("scripts/timelines/short.tl")), 0);

  // The window, by its title, read from the X server while it still shows
  // the session's last frame.
  Subprocess xwd({"/usr/bin/xwd", "-display", x.display(), "-name", "rmslab ESG", "-silent", "-out",
                  dir + "/window.xwd"},
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
  ASSERT_EQ(shown.size(), static_cast<std::size_t>(w * h * 3))
      << "the window is not " << w << "x" << h;
  ASSERT_EQ(rendered.size(), shown.size());
  int differing = 0, lit = 0;
  for (std::size_t i = 0; i < shown.size(); i += 3) {
    differing += shown[i] != rendered[i] || shown[i + 1] != rendered[i + 1] ||
                 shown[i + 2] != rendered[i + 2];
    lit += shown[i] + shown[i + 1] + shown[i + 2] > 0;
  }
  EXPECT_EQ(differing, 0) << "pixels where the window differs from " << last_png;
  EXPECT_GT(lit, w * h / 4) << "the window is mostly black";

  const auto stats = nlohmann::json::parse(testing::ReadFile(dir + "/esg_renderer.json"));
  EXPECT_GE(stats["counters"]["window.frames"].get<int>(), 85);
  fs::remove_all(dir);
}

// xdotool against the display: 0 when it did what it was asked.
int Xdotool(const std::string& display, std::vector<std::string> args, const std::string& log) {
  args.insert(args.begin(), "/usr/bin/xdotool");
  Subprocess p(args, log, {"DISPLAY=" + display});
  return p.Wait(20);
}

TEST(LiveWindow, AKeyHeldInTheWindowMovesTheArmAndItStopsWithinAFrameOfTheRelease) {
  const std::string dir = testing::MakeTempDir("window_keys");
  Xvfb x(dir);
  ASSERT_FALSE(x.display().empty()) << "Xvfb did not start:\n"
                                    << testing::ReadFile(dir + "/xvfb.log");
  testing::LabProcesses lab(dir, testing::UniqueLcmUrl(8750),
                            {"--width", "320", "--height", "240", "--window"});
  lab.set_esg_env({"DISPLAY=" + x.display()});
  std::string error;
  ASSERT_TRUE(lab.Start(&error)) << error;
  transport::LcmOptions o;
  o.url = lab.url();
  transport::UdpLcm lcm(o);
  // What went out: each operator block's arm words (did the command move?)
  // and the window's key messages, in the order they were heard.
  struct Input {
    std::int64_t frame;
    bool moved;
  };
  std::vector<Input> inputs;
  std::vector<std::int32_t> last_words;
  std::int64_t release_seen_at_input = -1, hold_seen_at_input = -1;
  std::int64_t latest_input = -1;
  std::optional<dcp_telemetry_t> tm;
  lcm.Subscribe(wire::channels::kOperatorInput, [&](const void* d, int n, std::int64_t) {
    operator_input_t m;
    if (wire::SafeDecode(d, n, &m) != wire::DecodeError::kNone) return;
    const std::vector<std::int32_t> words(m.words, m.words + 6);
    inputs.push_back({m.frame, !last_words.empty() && words != last_words});
    last_words = words;
    latest_input = m.frame;
  });
  lcm.Subscribe(wire::channels::kWindowKeys, [&](const void* d, int n, std::int64_t) {
    window_keys_t m;
    if (wire::SafeDecode(d, n, &m) != wire::DecodeError::kNone) return;
    const bool r_held = std::find(m.held.begin(), m.held.end(), 'r') != m.held.end();
    if (r_held && hold_seen_at_input < 0) hold_seen_at_input = latest_input;
    if (!r_held && hold_seen_at_input >= 0 && release_seen_at_input < 0)
      release_seen_at_input = latest_input;
  });
  lcm.Subscribe(wire::channels::kDcpTelemetry, [&](const void* d, int n, std::int64_t) {
    dcp_telemetry_t m;
    if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone) tm = m;
  });
  auto pump = [&](double seconds) {
    const std::int64_t until = lcm.NowUs() + static_cast<std::int64_t>(seconds * 1e6);
    while (lcm.NowUs() < until) lcm.HandleSubscriptions(5);
  };
  // A person at the window: no terminal (stdin is not one), the window's keys.
  Subprocess op(
      {testing::BuildPath("operator_station/operator_station"), "--lcm-url", lab.url(), "--manual",
       "--window-keys", "--no-gamepad", "--no-spacemouse", "--stats", dir + "/op.json"},
      dir + "/op.log");
  for (int i = 0; i < 100 && !tm; ++i) pump(0.1);
  ASSERT_TRUE(tm.has_value()) << testing::ReadFile(dir + "/op.log");
  const std::string log = dir + "/xdotool.log";
  ASSERT_EQ(Xdotool(x.display(),
                    {"search", "--sync", "--name", "rmslab ESG", "windowfocus", "--sync"}, log),
            0)
      << testing::ReadFile(log);
  pump(0.5);
  const double z0 = tm->p_RoA_R_ft[2];
  // 'r' held for 1.5 s (up, in the end effector's frame: +Z_R from the start).
  ASSERT_EQ(Xdotool(x.display(), {"keydown", "r"}, log), 0) << testing::ReadFile(log);
  pump(1.5);
  ASSERT_EQ(Xdotool(x.display(), {"keyup", "r"}, log), 0) << testing::ReadFile(log);
  pump(1.5);
  const double z1 = tm->p_RoA_R_ft[2];
  ASSERT_GE(hold_seen_at_input, 0) << "the window never said 'r' was held";
  ASSERT_GE(release_seen_at_input, 0) << "the window never said 'r' was let go";
  // While held: it moved, at the coarse rate (2 ft/s) for about 1.5 s.
  int moved_while_held = 0, moved_after_release = 0;
  for (const Input& in : inputs) {
    if (in.frame > hold_seen_at_input && in.frame <= release_seen_at_input && in.moved)
      ++moved_while_held;
    if (in.frame > release_seen_at_input && in.moved) ++moved_after_release;
  }
  EXPECT_GT(moved_while_held, 30) << "frames the command moved while the key was held";
  EXPECT_NEAR(z1 - z0, 2.0 * (release_seen_at_input - hold_seen_at_input) / 30.0, 0.5);
  // Released: at most one more frame of motion (the one already on its way
  // when the window's message arrived).
  EXPECT_LE(moved_after_release, 1)
      << "frames the command still moved after the window said the key was up";
  // The window shows the operator's guidance panel (its text's colour at
  // the image's foot); the guidance key takes it away.
  auto panel_pixels = [&](const std::string& name) {
    Subprocess xwd({"/usr/bin/xwd", "-display", x.display(), "-name", "rmslab ESG", "-silent",
                    "-out", dir + "/" + name + ".xwd"},
                   dir + "/xwd.log");
    EXPECT_EQ(xwd.Wait(20), 0) << testing::ReadFile(dir + "/xwd.log");
    const auto rgb = DecodeRgb(dir + "/" + name + ".xwd", dir);
    int n = 0;
    for (std::size_t i = 0; i + 2 < rgb.size(); i += 3)
      n += rgb[i] == 120 && rgb[i + 1] == 230 && rgb[i + 2] == 255;
    return n;
  };
  EXPECT_GT(panel_pixels("with_guidance"), 200);
  ASSERT_EQ(Xdotool(x.display(), {"key", "g"}, log), 0) << testing::ReadFile(log);
  pump(0.5);
  EXPECT_EQ(panel_pixels("without_guidance"), 0);
  // Q from the window ends the station.
  ASSERT_EQ(Xdotool(x.display(), {"key", "Q"}, log), 0) << testing::ReadFile(log);
  EXPECT_EQ(op.Wait(10), 0) << testing::ReadFile(dir + "/op.log");
  const auto stats = nlohmann::json::parse(testing::ReadFile(dir + "/op.json"));
  EXPECT_EQ(stats["counters"]["key_actions"].get<int>(), 3);  // r, g, Q
  ASSERT_TRUE(lab.Stop(&error)) << error;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rms
