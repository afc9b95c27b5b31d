// A person's whole flight, scripted (ctest -L long; scripts/fly-by-hand
// writes its figures into docs/operator.md): `scripts/lab demo --by-hand` in
// a real terminal, flown by an operator that reads only the status screen
// and types only its keys -- acquire, extract, dock -- in at most 100 key
// actions and 150 s of session time, docked within the report's 0.25 ft and
// 2 deg 32 min.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "hand_session.h"

namespace rms {
namespace {

using testing::HandSession;
using testing::kKeyBudget;
using testing::kReactionS;
using testing::kTimeBudgetS;
using testing::Transcript;

TEST(ScriptedOperatorLong, DocksByHandWithinTheBudget) {
  HandSession session("hand_dock", 9350);
  testing::ScriptedOperator op(session.tmux.get(), kReactionS);
  const testing::FlightReport r = op.Fly(/*acquire_only=*/false, 2 * kTimeBudgetS);
  std::ofstream(session.dir + "/transcript.txt") << Transcript(r);
  const std::string screen = session.tmux->Capture();
  std::printf(
      "acquired at %.1f s (%d keys); docked: %s at %.1f s of session time, %d key actions; %.3f "
      "ft, %.2f deg\n",
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
                  "| | Session time | Key actions |\n|---|---|---|\n| acquired | %.1f s | %d |\n| "
                  "docked | %.1f s | %d |\n\n"
                  "Docked at %.3f ft and %.2f deg (the report's 0.25 ft and 2 deg 32 min); %zu "
                  "collisions, %d frames "
                  "held. Reaction time 0.3 s after every look.\n\n",
                  r.acquired_t_s, r.key_actions_acquire, r.docked_t_s, r.key_actions,
                  summary["docking"]["distance_ft"].get<double>(),
                  summary["docking"]["angle_deg"].get<double>(), summary["collisions"].size(),
                  summary["held_frames"].get<int>());
    f << line;
    f << "The flight, as the scripted operator saw and did it:\n\n```\n"
      << Transcript(r) << "```\n";
  }
}

}  // namespace
}  // namespace rms
