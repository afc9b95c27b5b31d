// A whole study flown by scripted subjects (ctest -L long): 2 conditions x
// 2 subjects x 2 measured trials, each subject at a terminal of its own
// running `scripts/lab study run`, each trial flown by hand from the status
// screen by the scripted operator -- acquire, extract, dock -- the session
// ending by itself once docked. The suite flies a short one
// (tests/integration/study_test.cc).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "hand_session.h"
#include "study_subject.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::ReadFile;

TEST(StudyLong, TwoSubjectsFlyTwoConditionsTwiceEachByHand) {
  const std::string dir = testing::MakeTempDir("study_long");
  const std::string folder = dir + "/study";
  const std::string study = dir + "/study.toml";
  std::ofstream(study) << "[study]\nname = \"long\"\norder = \"balanced-latin-square\"\n"
                          "measured_trials = 2\ntrial_limit_s = 300\nsubjects = [\"P1\", \"P2\"]\n"
                          "[[conditions]]\nname = \"flown\"\n"
                          "[[conditions]]\nname = \"wrist-port-external\"\ncameras = [4, 7, 8]\n";
  const auto t0 = std::chrono::steady_clock::now();
  int docked = 0;
  for (const char* name : {"P1", "P2"}) {
    const std::string sub = dir + "/" + name;
    fs::create_directories(sub);
    testing::StudySubject subject(sub, study, name, folder, testing::UniqueLcmUrl(9540));
    for (int trial = 1; trial <= 4; ++trial) {
      ASSERT_TRUE(subject.StartTrial(trial, 120))
          << name << " trial " << trial << "\n"
          << subject.tmux()->Capture() << ReadFile(sub + "/study.log");
      testing::ScriptedOperator op(subject.tmux(), testing::kReactionS);
      const testing::FlightReport r = op.Fly(/*acquire_only=*/false, 2 * testing::kTimeBudgetS);
      std::printf("%s trial %d: docked %s at %.1f s of session time, %d key actions\n", name, trial,
                  r.docked ? "yes" : "no", r.docked_t_s, r.key_actions);
      docked += r.docked;
      if (!r.docked) subject.tmux()->Send({"Q"});  // the trial ends; counted as flown, not docked
    }
    ASSERT_EQ(subject.WaitExit(120), 0) << ReadFile(sub + "/study.log");
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const testing::ScriptRun st = testing::Script(
      {testing::SourcePath("scripts/lab"), "study", "status", study, "--dir", folder, "--json"},
      dir + "/status.log");
  const json s = json::parse(st.out.substr(st.out.find('{')), nullptr, false);
  ASSERT_TRUE(s.is_object()) << st.out;
  for (const char* name : {"P1", "P2"}) {
    EXPECT_EQ(s["subjects"][name]["done"], 4) << s.dump(1);
    EXPECT_EQ(s["subjects"][name]["lost_runs"], 0) << s.dump(1);
  }
  std::printf("study: 2 subjects x 2 conditions x 2 trials, %d of 8 docked, %.0f s of wall time\n",
              docked, wall_s);
  EXPECT_GE(docked, 6) << "the scripted operator docks nearly every flight";
  if (!::testing::Test::HasFailure()) fs::remove_all(dir);
}

}  // namespace
}  // namespace rms
