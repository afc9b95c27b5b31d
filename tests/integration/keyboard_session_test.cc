// Flying by hand: operator_station --keyboard in a real terminal (tmux),
// driven by keystrokes sent through tmux, with the other three processes
// over real LCM. The keys move the arm and switch cameras (seen in the DCP's
// telemetry and the ESG's control words), and the status screen shows it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <regex>
#include <nlohmann/json.hpp>

#include "lab_processes.h"
#include "rms/channels.h"
#include "rms/control_word.h"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/lcm_interface.h"
#include "rms/message_io.h"
#include "subprocess.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using testing::Subprocess;

class Tmux {
 public:
  explicit Tmux(std::string dir) : dir_(std::move(dir)), socket_("rmslab_test_" + std::to_string(getpid())) {}
  ~Tmux() { Stop(); }
  void Stop() {
    if (stopped_) return;
    stopped_ = true;
    try {
      Run({"kill-server"});
    } catch (const std::exception&) {
    }
  }
  int Run(std::vector<std::string> args) {
    args.insert(args.begin(), {"/usr/bin/tmux", "-L", socket_});
    Subprocess p(args, dir_ + "/tmux.log");
    return p.Wait(10);
  }
  // The pane's text, as the operator sees it.
  std::string Capture() {
    Subprocess p({"/usr/bin/tmux", "-L", socket_, "capture-pane", "-p", "-t", "op"}, dir_ + "/pane.txt");
    p.Wait(10);
    return testing::ReadFile(dir_ + "/pane.txt");
  }

 private:
  std::string dir_, socket_;
  bool stopped_ = false;
};

TEST(KeyboardSession, KeysThroughATerminalMoveTheArmAndSwitchCameras) {
  const std::string dir = testing::MakeTempDir("keys");
  testing::LabProcesses lab(dir, testing::UniqueLcmUrl(8900));
  std::string error;
  ASSERT_TRUE(lab.Start(&error)) << error;
  LcmOptions o;
  o.url = lab.url();
  UdpLcm lcm(o);
  std::optional<dcp_telemetry_t> tm;
  int camera_in_esg = 0;
  lcm.Subscribe(channels::kDcpTelemetry, [&](const void* d, int n, std::int64_t) {
    dcp_telemetry_t m;
    if (SafeDecode(d, n, 4096, &m) == DecodeError::kNone) tm = m;
  });
  lcm.Subscribe(channels::kEsgFrame, [&](const void* d, int n, std::int64_t) {
    esg_frame_t m;
    if (SafeDecode(d, n, 4096, &m) == DecodeError::kNone && m.num_words > 1) {
      camera_in_esg = UnpackControlWord(m.words[1]).camera_station;
    }
  });
  auto pump = [&](double seconds) {
    const std::int64_t until = lcm.NowUs() + static_cast<std::int64_t>(seconds * 1e6);
    while (lcm.NowUs() < until) lcm.HandleSubscriptions(20);
  };

  Tmux tmux(dir);
  const std::string cmd = testing::BuildPath("operator_station/operator_station") + " --lcm-url '" + lab.url() +
                          "' --keyboard --no-gamepad --no-spacemouse --stats " + dir + "/op.json 2>" + dir +
                          "/op.log; echo $? >" + dir + "/op.rc";
  ASSERT_EQ(tmux.Run({"new-session", "-d", "-s", "op", "-x", "120", "-y", "45", cmd}), 0);
  for (int i = 0; i < 100 && !tm; ++i) pump(0.1);
  ASSERT_TRUE(tm.has_value()) << "no telemetry: the station did not start?\n" << testing::ReadFile(dir + "/op.log");
  const double pitch0 = tm->master_angles_deg[1];
  EXPECT_EQ(camera_in_esg, 1);

  // Five presses of 'w' (shoulder pitch +2 deg each), then camera 3.
  ASSERT_EQ(tmux.Run({"send-keys", "-t", "op", "w", "w", "w", "w", "w", "3"}), 0);
  pump(2.5);  // 10 deg at the 8 deg/s rate limit, and then some
  ASSERT_TRUE(tm.has_value());
  EXPECT_NEAR(tm->master_angles_deg[1] - pitch0, 10.0, 0.01);
  EXPECT_NEAR(tm->slave_angles_deg[1] - pitch0, 10.0, 0.01);
  EXPECT_EQ(camera_in_esg, 3);
  const std::string screen = tmux.Capture();
  for (const char* want : {"rmslab operator station -- by hand", "MODE 1 ACQUISITION", "camera 3 elbow",
                           "devices: keyboard (this terminal)", "input to DCP"}) {
    EXPECT_NE(screen.find(want), std::string::npos) << "\"" << want << "\" not on the screen:\n" << screen;
  }

  // The rates measured over the last second: about the frame rate (a loaded
  // machine may run a little slow).
  std::smatch m;
  ASSERT_TRUE(std::regex_search(screen, m, std::regex(R"(rates: published ([\d.]+) Hz\s+DCP ([\d.]+) Hz)"))) << screen;
  EXPECT_NEAR(std::stod(m[1]), 30.0, 4.0) << screen;
  EXPECT_NEAR(std::stod(m[2]), 30.0, 4.0) << screen;

  // 'x' quits: the station exits 0 and says what it published.
  ASSERT_EQ(tmux.Run({"send-keys", "-t", "op", "x"}), 0);
  for (int i = 0; i < 50 && !fs::exists(dir + "/op.rc"); ++i) pump(0.1);
  EXPECT_EQ(testing::ReadFile(dir + "/op.rc"), "0\n") << testing::ReadFile(dir + "/op.log");
  const auto stats = nlohmann::json::parse(testing::ReadFile(dir + "/op.json"));
  EXPECT_GT(stats["counters"]["published"].get<int>(), 50);
  ASSERT_TRUE(lab.Stop(&error)) << error;
  tmux.Stop();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rms
