// Flying by hand: operator_station --keyboard in a real terminal (tmux),
// driven by keystrokes sent through tmux, with the other three processes
// over real LCM. A press is one increment of manual augmented control in the
// command frame (seen in the DCP's telemetry), the camera key switches the
// ESG's camera, the status screen shows guidance and follows the terminal's
// size, and Q quits.
#include <unistd.h>

#include <Eigen/Core>
#include <filesystem>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <regex>

#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/operator_state_t.hpp"
#include "rms/transport/lcm_interface.h"
#include "rms/wire/channels.h"
#include "rms/wire/control_word.h"
#include "rms/wire/message_io.h"

#include "lab_processes.h"
#include "subprocess.h"
#include "tmux.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using testing::Tmux;

TEST(KeyboardSession, APressIsOneIncrementAndTheScreenShowsGuidance) {
  const std::string dir = testing::MakeTempDir("keys");
  testing::LabProcesses lab(dir, testing::UniqueLcmUrl(8900));
  std::string error;
  ASSERT_TRUE(lab.Start(&error)) << error;
  transport::LcmOptions o;
  o.url = lab.url();
  transport::UdpLcm lcm(o);
  std::optional<dcp_telemetry_t> tm;
  std::optional<operator_state_t> state;
  int camera_in_esg = 0;
  lcm.Subscribe(wire::channels::kDcpTelemetry, [&](const void* d, int n, std::int64_t) {
    dcp_telemetry_t m;
    if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone) tm = m;
  });
  lcm.Subscribe(wire::channels::kOperatorState, [&](const void* d, int n, std::int64_t) {
    operator_state_t m;
    if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone) state = m;
  });
  lcm.Subscribe(wire::channels::kEsgFrame, [&](const void* d, int n, std::int64_t) {
    esg_frame_t m;
    if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone && m.num_words > 1) {
      camera_in_esg = wire::UnpackControlWord(m.words[1]).camera_station;
    }
  });
  auto pump = [&](double seconds) {
    const std::int64_t until = lcm.NowUs() + static_cast<std::int64_t>(seconds * 1e6);
    while (lcm.NowUs() < until) lcm.HandleSubscriptions(20);
  };

  Tmux tmux(dir);
  const std::string cmd = testing::BuildPath("operator_station/operator_station") + " --lcm-url '" +
                          lab.url() + "' --keyboard --no-gamepad --no-spacemouse --stats " + dir +
                          "/op.json 2>" + dir + "/op.log; echo $? >" + dir + "/op.rc.tmp; mv " +
                          dir + "/op.rc.tmp " + dir + "/op.rc";  // whole when it is there
  ASSERT_EQ(tmux.Start(cmd, 120, 45), 0);
  // Until the station has shown guidance: its first states can go out
  // before the DCP's first telemetry reaches it (start order varies).
  for (int i = 0; i < 100 && !(tm && state && state->guidance_valid); ++i) pump(0.1);
  ASSERT_TRUE(tm.has_value()) << "no telemetry: the station did not start?\n"
                              << testing::ReadFile(dir + "/op.log");
  ASSERT_TRUE(state.has_value()) << "no RMS_OPERATOR_STATE";
  EXPECT_EQ(state->control_mode, 2);   // manual augmented
  EXPECT_EQ(state->command_frame, 1);  // end effector
  EXPECT_TRUE(state->guidance_valid);
  EXPECT_EQ(state->target, 1);  // the grasp
  EXPECT_EQ(camera_in_esg, 1);
  const Eigen::Vector3d A0(tm->p_RoA_R_ft[0], tm->p_RoA_R_ft[1], tm->p_RoA_R_ft[2]);

  // The orbiter frame ('n'), then one press of 'w' (forward, toward the
  // orbiter's nose: -X_R, in from the arm's full reach) and camera 3; ten
  // more presses of 'w' in one burst are merged into the motion, not queued
  // behind it.
  ASSERT_EQ(tmux.Send({"n"}), 0);
  pump(0.3);
  ASSERT_EQ(tmux.Send({"w", "3"}), 0);
  pump(0.3);
  ASSERT_EQ(tmux.Send({"w", "w", "w", "w", "w", "w", "w", "w", "w", "w"}), 0);
  // 5 ft; slowly at first: from the straight arm (its reach's singular
  // direction) the elbow must bend first, at its 8 deg/s.
  for (int i = 0;
       i < 150 && !(state && state->hand_rate[0] == 0.0 && tm->p_RoA_R_ft[0] < A0.x() - 4.0); ++i) {
    pump(0.1);
  }
  pump(0.5);
  ASSERT_TRUE(tm.has_value());
  const Eigen::Vector3d A1(tm->p_RoA_R_ft[0], tm->p_RoA_R_ft[1], tm->p_RoA_R_ft[2]);
  EXPECT_EQ(state->command_frame, 2);
  // The burst came 0.3 s after the first press, when a few hundredths of
  // the first increment were done: one increment from then, about 5 ft.
  EXPECT_NEAR(A0.x() - A1.x(), 5.0, 0.15);
  EXPECT_LT((A1 - A0).tail<2>().norm(), 0.1);
  EXPECT_EQ(camera_in_esg, 3);
  pump(1.0);
  const Eigen::Vector3d A2(tm->p_RoA_R_ft[0], tm->p_RoA_R_ft[1], tm->p_RoA_R_ft[2]);
  EXPECT_LT((A2 - A1).norm(), 1e-6) << "the arm ran on after its increment";
  const std::string screen = tmux.Capture();
  SCOPED_TRACE(screen);
  for (const char* want :
       {"rmslab operator station -- by hand", "MODE 1 ACQUISITION", "CONTROL manual augmented",
        "frame: orbiter", "GUIDANCE to the grasp on the bar receptacle", "camera 3 elbow",
        "devices: keyboard (this terminal)", "input to DCP", "short by", "command frame"}) {
    EXPECT_NE(screen.find(want), std::string::npos) << "\"" << want << "\" not on the screen:\n"
                                                    << screen;
  }
  // The rates measured over the last second: about the frame rate (a loaded
  // machine may run a little slow).
  std::smatch m;
  ASSERT_TRUE(
      std::regex_search(screen, m, std::regex(R"(rates: published ([\d.]+) Hz\s+DCP ([\d.]+) Hz)")))
      << screen;
  EXPECT_NEAR(std::stod(m[1]), 30.0, 4.0) << screen;
  EXPECT_NEAR(std::stod(m[2]), 30.0, 4.0) << screen;
  // The screen follows the terminal: narrower, no line is wider.
  ASSERT_EQ(tmux.Resize(72, 40), 0);
  pump(0.5);
  const std::string narrow = tmux.Capture();
  std::istringstream lines(narrow);
  for (std::string l; std::getline(lines, l);) EXPECT_LE(l.size(), 72u) << l;
  EXPECT_NE(narrow.find("GUIDANCE"), std::string::npos) << narrow;

  // Q quits: the station exits 0 and says what it published and pressed.
  ASSERT_EQ(tmux.Send({"Q"}), 0);
  for (int i = 0; i < 50 && !fs::exists(dir + "/op.rc"); ++i) pump(0.1);
  EXPECT_EQ(testing::ReadFile(dir + "/op.rc"), "0\n") << testing::ReadFile(dir + "/op.log");
  const auto stats = nlohmann::json::parse(testing::ReadFile(dir + "/op.json"));
  EXPECT_GT(stats["counters"]["published"].get<int>(), 50);
  EXPECT_EQ(stats["counters"]["key_actions"].get<int>(), 14);
  EXPECT_EQ(stats["counters"]["control.frame_changes"].get<int>(), 1);
  ASSERT_TRUE(lab.Stop(&error)) << error;
  tmux.Stop();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rms
