// Stalls (long label: scripts/test leaves it out; ctest -L long runs it):
// each process and the recorder stopped (SIGSTOP) for 4 s in turn while the
// autopilot flies (docs/sessions.md "Faults").
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <regex>
#include <thread>

#include "live_session.h"
#include "session_files.h"
#include "subprocess.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using testing::Counter;
using testing::LiveSession;
using testing::ReadFile;
using testing::ReadJson;
using testing::Script;

void Sleep(double s) { std::this_thread::sleep_for(std::chrono::duration<double>(s)); }

// Stalls (long label: scripts/test leaves it out; ctest -L long runs it):
// each process and the recorder stopped (SIGSTOP) for 4 s in turn while
// the autopilot flies. A stopped receiver wakes to frames that waited
// beyond the link's delay and drops them, counted (dropped.late), instead
// of acting on them in a burst; the recorder's gap is reported as what the
// network's recorder missed, per channel, and the record (made from the
// processes' journals) loses nothing; the autopilot still docks.
TEST(SessionStallsLong, EachProcessAndTheRecorderStoppedIsSurvivedAndReported) {
  const std::string tmp = testing::MakeTempDir("stalls");
  LiveSession s(tmp, testing::UniqueLcmUrl(8720));
  ASSERT_TRUE(s.WaitRunning(60)) << ReadFile(s.log());
  Sleep(2);
  for (const char* p :
       {"dynamics_proc", "scene_proc", "esg_renderer", "lcm-logger", "operator_station"}) {
    const int pid = s.pid(p);
    ASSERT_GT(pid, 0) << p;
    std::printf("SIGSTOP %s (pid %d) for 4 s\n", p, pid);
    kill(pid, SIGSTOP);
    Sleep(4);
    kill(pid, SIGCONT);
    Sleep(3);
  }
  ASSERT_EQ(s.Wait(300), 0) << ReadFile(s.log());
  const std::string out = s.out();
  const nlohmann::json sum = ReadJson(out + "/summary.json");
  std::printf("refused %s\nrecord %s\n", sum["frames"]["refused"].dump().c_str(),
              sum["record"].dump().c_str());
  EXPECT_TRUE(sum.value("docked", false));
  // The DCP stopped 4 s: what waited for it was dropped, not run in a burst
  // (a burst would overflow the receivers downstream: their gaps stay small).
  EXPECT_GT(Counter(out, "dynamics_proc", "dropped.late"), 30);
  EXPECT_GT(Counter(out, "scene_proc", "dropped.late"), 30);
  EXPECT_GT(Counter(out, "esg_renderer", "dropped.late"), 30);
  EXPECT_GT(sum["frames"]["refused"]["late"].get<long>(), 90);
  // The recorder stopped 4 s: what the network delivered has a gap, said
  // per channel; the record (made from the journals) has none, and the
  // session re-simulates (docs/sessions.md "The record").
  EXPECT_GT(sum["record"]["network"]["missed"].get<long>(), 0) << sum["record"].dump();
  EXPECT_EQ(sum["record"]["lost"].get<long>(), 0) << sum["record"].dump();
  for (const char* ch : {"RMS_OPERATOR_INPUT", "RMS_DCP_FRAME"}) {
    const auto& r = sum["record"]["by_channel"][ch];
    EXPECT_EQ(r["published"], r["logged"]) << ch;
    EXPECT_GT(sum["record"]["network"]["missed_by_channel"][ch].get<long>(), 0) << ch;
  }
  EXPECT_EQ(sum["resimulation"]["verdict"], "identical") << sum["resimulation"].dump();
  const auto brief = Script({testing::BuildPath("tools/rms_session"), "summary", out, "--brief",
                             "--out", tmp + "/summary.json"},
                            tmp + "/brief.log", 60);
  EXPECT_NE(brief.out.find("the network's recorder missed"), std::string::npos) << brief.out;
  EXPECT_EQ(brief.out.find("the record lost"), std::string::npos) << brief.out;
  EXPECT_EQ(brief.out.find("the record lacks"), std::string::npos) << brief.out;
  // ... and in the report, apart from the link's losses.
  const auto report =
      Script({testing::BuildPath("tools/rms_report"), out, "--out", tmp + "/report.html"},
             tmp + "/report.log", 120);
  ASSERT_EQ(report.rc, 0) << report.out;
  const std::string html = ReadFile(tmp + "/report.html");
  EXPECT_TRUE(std::regex_search(
      html, std::regex("missed by the network's recorder \\(the record has them from the "
                       "journals\\): RMS_DCP_FRAME</td><td>[1-9]")))
      << html.substr(html.find("<h2>Losses"), 1500);
  fs::remove_all(tmp);
}

}  // namespace
}  // namespace rms
