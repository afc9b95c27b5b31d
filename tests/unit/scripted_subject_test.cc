// The scripted operator as a virtual subject (docs/studies.md "Designs
// judged by flying them"): it flies the operator station offline -- the
// hand controllers, the real DCP, the status screen it reads -- from the
// start to the dock, by keys alone; the same draws give the same flight;
// a boom too short to reach the bar never acquires.
#include <cmath>
#include <cstdio>
#include <gtest/gtest.h>
#include <stdexcept>
#include <vector>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/operator_station/bindings.h"
#include "rms/sim/offline_station.h"
#include "rms/sim/virtual_subjects.h"

namespace rms::sim {
namespace {

const operator_station::Bindings& DefaultBindings() {
  static const operator_station::Bindings b =
      operator_station::LoadBindings(operator_station::DefaultBindingsPath());
  return b;
}

TEST(ScriptedSubject, DocksOfflineFromTheStatusScreenAndKeysAlone) {
  const LabConfig c = LoadConfig(DefaultConfigPath());
  ScriptedOperatorOptions o;
  o.reaction_s = 0.3;
  const ScriptedFlight f = FlyScriptedSubject(c, DefaultBindings(), o, 300);
  std::printf("offline: docked %d at %.1f s, %ld keys (%d to acquire), %d collision events\n",
              f.result.docked, f.result.docked_frame / c.session.frame_rate_hz, f.key_actions,
              f.report.key_actions_acquire, f.result.collision_events);
  for (const auto& line : f.report.transcript) std::printf("  %s\n", line.c_str());
  ASSERT_TRUE(f.result.docked) << f.result.failure;
  EXPECT_TRUE(f.report.docked);  // the screen said so too
  EXPECT_GT(f.result.modes_entered[2], 0);
  EXPECT_GT(f.result.modes_entered[3], f.result.modes_entered[2]);
  EXPECT_LE(f.result.dock_distance_ft, c.dcp.dock_distance_ft);
  // The keys the station counted are the ones the operator pressed.
  EXPECT_EQ(f.key_actions, f.report.key_actions);
  EXPECT_GT(f.key_actions, 10);
}

// docs/operator.md "A scripted operator": from the start and three awkward
// attitudes of the wrist (one of the whole arm too) the operator squares up
// with the square-up key, unwinds the wrist where the screen warns of its
// limit (and stows the arm where it warns again after that: a second
// attempt after a reset from Mode 3), acquires within the budget -- 50 key actions at a terminal,
// 30 at the live window (held keys) -- and docks.
TEST(ScriptedSubject, SquaresUpFromAwkwardAttitudesAndDocksWithinTheBudget) {
  struct Attitude {
    const char* name;
    double q_deg[6];
    bool after_reset = false;  // a second attempt, after a reset from Mode 3
  };
  const Attitude attitudes[] = {
      {"the start (the stowed arm)", {NAN, NAN, NAN, NAN, NAN, NAN}},
      {"wrist pitched up, yawed and rolled", {0.06, 0.16, -0.31, 90.0, -60.0, 150.0}},
      {"wrist pitched down, yawed the other way", {0.06, 0.16, -0.31, -100.0, 80.0, -120.0}},
      {"arm raised, wrist rolled near its limit", {20.0, 30.0, -60.0, 40.0, 100.0, 172.0}},
      // A reset from Mode 3 leaves the arm over the CAE, where it docked.
      {"where the arm docked, after a reset", {NAN, NAN, NAN, NAN, NAN, NAN}, true},
  };
  for (const Attitude& a : attitudes) {
    LabConfig c = LoadConfig(DefaultConfigPath());
    for (int i = 0; i < 6; ++i)
      if (!std::isnan(a.q_deg[i])) c.inputs[i].initial = a.q_deg[i];
    ScriptedOperatorOptions o;
    o.reaction_s = 0.3;
    // A terminal's keys (budget 50 to acquire), then the live window's
    // held keys (budget 30).
    for (const bool window : {false, true}) {
      const ScriptedFlight f = FlyScriptedSubject(c, DefaultBindings(), o,
                                                  a.after_reset ? 700 : 400, window, a.after_reset);
      std::printf(
          "%s, %s: acquired at %.1f s with %d keys, docked %d at %.1f s with %d keys, "
          "%d collision events\n",
          a.name, window ? "window" : "terminal", f.report.acquired_t_s,
          f.report.key_actions_acquire, f.report.docked, f.report.docked_t_s, f.report.key_actions,
          f.result.collision_events);
      for (const auto& line : f.report.transcript) std::printf("  %s\n", line.c_str());
      ASSERT_TRUE(f.result.docked) << a.name << ": " << f.result.failure << f.report.failure;
      ASSERT_TRUE(f.report.docked) << a.name << ": " << f.report.failure;  // this attempt
      EXPECT_LE(f.report.key_actions_acquire, window ? 30 : 50) << a.name;
      EXPECT_LE(f.result.dock_distance_ft, c.dcp.dock_distance_ft) << a.name;
      if (!a.after_reset) {  // the station counted them too (after a reset: both attempts')
        EXPECT_EQ(f.key_actions, f.report.key_actions) << a.name;
      }
    }
  }
}

TEST(ScriptedSubject, TheSameDrawsFlyTheSameFlightAndOthersAnother) {
  const LabConfig c = LoadConfig(DefaultConfigPath());
  Dispersions d;
  constexpr std::uint64_t kSeed = 11;
  std::printf("seed %llu, 2 runs\n", static_cast<unsigned long long>(kSeed));
  const auto a = FlyRuns(c, d, kSeed, 2, 300, 2, SubjectKind::kScripted);
  const auto b = FlyRuns(c, d, kSeed, 2, 300, 1, SubjectKind::kScripted);
  ASSERT_EQ(a.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(a[i].subject, SubjectKind::kScripted);
    EXPECT_EQ(a[i].result.frames, b[i].result.frames) << i;
    EXPECT_EQ(a[i].key_actions, b[i].key_actions) << i;
    EXPECT_EQ(a[i].result.docked_frame, b[i].result.docked_frame) << i;
  }
  EXPECT_NE(a[0].reaction_s, a[1].reaction_s);
  EXPECT_NE(a[0].result.frames, a[1].result.frames) << "two subjects flew frame for frame alike";
  // Paired: run k of the autopilot draws what run k of the scripted one did.
  const auto p = FlyRuns(c, d, kSeed, 2, 300, 2, SubjectKind::kAutopilot);
  EXPECT_EQ(p[1].reaction_s, a[1].reaction_s);
  EXPECT_EQ(p[1].rate_gain, a[1].rate_gain);
  EXPECT_EQ(p[1].key_actions, -1);
}

TEST(ScriptedSubject, ABoomTooShortToReachTheBarNeverAcquires) {
  LabConfig c = LoadConfig(DefaultConfigPath());
  c.arm.upper_boom_ft = 8.0;  // (12 ft reaches: the scripted operator docks with it)
  ScriptedOperatorOptions o;
  const ScriptedFlight f = FlyScriptedSubject(c, DefaultBindings(), o, 120);
  EXPECT_FALSE(f.result.docked);
  EXPECT_EQ(f.result.modes_entered[2], 0) << "acquired with a 12 ft upper boom";
  EXPECT_EQ(f.result.failure, "no acquisition by 120 s");
  EXPECT_LE(f.result.time_s, 120.0 + 1e-9);
}

TEST(ScriptedSubject, AKeyTheStationHasNotIsRefusedByName) {
  const LabConfig c = LoadConfig(DefaultConfigPath());
  OfflineStation s(c, DefaultBindings(), 10);
  try {
    s.Send({"F13"});
    FAIL() << "an unknown key was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("F13"), std::string::npos) << e.what();
  }
  s.Wait(0.5);
  EXPECT_NEAR(s.session_s(), 0.5, 1.0 / c.session.frame_rate_hz + 1e-9);
  EXPECT_THROW(s.Wait(20), FlightTimeUp);
}

}  // namespace
}  // namespace rms::sim
