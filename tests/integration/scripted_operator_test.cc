// A person's flight, scripted: `scripts/lab demo --by-hand` in a real
// terminal (tmux), flown by an operator that reads only the status screen,
// acts a reaction time (0.3 s) after each look, and types only the
// terminal's keys in manual augmented control (tests/support/scripted_operator.h).
//
// The suite flies the acquisition. The whole flight -- acquire, extract,
// dock -- is the long test (tests/long/scripted_operator_docks_test.cc).
#include "scripted_operator.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "hand_session.h"
#include "subprocess.h"
#include "tmux.h"

namespace rms {
namespace {

namespace fs = std::filesystem;

using testing::HandSession;
using testing::kKeyBudget;
using testing::kReactionS;
using testing::kTimeBudgetS;
using testing::Transcript;

TEST(ScriptedOperator, AcquiresThePayloadByHandReadingOnlyTheStatusScreen) {
  HandSession session("hand_acquire", 9300);
  testing::ScriptedOperator op(session.tmux.get(), kReactionS);
  const testing::FlightReport r = op.Fly(/*acquire_only=*/true, kTimeBudgetS);
  std::ofstream(session.dir + "/transcript.txt") << Transcript(r);
  std::printf("acquired: %s at %.1f s of session time, %d key actions\n", r.acquired ? "yes" : "no",
              r.acquired_t_s, r.key_actions);
  EXPECT_TRUE(r.acquired) << r.failure << "\n" << Transcript(r) << session.tmux->Capture();
  EXPECT_LE(r.key_actions, kKeyBudget / 2) << Transcript(r);
  const nlohmann::json summary = session.Quit();
  ASSERT_FALSE(summary.is_null()) << testing::ReadFile(session.dir + "/lab.log");
  EXPECT_TRUE(summary["acquired"].get<bool>());
  // The session's record has what the operator did: every key (Q too) and
  // the control mode it flew in.
  EXPECT_EQ(summary["by_hand"]["key_actions"].get<int>(), r.key_actions + 1);
  EXPECT_EQ(summary["by_hand"]["control_changes"][0]["control_mode"], "manual augmented");
  // Flown with the square-up and null keys (docs/operator.md "Nulling an
  // axis, squaring up, unwinding"), counted, and the session re-simulates
  // word for word: what flew by itself is in the record as inputs.
  const nlohmann::json stats =
      nlohmann::json::parse(testing::ReadFile(session.out + "/stats/operator_station.json"));
  EXPECT_GE(stats["counters"].value("control.square_ups", 0), 1) << stats.dump();
  EXPECT_GE(stats["counters"].value("control.nulls", 0), 3) << stats.dump();
  EXPECT_TRUE(summary["resimulation"]["exact"].get<bool>()) << summary["resimulation"].dump();
}

}  // namespace
}  // namespace rms
