// Every session is data (docs/sessions.md "Re-simulation", "Attempts"):
// a session flown by hand in a real terminal, on a machine whose every core
// is busy, with a reset, a checkpoint restored, the DCP killed and
// restarted, and a freeze, re-simulates word for word; its summary lists
// every attempt; a log that misses the session's start re-simulates from
// the DCP's state logged later, and one that lacks every state says so.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>
#include <thread>

#include "lab_processes.h"
#include "subprocess.h"
#include "tmux.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using testing::ReadFile;
using testing::Script;
using testing::ScriptRun;
using testing::SourcePath;
using testing::Subprocess;
using testing::Tmux;

void Sleep(double s) { std::this_thread::sleep_for(std::chrono::duration<double>(s)); }

// Busy processes, one a core, for as long as the object lives.
class CpuLoad {
 public:
  explicit CpuLoad(const std::string& dir) {
    const long cores = std::max(1L, sysconf(_SC_NPROCESSORS_ONLN));
    for (long i = 0; i < cores; ++i) {
      busy_.push_back(std::make_unique<Subprocess>(
          std::vector<std::string>{"/usr/bin/timeout", "600", "/bin/sh", "-c", "while :; do :; done"}, dir + "/busy.log"));
    }
    std::printf("CPU load: %ld busy processes\n", cores);
  }
  ~CpuLoad() {
    for (auto& b : busy_) {
      b->Signal(SIGKILL);
      b->Wait(5);
    }
  }

 private:
  std::vector<std::unique_ptr<Subprocess>> busy_;
};

bool WaitFor(const std::function<bool()>& done, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    Sleep(0.1);
  }
  return done();
}

int PidOf(const std::string& out, const std::string& process) {
  std::ifstream f(out + "/run/" + process + ".pid");
  int pid = 0;
  return (f >> pid) ? pid : -1;
}

ScriptRun Control(const std::string& out, const std::vector<std::string>& args, const std::string& log) {
  std::vector<std::string> cmd = {SourcePath("scripts/lab"), "control", "--session", out};
  cmd.insert(cmd.end(), args.begin(), args.end());
  return Script(cmd, log, 60);
}

// Copies SESSION to DIR with only the log events `keep` says yes to.
void CopyWithLog(const std::string& from, const std::string& to,
                 const std::function<bool(const lcm::LogEvent&, std::int64_t first_us)>& keep) {
  fs::create_directories(to);
  for (const char* f : {"manifest.json", "config.toml"}) fs::copy_file(from + "/" + f, to + "/" + f);
  fs::copy(from + "/run", to + "/run", fs::copy_options::recursive);
  lcm::LogFile in(from + "/lcmlog", "r"), out(to + "/lcmlog", "w");
  std::int64_t first = -1;
  while (const lcm::LogEvent* ev = in.readNextEvent()) {
    if (first < 0) first = ev->timestamp;
    if (keep(*ev, first)) out.writeEvent(const_cast<lcm::LogEvent*>(ev));
  }
}

class HandFlownSession : public ::testing::Test {
 protected:
  // Flown once, by hand in tmux, under CPU load; shared by the tests that read it.
  static void SetUpTestSuite() {
    tmp_ = new std::string(testing::MakeTempDir("handflown"));
    out_ = new std::string(*tmp_ + "/session");
    CpuLoad load(*tmp_);
    Tmux tmux(*tmp_);
    const std::string cmd = "RMSLAB_BUILD=" RMSLAB_BUILD_DIR " " + SourcePath("scripts/lab") +
                            " demo --by-hand --no-build --out " + *out_ + " --lcm-url '" +
                            testing::UniqueLcmUrl(9700) +
                            "' --png-every 0 --no-video --width 160 --height 120 --subject ann --note 'first try' >" +
                            *tmp_ + "/lab.log 2>&1; echo $? >" + *tmp_ + "/lab.rc";
    ASSERT_EQ(tmux.Start(cmd, 120, 45), 0);
    const std::string op_log = *out_ + "/logs/operator_station.log";
    ASSERT_TRUE(WaitFor([&] { return (PidOf(*out_, "operator_station") > 0 && fs::exists(op_log)) ||
                                      fs::exists(*tmp_ + "/lab.rc"); }, 90) && !fs::exists(*tmp_ + "/lab.rc"))
        << ReadFile(*tmp_ + "/lab.log");
    Sleep(2.0);
    auto press = [&](const std::string& key, int n, double each_s) {
      for (int i = 0; i < n; ++i) {
        tmux.Send({key});
        Sleep(each_s);
      }
    };
    press("w", 4, 0.3);  // attempt 1: away from the start
    press("d", 3, 0.3);
    Sleep(1.0);
    press("BSpace", 1, 1.0);  // reset: attempt 2
    press("s", 3, 0.3);
    ASSERT_EQ(Control(*out_, {"checkpoint", "cp1"}, *tmp_ + "/cp.log").rc, 0) << ReadFile(*tmp_ + "/cp.log");
    press("a", 4, 0.3);
    ASSERT_EQ(Control(*out_, {"restore", "cp1", "--run"}, *tmp_ + "/restore.log").rc, 0)
        << ReadFile(*tmp_ + "/restore.log");  // attempt 3
    press("w", 2, 0.3);
    const int dcp = PidOf(*out_, "dynamics_proc");
    ASSERT_GT(dcp, 0);
    kill(dcp, SIGKILL);  // the launcher restarts it; it resumes its last state
    ASSERT_TRUE(WaitFor([&] { return PidOf(*out_, "dynamics_proc") > 0 && PidOf(*out_, "dynamics_proc") != dcp; }, 60));
    Sleep(2.0);
    press("d", 3, 0.3);
    press("p", 1, 1.5);  // freeze, a step, run
    press("period", 1, 0.5);
    press("p", 1, 1.0);
    press("e", 2, 0.3);
    press("Q", 1, 0.5);
    ASSERT_TRUE(WaitFor([&] { return fs::exists(*tmp_ + "/lab.rc"); }, 120)) << ReadFile(*tmp_ + "/lab.log");
    EXPECT_EQ(ReadFile(*tmp_ + "/lab.rc"), "0\n") << ReadFile(*tmp_ + "/lab.log");
  }
  static void TearDownTestSuite() {
    fs::remove_all(*tmp_);
    delete tmp_;
    delete out_;
  }
  static std::string* tmp_;
  static std::string* out_;
};
std::string* HandFlownSession::tmp_ = nullptr;
std::string* HandFlownSession::out_ = nullptr;

TEST_F(HandFlownSession, ReSimulatesWordForWord) {
  const ScriptRun r = Script({SourcePath("scripts/lab"), "resim", *out_, "--no-build"}, *tmp_ + "/resim.log", 120);
  EXPECT_EQ(r.rc, 0) << r.out;
  EXPECT_NE(r.out.find("identical, word for word"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("note:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("the DCP's whole state agreed"), std::string::npos) << r.out;
}

TEST_F(HandFlownSession, TheSummaryListsEveryAttempt) {
  const auto s = nlohmann::json::parse(ReadFile(*out_ + "/summary.json"));
  ASSERT_TRUE(s.contains("attempts")) << s.dump(2).substr(0, 2000);
  const auto& a = s["attempts"];
  ASSERT_GE(a.size(), 3u) << a.dump(2);
  EXPECT_EQ(a[0]["started_by"], "start");
  EXPECT_EQ(a[1]["started_by"], "reset");
  EXPECT_EQ(a[2]["started_by"], "restore");
  double total = 0;
  for (const auto& x : a) {
    EXPECT_TRUE(x.contains("phase_durations_s"));
    EXPECT_TRUE(x.contains("scorecard"));
    EXPECT_GE(x["duration_s"].get<double>(), 0.0);
    total += x["duration_s"].get<double>();
  }
  EXPECT_NEAR(total, s["totals"]["duration_s"].get<double>(), 0.2);
  EXPECT_GE(s["totals"]["resets"].get<int>(), 1);
  EXPECT_GE(s["totals"]["restores"].get<int>(), 1);
  EXPECT_GE(s["totals"]["restarts"].get<int>(), 1);
  const auto m = nlohmann::json::parse(ReadFile(*out_ + "/manifest.json"));
  EXPECT_EQ(m["subject"], "ann");
  EXPECT_EQ(m["note"], "first try");
}

TEST_F(HandFlownSession, ALogThatMissesTheStartReSimulatesFromALaterState) {
  // The recorder started 6 s late: the DCP's start and its first states are
  // not in the log; the first periodic state (every 5 s of frames) is.
  const std::string late = *tmp_ + "/late";
  CopyWithLog(*out_, late, [](const lcm::LogEvent& ev, std::int64_t first) { return ev.timestamp - first > 6000000; });
  const ScriptRun r = Script({SourcePath("scripts/lab"), "resim", late, "--no-build"}, *tmp_ + "/late.log", 120);
  EXPECT_EQ(r.rc, 0) << r.out;
  EXPECT_NE(r.out.find("identical, word for word"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not re-simulated: the log starts at DCP frame"), std::string::npos) << r.out;
}

TEST_F(HandFlownSession, ALogWithoutTheDcpsStateSaysWhatIsMissing) {
  const std::string bare = *tmp_ + "/bare";
  CopyWithLog(*out_, bare, [](const lcm::LogEvent& ev, std::int64_t first) {
    return ev.timestamp - first > 3000000 && ev.channel.rfind("RMS_DCP_STATE", 0) != 0;
  });
  const ScriptRun r = Script({SourcePath("scripts/lab"), "resim", bare, "--no-build"}, *tmp_ + "/bare.log", 120);
  EXPECT_NE(r.rc, 0) << r.out;
  EXPECT_NE(r.out.find("holds no RMS_DCP_STATE"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace rms
