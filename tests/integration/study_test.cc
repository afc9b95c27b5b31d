// Studies (docs/studies.md), as an experimenter runs them: `scripts/lab
// study check / run / status` on study files written here, the trials real
// sessions of the four processes over LCM. A study file refused naming its
// key; each subject's order a balanced Latin square or a seeded shuffle;
// trials run one after another, tagged, resumed after the run is killed, a
// trial whose process crashed flown again and never counted; and a subject
// played by the scripted operator at a real terminal, by hand, with the
// condition's camera set.
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "hand_session.h"
#include "netns_lab.h"
#include "scripted_operator.h"
#include "study_subject.h"
#include "subprocess.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::ReadFile;
using testing::Script;
using testing::ScriptRun;
using testing::SourcePath;

std::string Lab() { return SourcePath("scripts/lab"); }

std::string WriteStudy(const std::string& dir, const std::string& name, const std::string& text) {
  std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

// A study of `n` conditions (c0, c1, ...) and `subjects` subjects (s0, ...).
std::string StudyText(const std::string& order, int n, int subjects, int practice = 0) {
  std::string t = "[study]\nname = \"t\"\norder = \"" + order + "\"\n";
  if (order == "random") t += "seed = 7\n";
  t += "practice_trials = " + std::to_string(practice) +
       "\nmeasured_trials = 1\ntrial_limit_s = 60\n";
  t += "subjects = [";
  for (int i = 0; i < subjects; ++i)
    t += (i ? ", " : "") + std::string("\"s") + std::to_string(i) + "\"";
  t += "]\n";
  for (int i = 0; i < n; ++i) {
    t += "[[conditions]]\nname = \"c";
    t += std::to_string(i);
    t += "\"\n";
  }
  return t;
}

json Plan(const std::string& dir, const std::string& study) {
  const ScriptRun r =
      Script({Lab(), "study", "check", study, "--json", "--no-build"}, dir + "/check.log");
  EXPECT_EQ(r.rc, 0) << r.out;
  const auto brace = r.out.find('{');
  return brace == std::string::npos ? json() : json::parse(r.out.substr(brace), nullptr, false);
}

// Each subject's order of conditions (indices), from the plan.
std::vector<std::vector<int>> Orders(const json& plan, int subjects) {
  std::vector<std::vector<int>> out;
  for (int s = 0; s < subjects; ++s) {
    std::vector<int> order;
    std::string name = "s";
    name += std::to_string(s);
    for (const json& t : plan["subjects"][name]) {
      const int c = std::stoi(t["condition"].get<std::string>().substr(1));
      if (order.empty() || order.back() != c) order.push_back(c);
    }
    out.push_back(order);
  }
  return out;
}

TEST(Study, AStudyFileIsRefusedNamingTheKeyAndWhy) {
  const std::string dir = testing::MakeTempDir("study_file");
  const std::string good =
      "[study]\nname = \"ok\"\norder = \"balanced-latin-square\"\nmeasured_trials = 2\n"
      "trial_limit_s = 120\nsubjects = [\"S1\", \"S2\"]\n"
      "[[conditions]]\nname = \"flown\"\n"
      "[[conditions]]\nname = \"short\"\nset = { \"arm.upper_boom_ft\" = 19.9 }\ncameras = [4, 7, "
      "8]\n";
  ASSERT_EQ(Script({Lab(), "study", "check", WriteStudy(dir, "good.toml", good), "--no-build"},
                   dir + "/good.log")
                .rc,
            0)
      << ReadFile(dir + "/good.log");
  struct Case {
    std::string from, to, message;
  };
  const Case cases[] = {
      {"order = \"balanced-latin-square\"", "order = \"latin\"", "key 'study.order': must be"},
      {"order = \"balanced-latin-square\"", "order = \"random\"", "key 'study.seed': missing"},
      {"measured_trials = 2", "measured_trials = 0",
       "key 'study.measured_trials': must be a whole"},
      {"trial_limit_s = 120", "trial_limt_s = 120", "key 'study.trial_limt_s': unknown key"},
      {"\"S2\"", "\"S1\"", "key 'study.subjects[1]': 'S1' is listed twice"},
      {"\"S2\"", "\"../x\"", "key 'study.subjects[1]': a subject's name must be"},
      {"name = \"short\"", "name = \"flown\"", "key 'conditions[1].name': 'flown' is the name"},
      {"19.9", "-3", "key 'conditions[1].set.arm.upper_boom_ft': must be > 0, got -3"},
      {"19.9", "\"long\"", "key 'conditions[1].set.arm.upper_boom_ft': the key is a number"},
      {"arm.upper_boom_ft", "arm.uper_boom_ft",
       "key 'conditions[1].set.arm.uper_boom_ft': the "
       "configuration has no key"},
      {"cameras = [4, 7, 8]", "cameras = [4, 9]", "key 'conditions[1].cameras': must be distinct"},
      {"cameras = [4, 7, 8]", "control = \"joystick\"", "key 'conditions[1].control': must be"},
      {"cameras = [4, 7, 8]", "lesson = \"nowhere.toml\"",
       "key 'conditions[1].lesson': no such file"},
      {"cameras = [4, 7, 8]", "lesson = \"bad_lesson.toml\"", "key 'conditions[1].lesson':"},
      {"[[conditions]]\nname = \"flown\"\n", "", "name = \"flown\""},  // one condition left: fine
  };
  WriteStudy(dir, "bad_lesson.toml", "[[events]]\nat_s = 1\ndo = \"explode\"\n");
  for (std::size_t i = 0; i + 1 < std::size(cases); ++i) {
    const Case& c = cases[i];
    std::string text = good;
    ASSERT_NE(text.find(c.from), std::string::npos) << c.from;
    text.replace(text.find(c.from), c.from.size(), c.to);
    const ScriptRun r =
        Script({Lab(), "study", "check", WriteStudy(dir, "bad.toml", text), "--no-build"},
               dir + "/bad.log");
    EXPECT_EQ(r.rc, 2) << c.to << "\n" << r.out;
    EXPECT_NE(r.out.find("bad.toml: " + c.message), std::string::npos) << c.to << "\n" << r.out;
  }
  fs::remove_all(dir);
}

// Williams's balanced Latin square: over a whole square's subjects each
// condition comes once (n even) or twice (n odd, the square and its mirror)
// in each place, and each condition directly follows each other as often.
TEST(Study, OrdersAreBalancedLatinSquaresOrShufflesOfAPrintedSeed) {
  const std::string dir = testing::MakeTempDir("study_order");
  for (const int n : {4, 3}) {
    const int rows = n % 2 == 0 ? n : 2 * n;
    const json plan = Plan(
        dir, WriteStudy(dir, "latin.toml", StudyText("balanced-latin-square", n, 2 * rows, 1)));
    ASSERT_TRUE(plan.is_object());
    const auto orders = Orders(plan, 2 * rows);
    std::map<std::pair<int, int>, int> at, follows;
    for (int s = 0; s < rows; ++s) {
      ASSERT_EQ(std::set<int>(orders[s].begin(), orders[s].end()).size(),
                static_cast<std::size_t>(n))
          << "subject " << s << " does not fly every condition once";
      for (int k = 0; k < n; ++k) ++at[{orders[s][k], k}];
      for (int k = 0; k + 1 < n; ++k) ++follows[{orders[s][k], orders[s][k + 1]}];
      EXPECT_EQ(orders[s + rows], orders[s]) << "the square's rows repeat for the next subjects";
    }
    for (const auto& [key, count] : at)
      EXPECT_EQ(count, rows / n) << "condition " << key.first << " place " << key.second;
    EXPECT_EQ(follows.size(), static_cast<std::size_t>(n * (n - 1)));
    for (const auto& [key, count] : follows)
      EXPECT_EQ(count, rows / n) << key.first << " then " << key.second;
    // Each condition's practice trial comes before its measured one.
    const json& s0 = plan["subjects"]["s0"];
    ASSERT_EQ(s0.size(), static_cast<std::size_t>(2 * n));
    for (int k = 0; k < n; ++k) {
      EXPECT_EQ(s0[2 * k]["kind"], "practice");
      EXPECT_EQ(s0[2 * k + 1]["kind"], "measured");
      EXPECT_EQ(s0[2 * k]["condition"], s0[2 * k + 1]["condition"]);
      EXPECT_EQ(s0[2 * k]["trial"], 2 * k + 1);
    }
  }
  // Random: the same seed, the same orders, and the seed is printed.
  const std::string random = WriteStudy(dir, "random.toml", StudyText("random", 4, 6));
  std::printf("random order: seed 7 (the study file's)\n");
  const json a = Plan(dir, random), b = Plan(dir, random);
  EXPECT_EQ(a["subjects"], b["subjects"]);
  EXPECT_EQ(a["seed"], 7);
  const ScriptRun said = Script({Lab(), "study", "check", random, "--no-build"}, dir + "/said.log");
  EXPECT_NE(said.out.find("seed 7"), std::string::npos) << said.out;
  std::string other = StudyText("random", 4, 6);
  other.replace(other.find("seed = 7"), 8, "seed = 8");
  const json c = Plan(dir, WriteStudy(dir, "random8.toml", other));
  EXPECT_NE(Orders(a, 6), Orders(c, 6)) << "seeds 7 and 8 gave the same orders";
  std::set<std::vector<int>> distinct;
  for (const auto& o : Orders(a, 6)) distinct.insert(o);
  EXPECT_GT(distinct.size(), 1u) << "every subject has the same shuffle";
  fs::remove_all(dir);
}

json Status(const std::string& dir, const std::string& study, const std::string& folder) {
  const ScriptRun r =
      Script({Lab(), "study", "status", study, "--dir", folder, "--json"}, dir + "/status.log");
  EXPECT_EQ(r.rc, 0) << r.out;
  const auto brace = r.out.find('{');
  return brace == std::string::npos ? json() : json::parse(r.out.substr(brace), nullptr, false);
}

std::vector<json> Journal(const std::string& folder) {
  std::vector<json> out;
  std::ifstream f(folder + "/trials.jsonl");
  for (std::string line; std::getline(f, line);) out.push_back(json::parse(line, nullptr, false));
  return out;
}

int Starts(const std::string& folder, int trial) {
  int n = 0;
  for (const json& e : Journal(folder))
    n += e.value("event", "") == "start" && e.value("trial", 0) == trial;
  return n;
}

using testing::WaitUntil;

// A dry run (the autopilot as a virtual subject): four trials one after
// another, the run killed (SIGKILL) as its second begins and resumed, and
// the DCP killed in the third; each a session tagged with its trial, the
// killed and the crashed runs marked lost and flown again, none counted.
TEST(Study, TrialsRunInOrderResumeAfterAKillAndALostOneIsFlownAgain) {
  const std::string dir = testing::MakeTempDir("study_run");
  const std::string folder = dir + "/study";
  const std::string url = testing::UniqueLcmUrl(9500);
  const std::string study =
      WriteStudy(dir, "dry.toml",
                 "[study]\nname = \"dry\"\norder = \"balanced-latin-square\"\n"
                 "measured_trials = 2\ntrial_limit_s = 12\nsubjects = [\"A\", \"B\"]\n"
                 "[[conditions]]\nname = \"flown\"\n"
                 "[[conditions]]\nname = \"tpob\"\nset = { \"dcp.tpob_ft\" = 0.35 }\n"
                 "lesson = \"lesson.toml\"\n");
  WriteStudy(dir, "lesson.toml", "[[events]]\nat_s = 2\ndo = \"malfunction camera 2 lost\"\n");
  const std::vector<std::string> run = {
      Lab(),   "study",      "run",         study,       "--subject",  "A",
      "--dir", folder,       "--pilot",     "autopilot", "--no-build", "--speed",
      "2",     "--no-video", "--png-every", "0",         "--lcm-url",  url};
  {
    testing::Subprocess first(run, dir + "/first.log");
    ASSERT_TRUE(WaitUntil([&] { return Starts(folder, 2) >= 1; }, 120))
        << ReadFile(dir + "/first.log");
    first.Signal(SIGKILL);
    first.Wait(10);
  }
  // The killed run's trial-2 session stops by itself (its launcher is told
  // when the study run dies); the resumed run waits for it, marks it lost
  // and flies it again.
  testing::Subprocess second(run, dir + "/second.log");
  ASSERT_TRUE(WaitUntil([&] { return Starts(folder, 3) >= 1; }, 180))
      << ReadFile(dir + "/second.log");
  std::string pid_file;
  ASSERT_TRUE(WaitUntil(
      [&] {
        for (const auto& e : fs::directory_iterator(folder + "/trials/A"))
          if (e.path().filename().string().rfind("03-", 0) == 0 &&
              fs::exists(e.path() / "run/dynamics_proc.ready"))
            pid_file = (e.path() / "run/dynamics_proc.pid").string();
        return !pid_file.empty();
      },
      60));
  const int dcp = std::stoi(ReadFile(pid_file));
  ASSERT_EQ(kill(dcp, SIGKILL), 0);
  ASSERT_EQ(second.Wait(300), 0) << ReadFile(dir + "/second.log");
  const std::string log = ReadFile(dir + "/second.log");
  EXPECT_NE(log.find("marked lost, to be flown again"), std::string::npos) << log;
  EXPECT_NE(log.find("LOST: a process crashed and was restarted (dynamics_proc)"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("subject A has flown every trial"), std::string::npos) << log;

  const json st = Status(dir, study, folder);
  const json& a = st["subjects"]["A"];
  EXPECT_EQ(a["planned"], 4);
  EXPECT_EQ(a["done"], 4);
  EXPECT_EQ(a["lost_runs"], 2);
  EXPECT_TRUE(a["next"].is_null());
  EXPECT_EQ(st["subjects"]["B"]["done"], 0);
  EXPECT_EQ(st["subjects"]["B"]["next"]["trial"], 1);
  // Balanced Latin square of two: A flies flown, flown, tpob, tpob.
  const std::vector<std::string> conds = {"flown", "flown", "tpob", "tpob"};
  for (int i = 0; i < 4; ++i) {
    const json& t = a["trials"][i];
    EXPECT_EQ(t["condition"], conds[i]);
    EXPECT_TRUE(t["done"].get<bool>());
    const std::size_t runs = t["sessions"].size();
    EXPECT_EQ(runs, i == 1 || i == 2 ? 2u : 1u) << t.dump();
    // The run counted is the last; each run's session is tagged (a lost
    // run's, killed before its session began, may have none).
    for (std::size_t k = 0; k < runs; ++k) {
      const std::string session = folder + "/" + t["sessions"][k].get<std::string>();
      if (k + 1 < runs && !fs::exists(session + "/manifest.json")) continue;
      const json m = json::parse(ReadFile(session + "/manifest.json"), nullptr, false);
      ASSERT_TRUE(m.is_object()) << session;
      EXPECT_EQ(m["subject"], "A");
      EXPECT_EQ(m["study"]["name"], "dry");
      EXPECT_EQ(m["study"]["condition"], conds[i]);
      EXPECT_EQ(m["study"]["trial"], i + 1);
      EXPECT_EQ(m["study"]["run"], static_cast<int>(k) + 1);
      EXPECT_EQ(m["study"]["kind"], "measured");
      // The condition's design is the session's configuration.
      const std::string cfg = ReadFile(session + "/config.toml");
      EXPECT_EQ(cfg.find("tpob_ft = 0.34999999999999998") != std::string::npos, conds[i] == "tpob")
          << session;
    }
    const std::string counted = folder + "/" + t["sessions"][runs - 1].get<std::string>();
    const json sum = json::parse(ReadFile(counted + "/summary.json"), nullptr, false);
    EXPECT_TRUE(sum["resimulation"]["exact"].get<bool>()) << counted;
    EXPECT_TRUE(sum["restarts"].empty()) << counted;
    // The condition's lesson: its event in the tpob trials only.
    EXPECT_EQ(sum["malfunctions"].size(), conds[i] == "tpob" ? 1u : 0u) << counted;
  }
  // The report: a row an attempt of the four trials counted (the lost runs
  // are not in it), and the statistics over them.
  const ScriptRun rep = Script({Lab(), "study", "report", study, "--dir", folder, "--no-build"},
                               dir + "/report.log", 120);
  ASSERT_EQ(rep.rc, 0) << rep.out;
  EXPECT_NE(rep.out.find("2 lost runs not counted"), std::string::npos) << rep.out;
  {
    std::ifstream csv(folder + "/report/study.csv");
    std::string header, line;
    std::getline(csv, header);
    EXPECT_EQ(header.rfind("study,subject,condition,trial,trial_kind,run,session,result,docked", 0),
              0u)
        << header;
    int rows = 0;
    while (std::getline(csv, line)) rows += !line.empty();
    EXPECT_EQ(rows, 4) << "one row an attempt of each trial counted";
    const json stats = json::parse(ReadFile(folder + "/report/stats.json"), nullptr, false);
    EXPECT_EQ(stats["trials"], 4);
    EXPECT_EQ(stats["lost_runs"], 2);
    EXPECT_EQ(stats["conditions"]["tpob"]["trials"], 2);
    EXPECT_NE(ReadFile(folder + "/report/study.html").find("learning curve of A"),
              std::string::npos);
  }
  // Run again: nothing left to fly.
  const ScriptRun again = Script(run, dir + "/again.log", 60);
  EXPECT_EQ(again.rc, 0);
  EXPECT_NE(again.out.find("has flown every trial"), std::string::npos) << again.out;
  // A changed study file is refused for the folder its trials were flown in.
  std::string changed = ReadFile(study);
  changed.replace(changed.find("0.35"), 4, "0.40");
  const ScriptRun refused =
      Script({Lab(), "study", "run", WriteStudy(dir, "dry.toml", changed), "--subject", "B",
              "--dir", folder, "--pilot", "autopilot", "--no-build"},
             dir + "/refused.log", 60);
  EXPECT_EQ(refused.rc, 2);
  EXPECT_NE(refused.out.find("is not the study file its folder"), std::string::npos) << refused.out;
  if (!::testing::Test::HasFailure()) fs::remove_all(dir);
}

// A subject at a terminal: the scripted operator flies each trial by hand
// from the status screen (acquires, then quits), the study's prompt between
// them; the second condition's camera set refuses station 1.
TEST(Study, ASubjectFliesEachTrialByHandAtATerminal) {
  const std::string dir = testing::MakeTempDir("study_hand");
  const std::string folder = dir + "/study";
  const std::string study =
      WriteStudy(dir, "hand.toml",
                 "[study]\nname = \"hand\"\norder = \"balanced-latin-square\"\n"
                 "measured_trials = 1\ntrial_limit_s = 200\nsubjects = [\"P1\"]\n"
                 "[[conditions]]\nname = \"all-cameras\"\n"
                 "[[conditions]]\nname = \"three-cameras\"\ncameras = [4, 7, 8]\n");
  testing::StudySubject subject(dir, study, "P1", folder, testing::UniqueLcmUrl(9520));
  for (int trial = 1; trial <= 2; ++trial) {
    ASSERT_TRUE(subject.StartTrial(trial, 120))
        << "trial " << trial << "\n"
        << subject.tmux()->Capture() << ReadFile(dir + "/study.log");
    if (trial == 2) {
      // The camera set: station 1 is refused, and said so on the screen.
      subject.tmux()->Send({"1"});
      EXPECT_TRUE(subject.WaitFor("camera 1 is not in this session's camera set (4 7 8)", 10))
          << subject.tmux()->Capture();
    }
    testing::ScriptedOperator op(subject.tmux(), testing::kReactionS);
    const testing::FlightReport r = op.Fly(/*acquire_only=*/true, 150);
    EXPECT_TRUE(r.acquired) << "trial " << trial << ": " << r.failure << "\n"
                            << subject.tmux()->Capture();
    subject.tmux()->Send({"Q"});
  }
  ASSERT_EQ(subject.WaitExit(120), 0) << ReadFile(dir + "/study.log");
  const std::string log = ReadFile(dir + "/study.log");
  EXPECT_NE(log.find("subject P1: trial 1 of 2 -- condition 'all-cameras'"), std::string::npos)
      << log;
  EXPECT_NE(log.find("trial 2 of 2 done: acquired"), std::string::npos) << log;
  const json st = Status(dir, study, folder);
  EXPECT_EQ(st["subjects"]["P1"]["done"], 2);
  const std::string second =
      folder + "/" + st["subjects"]["P1"]["trials"][1]["sessions"][0].get<std::string>();
  const json stats = json::parse(ReadFile(second + "/stats/operator_station.json"), nullptr, false);
  EXPECT_EQ(stats["counters"].value("camera.refused", 0), 1) << stats.dump();
  const json sum = json::parse(ReadFile(second + "/summary.json"), nullptr, false);
  EXPECT_EQ(sum["pilot"], "by-hand");
  EXPECT_TRUE(sum["acquired"].get<bool>());
  if (!::testing::Test::HasFailure()) fs::remove_all(dir);
}

// The statistics against a case worked by hand: three subjects each fly
// two conditions (their measured trials' result attempts), plus rows the
// figures must leave out (a practice trial, an attempt not the result).
TEST(Study, TheStatisticsAgreeWithACaseWorkedByHand) {
  const std::string dir = testing::MakeTempDir("study_stats");
  std::ofstream(dir + "/study.csv")
      << "study,subject,condition,trial,trial_kind,run,session,result,docked,duration_s,outcome,"
         "task_time_s,collisions,actions\n"
         "h,s1,c0,1,practice,1,x,1,1,300,docked,400,9,99\n"  // practice: left out
         "h,s1,c0,2,measured,1,x,0,0,300,acquired,,7,50\n"   // not the result: left out
         "h,s1,c0,2,measured,1,x,1,1,300,docked,100,1,40\n"
         "h,s1,c1,3,measured,1,x,1,1,300,docked,110,2,44\n"
         "h,s2,c0,1,measured,1,x,1,1,300,docked,90,0,38\n"
         "h,s2,c1,2,measured,1,x,1,1,300,docked,104,3,47\n"
         "h,s3,c0,1,measured,1,x,1,1,300,docked,120,2,41\n"
         "h,s3,c1,2,measured,1,x,1,1,300,docked,128,4,45\n";
  const ScriptRun r =
      Script({"/usr/bin/env", "PYTHONPATH=" + SourcePath("scripts"),
              fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3", "-m",
              "rmslab_launcher.study_stats", dir + "/study.csv", dir, "--conditions", "c0,c1"},
             dir + "/stats.log", 120);
  ASSERT_EQ(r.rc, 0) << r.out;
  const json s = json::parse(ReadFile(dir + "/stats.json"), nullptr, false);
  ASSERT_TRUE(s.is_object());
  EXPECT_EQ(s["trials"], 6);
  // c0's task times 100, 90, 120: mean 103.333, s 15.2753, t(0.975, 2)
  // 4.302653: 103.333 +- 37.946.
  const json& t0 = s["conditions"]["c0"]["task_time_s"];
  EXPECT_NEAR(t0["mean"].get<double>(), 103.3333, 1e-3);
  EXPECT_NEAR(t0["sd"].get<double>(), 15.2753, 1e-3);
  EXPECT_NEAR(t0["low"].get<double>(), 65.387, 1e-2);
  EXPECT_NEAR(t0["high"].get<double>(), 141.280, 1e-2);
  // Three of three docked: Wilson's interval 0.4385 to 1.
  const json& d0 = s["conditions"]["c0"]["docked_rate"];
  EXPECT_NEAR(d0["p"].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(d0["low"].get<double>(), 0.4385, 1e-3);
  EXPECT_NEAR(d0["high"].get<double>(), 1.0, 1e-9);
  // Balanced: the mixed model's difference is the difference of the means,
  // (110 + 104 + 128 - 100 - 90 - 120) / 3 = 10.667 s; each subject's own
  // differences (10, 14, 8) are close, so its interval excludes 0.
  const json& m = s["models"]["task_time_s"];
  ASSERT_TRUE(m["fitted"].get<bool>()) << m.dump();
  EXPECT_EQ(m["reference"], "c0");
  ASSERT_EQ(m["differences"].size(), 1u);
  EXPECT_NEAR(m["differences"][0]["estimate"].get<double>(), 10.6667, 1e-3);
  EXPECT_GT(m["differences"][0]["low"].get<double>(), 0.0);
  EXPECT_LT(m["differences"][0]["p"].get<double>(), 0.05);
  // Collisions: c0 1, 0, 2 and c1 2, 3, 4: a difference of 2.
  EXPECT_NEAR(s["models"]["collisions"]["differences"][0]["estimate"].get<double>(), 2.0, 1e-6);
  const std::string page = ReadFile(dir + "/study.html");
  EXPECT_NE(page.find("statsmodels MixedLM"), std::string::npos);
  EXPECT_NE(page.find("c1 minus c0"), std::string::npos);
  EXPECT_NE(page.find("higher with c1: the 95 % interval lies above 0"), std::string::npos);
  // The page in a real browser: its table, curves and comparisons, and
  // axe-core's accessibility check.
  const ScriptRun browser =
      Script({"/usr/bin/env", "node", SourcePath("tests/browser/study_page.mjs"),
              dir + "/study.html", "2", "3"},
             dir + "/browser.log", 120);
  EXPECT_EQ(browser.rc, 0) << browser.out;
  if (!::testing::Test::HasFailure()) fs::remove_all(dir);
}

// Designs judged by flying them: a boom far too short to fly the task fails
// in every run, the flown arm docks in (nearly) every one; the same seed
// gives the same flights whatever the number of threads.
std::size_t FilesIn(const std::string& dir) {
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += e.is_regular_file();
  return n;
}

// flights.csv's rows as maps, column name to text.
std::vector<std::map<std::string, std::string>> ReadFlights(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> head;
  std::vector<std::map<std::string, std::string>> rows;
  auto split = [](std::string l) {
    if (!l.empty() && l.back() == '\r') l.pop_back();  // (Python's csv ends its lines so)
    std::vector<std::string> v;
    std::size_t at = 0;
    for (std::size_t c; (c = l.find(',', at)) != std::string::npos; at = c + 1)
      v.push_back(l.substr(at, c - at));
    v.push_back(l.substr(at));
    return v;
  };
  if (std::getline(in, line)) head = split(line);
  while (std::getline(in, line)) {
    const auto v = split(line);  // (no field of these holds a comma but `failure`'s, kept whole)
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < head.size() && i < v.size(); ++i) row[head[i]] = v[i];
    rows.push_back(row);
  }
  return rows;
}

// A closed-loop sweep (docs/studies.md "Designs judged by flying them"): a
// boom too short to reach the bar fails for both kinds of virtual subject,
// every run; the recorded design docks for both; the autopilot and the
// scripted operator (status screen and keys alone, offline) each fly;
// the same seed gives the same flights on one thread or two.
TEST(Study, AClosedLoopSweepFliesEachDesignByVirtualSubjects) {
  const std::string dir = testing::MakeTempDir("sweep_closed");
  std::printf("closed-loop sweep: seed 5, 6 autopilot and 3 scripted runs a design\n");
  const auto sweep = [&](const std::string& out, const std::string& jobs, const char* subjects,
                         const char* runs, const std::string& cache = "") {
    return Script({Lab(),
                   "sweep",
                   "--closed-loop",
                   "--vary",
                   "arm.upper_boom_ft=8,20.9",
                   "--subjects",
                   subjects,
                   "--runs",
                   runs,
                   "--runs-per-cell",
                   "2",
                   "--seed",
                   "5",
                   "--max-s",
                   "150",
                   "--jobs",
                   jobs,
                   "--out",
                   out,
                   "--cache",
                   cache.empty() ? out + "-cache" : cache,
                   "--no-build"},
                  out + ".log", 300);
  };
  const ScriptRun a = sweep(dir + "/a", "1", "autopilot", "6");
  ASSERT_EQ(a.rc, 0) << a.out;
  const ScriptRun s = sweep(dir + "/s", "2", "scripted", "3");
  ASSERT_EQ(s.rc, 0) << s.out;
  for (const auto& [name, runs] : {std::pair<std::string, int>{"a", 6}, {"s", 3}}) {
    std::string table = dir;
    table.append("/").append(name).append("/designs.json");
    const json d = json::parse(ReadFile(table), nullptr, false);
    ASSERT_TRUE(d.is_object()) << name;
    ASSERT_EQ(d["designs"].size(), 2u) << name;
    EXPECT_EQ(d["designs"][0]["arm.upper_boom_ft"], "8");  // as given
    EXPECT_EQ(d["designs"][0]["runs"], runs);
    EXPECT_EQ(d["designs"][0]["docked"], 0) << name << ": an 8 ft upper boom flew the task";
    EXPECT_EQ(d["designs"][1]["docked"].get<int>(), runs) << d["designs"][1].dump();
    EXPECT_LT(d["designs"][0]["docked_high"].get<double>(), 0.71);
  }
  EXPECT_NE(a.out.find("autopilot: docked 0 of 6"), std::string::npos) << a.out;
  EXPECT_NE(s.out.find("scripted: docked 0 of 3"), std::string::npos) << s.out;
  EXPECT_NE(s.out.find("not docked: 3 x no acquisition by 150 s"), std::string::npos) << s.out;
  // The scripted operator's flights: keys counted, every run its own.
  std::set<std::string> reactions;
  for (const auto& row : ReadFlights(dir + "/s/flights.csv")) {
    EXPECT_EQ(row.at("subject"), "scripted");
    EXPECT_GT(std::stoi(row.at("key_actions")), 10) << row.at("run");
    reactions.insert(row.at("reaction_s"));
  }
  EXPECT_EQ(reactions.size(), 3u) << "each design's runs draw the same 3 subjects, each its own";
  // Deterministic: two threads give the same flights as one (a cache of its own).
  const ScriptRun b = sweep(dir + "/b", "2", "autopilot", "6");
  ASSERT_EQ(b.rc, 0) << b.out;
  EXPECT_EQ(ReadFile(dir + "/a/flights.csv"), ReadFile(dir + "/b/flights.csv"));
  // Run again into the same cache: nothing flown, the same table.
  const ScriptRun again = sweep(dir + "/a2", "2", "autopilot", "6", dir + "/a-cache");
  ASSERT_EQ(again.rc, 0) << again.out;
  EXPECT_NE(again.out.find("6 cells, 6 already in the cache"), std::string::npos) << again.out;
  EXPECT_EQ(ReadFile(dir + "/a/flights.csv"), ReadFile(dir + "/a2/flights.csv"));
  // A design the configuration refuses is refused naming the key.
  const ScriptRun bad = Script({Lab(), "sweep", "--closed-loop", "--vary", "arm.upper_boom_ft=-1",
                                "--runs", "2", "--out", dir + "/bad", "--no-build"},
                               dir + "/bad.log", 60);
  EXPECT_EQ(bad.rc, 2);
  EXPECT_NE(bad.out.find("arm.upper_boom_ft"), std::string::npos) << bad.out;
  if (!::testing::Test::HasFailure()) fs::remove_all(dir);
}

// The same closed-loop sweep flown where a lab flies its sweeps
// (docs/studies.md "Designs judged by flying them"): its cells on the lab's
// hosts through GNU parallel (network-namespace hosts, as the replay
// sweep's test), and as a Slurm array job whose tasks the test runs as
// Slurm would; both tables are the one this machine flies, flight for flight.
TEST(Study, AClosedLoopSweepFliesOnTheLabsHostsAndAsASlurmArrayJob) {
  const std::string dir = testing::MakeTempDir("sweep_closed_hosts");
  std::printf("closed-loop sweep: seed 9, 2 runs a design and subject\n");
  const auto sweep = [&](const std::string& name, std::vector<std::string> more) {
    std::vector<std::string> argv = {Lab(),
                                     "sweep",
                                     "--closed-loop",
                                     "--vary",
                                     "arm.upper_boom_ft=8,20.9",
                                     "--runs",
                                     "2",
                                     "--runs-per-cell",
                                     "1",
                                     "--seed",
                                     "9",
                                     "--max-s",
                                     "120",
                                     "--out",
                                     dir + "/" + name,
                                     "--cache",
                                     dir + "/cache-" + name,
                                     "--no-build"};
    argv.insert(argv.end(), more.begin(), more.end());
    return Script(argv, dir + "/" + name + ".log", 400);
  };
  const ScriptRun here = sweep("here", {});
  ASSERT_EQ(here.rc, 0) << here.out;
  const std::string flights = ReadFile(dir + "/here/flights.csv");
  EXPECT_EQ(ReadFlights(dir + "/here/flights.csv").size(), 8u);

  testing::NetnsLab net("fl" + std::to_string(getpid() % 100000), dir, 2);
  ASSERT_TRUE(net.ok()) << ReadFile(dir + "/netns.log");
  const std::string lab = dir + "/lab.toml";
  std::ofstream(lab)
      << "[hosts]\noperator_station = \"" << net.host(1) << "\"\ndynamics_proc = \"" << net.host(2)
      << "\"\nscene_proc = \"" << net.host(1) << "\"\nesg_renderer = \"" << net.host(2)
      << "\"\nrecorder = \"localhost\"\n[lcm]\ngroup = \"239.255.76.69\"\nport = 7670\nttl = 1\n"
         "[remote]\nroot = \"\"\nbuild = \"\"\n"
         "[sweep]\nhosts = [\""
      << net.host(1) << "\", \"" << net.host(2) << "\"]\njobs_per_host = 1\n";
  const ScriptRun across = sweep("across", {"--hosts", lab});
  ASSERT_EQ(across.rc, 0) << across.out;
  EXPECT_EQ(ReadFile(dir + "/across/flights.csv"), flights);
  // Every batch ran on one of the lab's hosts (GNU parallel's joblog).
  std::set<std::string> hosts;
  for (const auto& e : fs::directory_iterator(dir + "/across")) {
    if (e.path().filename().string().rfind("joblog-", 0) != 0) continue;
    std::istringstream jl(ReadFile(e.path().string()));
    std::string line;
    std::getline(jl, line);  // the header
    while (std::getline(jl, line)) {
      std::istringstream fields(line);
      std::string field[7];  // Seq, Host, Starttime, JobRuntime, Send, Receive, Exitval
      for (std::string& f : field) std::getline(fields, f, '\t');
      hosts.insert(field[1]);
      EXPECT_NE(field[1].find("netns-login"), std::string::npos) << line;
      EXPECT_EQ(field[6], "0") << line;
    }
  }
  EXPECT_EQ(hosts.size(), 2u) << "both hosts took cells";
  net.Down();

  ScriptRun job = sweep("slurm", {"--slurm"});
  ASSERT_EQ(job.rc, 0) << job.out;
  const std::string sbatch = ReadFile(dir + "/slurm/sweep.sbatch");
  EXPECT_NE(sbatch.find("#SBATCH --array=1-8"), std::string::npos) << sbatch;
  EXPECT_FALSE(fs::exists(dir + "/slurm/designs.csv")) << "--slurm flew the cells itself";
  // Before the job: every cell missing, nothing flown, said.
  ScriptRun table = sweep("slurm", {"--cached-only"});
  EXPECT_EQ(table.rc, 1) << table.out;
  EXPECT_NE(table.out.find("not in the cache"), std::string::npos) << table.out;
  for (int task = 8; task >= 1; --task) {  // as Slurm runs them: any order
    const std::string log = dir + "/task-" + std::to_string(task) + ".log";
    testing::Subprocess t({"/bin/sh", dir + "/slurm/sweep.sbatch"}, log,
                          {"SLURM_ARRAY_TASK_ID=" + std::to_string(task)});
    ASSERT_EQ(t.Wait(120), 0) << ReadFile(log);
    EXPECT_EQ(ReadFile(log).rfind(std::to_string(task) + "\t{\"flights\":[", 0), 0u)
        << ReadFile(log);
  }
  table = sweep("slurm", {"--cached-only"});
  ASSERT_EQ(table.rc, 0) << table.out;
  EXPECT_NE(table.out.find("8 cells, 8 already in the cache"), std::string::npos) << table.out;
  EXPECT_EQ(ReadFile(dir + "/slurm/flights.csv"), flights);
  // A cells.tsv edited by hand (design 1's 8 ft made 20.9 ft) flies nothing
  // under the old key, and caches nothing.
  std::string tsv = ReadFile(dir + "/slurm/cells.tsv");
  const std::size_t at = tsv.find("arm.upper_boom_ft=8");
  ASSERT_NE(at, std::string::npos);
  tsv.replace(at, std::string("arm.upper_boom_ft=8").size(), "arm.upper_boom_ft=20.9");
  std::ofstream(dir + "/slurm/cells.tsv") << tsv;
  const std::size_t cached = FilesIn(dir + "/cache-slurm");
  fs::remove_all(dir + "/cache-slurm");
  fs::create_directories(dir + "/cache-slurm");
  testing::Subprocess edited({"/bin/sh", dir + "/slurm/sweep.sbatch"}, dir + "/edited.log",
                             {"SLURM_ARRAY_TASK_ID=1"});
  EXPECT_NE(edited.Wait(120), 0);
  EXPECT_NE(ReadFile(dir + "/edited.log").find("is not its options' SHA-256"), std::string::npos)
      << ReadFile(dir + "/edited.log");
  EXPECT_EQ(FilesIn(dir + "/cache-slurm"), 0u) << "an edited cell was cached";
  EXPECT_EQ(cached, 8u);
  if (!::testing::Test::HasFailure()) fs::remove_all(dir);
}

// A lesson (docs/lessons.md) in a live session flown by the autopilot: each
// event fires once, at its time, on entering its mode, when its condition
// first holds; the DCP takes each; the summary lists them as the operator
// station's commands; and the session re-simulates word for word.
TEST(Lesson, ScriptedEventsFireInASessionAndReSimulateWordForWord) {
  const std::string dir = testing::MakeTempDir("lesson");
  const ScriptRun r = Script({Lab(), "demo", "--lesson", SourcePath("config/lessons/example.toml"),
                              "--no-build", "--speed", "4", "--no-video", "--png-every", "0",
                              "--out", dir + "/s", "--lcm-url", testing::UniqueLcmUrl(9560)},
                             dir + "/demo.log", 300);
  ASSERT_EQ(r.rc, 0) << r.out;
  EXPECT_TRUE(fs::exists(dir + "/s/lesson.toml"));
  const json sum = json::parse(ReadFile(dir + "/s/summary.json"), nullptr, false);
  ASSERT_TRUE(sum.is_object());
  EXPECT_TRUE(sum["docked"].get<bool>());
  EXPECT_TRUE(sum["resimulation"]["exact"].get<bool>());
  const json& modes = sum["mode_changes"];
  ASSERT_EQ(modes.size(), 2u);
  const json& m = sum["malfunctions"];
  ASSERT_EQ(m.size(), 3u) << m.dump(1);
  // at 15 s: camera 4 lost (taken by the DCP within a frame or a few of the
  // station's sending it, however loaded the machine).
  EXPECT_EQ(m[0]["injected"][0], "camera 4 lost");
  EXPECT_GE(m[0]["time_s"].get<double>(), 15.0 - 1e-9);
  EXPECT_LT(m[0]["time_s"].get<double>(), 16.0);
  // on entering Mode 2: repaired.
  EXPECT_EQ(m[1]["repaired"][0], "camera 4 lost");
  EXPECT_GE(m[1]["time_s"].get<double>(), modes[0]["time_s"].get<double>());
  EXPECT_LT(m[1]["time_s"].get<double>(), modes[0]["time_s"].get<double>() + 1.0);
  // within 5 ft of the port (Mode 3): joint 6 slow.
  EXPECT_EQ(m[2]["injected"][0], "joint 6 slow 2");
  EXPECT_GT(m[2]["time_s"].get<double>(), modes[1]["time_s"].get<double>());
  int from_station = 0;
  for (const json& c : sum["control"]) from_station += c.value("process", "") == "operator_station";
  EXPECT_EQ(from_station, 3) << sum["control"].dump(1);
  const json stats = json::parse(ReadFile(dir + "/s/stats/operator_station.json"), nullptr, false);
  EXPECT_EQ(stats["counters"].value("lesson.events", 0), 3);
  if (!::testing::Test::HasFailure()) fs::remove_all(dir);
}

}  // namespace
}  // namespace rms
