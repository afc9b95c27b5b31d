// A person's flight, scripted: `scripts/lab demo --by-hand` in a real
// terminal (tmux), flown by an operator that reads only the status screen,
// acts a reaction time (0.3 s) after each look, and types only the
// terminal's keys in manual augmented control (tests/support/scripted_operator.h).
//
// The suite flies the acquisition. The whole flight -- acquire, extract,
// dock -- is the long test (ctest -L long; scripts/fly-by-hand writes its
// figures into docs/operator.md): at most 100 key actions and 150 s of
// session time, docked within the report's 0.25 ft and 2 deg 32 min.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "scripted_operator.h"
#include "subprocess.h"
#include "tmux.h"

namespace rms {
namespace {

namespace fs = std::filesystem;

constexpr double kReactionS = 0.3;
constexpr int kKeyBudget = 100;
constexpr double kTimeBudgetS = 150.0;

struct HandSession {
  std::string dir, out;
  std::unique_ptr<testing::Tmux> tmux;
  explicit HandSession(const std::string& tag, int port) : dir(testing::MakeTempDir(tag)), out(dir + "/session") {
    tmux = std::make_unique<testing::Tmux>(dir);
    // As a person starts it from the README, on a private port.
    const std::string cmd = "RMSLAB_BUILD=" + std::string(RMSLAB_BUILD_DIR) + " " + testing::SourcePath("scripts/lab") +
                            " demo --by-hand --no-build --no-video --png-every 0 --out " + out + " --lcm-url '" +
                            testing::UniqueLcmUrl(port) + "' 2>" + dir + "/lab.log; echo $? >" + dir + "/lab.rc";
    tmux->Start(cmd, 132, 50);
  }
  // Q, and the launcher's summary.
  nlohmann::json Quit() {
    tmux->Send({"Q"});
    for (int i = 0; i < 300 && !fs::exists(dir + "/lab.rc"); ++i) usleep(100000);
    if (!fs::exists(out + "/summary.json")) return nullptr;
    return nlohmann::json::parse(testing::ReadFile(out + "/summary.json"));
  }
  ~HandSession() {
    tmux->Stop();
    if (!::testing::Test::HasFailure()) fs::remove_all(dir);
  }
};

std::string Transcript(const testing::FlightReport& r) {
  std::string t;
  for (const auto& l : r.transcript) t += l + "\n";
  return t;
}

TEST(ScriptedOperator, AcquiresThePayloadByHandReadingOnlyTheStatusScreen) {
  HandSession session("hand_acquire", 9300);
  testing::ScriptedOperator op(session.tmux.get(), kReactionS);
  const testing::FlightReport r = op.Fly(/*acquire_only=*/true, kTimeBudgetS);
  std::ofstream(session.dir + "/transcript.txt") << Transcript(r);
  std::printf("acquired: %s at %.1f s of session time, %d key actions\n", r.acquired ? "yes" : "no", r.acquired_t_s,
              r.key_actions);
  EXPECT_TRUE(r.acquired) << r.failure << "\n" << Transcript(r) << session.tmux->Capture();
  EXPECT_LE(r.key_actions, kKeyBudget / 2) << Transcript(r);
  const nlohmann::json summary = session.Quit();
  ASSERT_FALSE(summary.is_null()) << testing::ReadFile(session.dir + "/lab.log");
  EXPECT_TRUE(summary["acquired"].get<bool>());
  // The session's record has what the operator did: every key (Q too) and
  // the control mode it flew in.
  EXPECT_EQ(summary["by_hand"]["key_actions"].get<int>(), r.key_actions + 1);
  EXPECT_EQ(summary["by_hand"]["control_changes"][0]["control_mode"], "manual augmented");
}

TEST(ScriptedOperatorLong, DocksByHandWithinTheBudget) {
  HandSession session("hand_dock", 9350);
  testing::ScriptedOperator op(session.tmux.get(), kReactionS);
  const testing::FlightReport r = op.Fly(/*acquire_only=*/false, 2 * kTimeBudgetS);
  std::ofstream(session.dir + "/transcript.txt") << Transcript(r);
  const std::string screen = session.tmux->Capture();
  std::printf("acquired at %.1f s (%d keys); docked: %s at %.1f s of session time, %d key actions; %.3f ft, %.2f deg\n",
              r.acquired_t_s, r.key_actions_acquire, r.docked ? "yes" : "no", r.docked_t_s, r.key_actions,
              r.dock_distance_ft, r.dock_angle_deg);
  EXPECT_TRUE(r.docked) << r.failure << "\n" << Transcript(r) << screen;
  EXPECT_LE(r.key_actions, kKeyBudget) << Transcript(r);
  EXPECT_LE(r.docked_t_s, kTimeBudgetS) << Transcript(r);
  const nlohmann::json summary = session.Quit();
  ASSERT_FALSE(summary.is_null()) << testing::ReadFile(session.dir + "/lab.log");
  EXPECT_TRUE(summary["docked"].get<bool>());
  EXPECT_TRUE(summary["docking"]["within_tolerance"].get<bool>());
  // scripts/fly-by-hand asks for the figures in markdown, for docs/operator.md.
  if (const char* path = std::getenv("RMSLAB_FLIGHT_REPORT"); path && *path) {
    std::ofstream f(path);
    char line[512];
    std::snprintf(line, sizeof line,
                  "| | Session time | Key actions |\n|---|---|---|\n| acquired | %.1f s | %d |\n| docked | %.1f s | %d |\n\n"
                  "Docked at %.3f ft and %.2f deg (the report's 0.25 ft and 2 deg 32 min); %zu collisions, %d frames "
                  "held. Reaction time 0.3 s after every look.\n\n",
                  r.acquired_t_s, r.key_actions_acquire, r.docked_t_s, r.key_actions,
                  summary["docking"]["distance_ft"].get<double>(), summary["docking"]["angle_deg"].get<double>(),
                  summary["collisions"].size(), summary["held_frames"].get<int>());
    f << line;
    f << "The flight, as the scripted operator saw and did it:\n\n```\n" << Transcript(r) << "```\n";
  }
}

}  // namespace
}  // namespace rms
