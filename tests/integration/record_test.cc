// The record does not depend on one listener keeping up (docs/sessions.md
// "The record", "Does it re-simulate"): scripts/lab demo as a user runs it,
// on a machine with a busy loop on every core, the network's recorder
// stopped (SIGSTOP) for 10 s mid-flight. The recorder misses what was sent
// meanwhile; the record (made from the processes' journals) holds every
// frame each process published, the session says last that it
// re-simulates, and it does.
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "cpu_load.h"
#include "subprocess.h"

namespace rms {
namespace {

namespace fs = std::filesystem;
using testing::ReadFile;
using testing::SourcePath;
using testing::Subprocess;

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream f(path);
  return nlohmann::json::parse(f);
}

// The launcher's last line that is not empty.
std::string LastLine(const std::string& text) {
  std::string last, line;
  std::istringstream in(text);
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

pid_t PidOf(const std::string& out, const std::string& process) {
  std::ifstream f(out + "/run/" + process + ".pid");
  pid_t pid = 0;
  return (f >> pid) ? pid : 0;
}

TEST(Record, TheRecorderStoppedOnABusyMachineLosesNothingAndItReSimulates) {
  const std::string tmp = testing::MakeTempDir("record");
  const std::string out = tmp + "/session";
  testing::CpuLoad load(tmp);
  Subprocess lab({SourcePath("scripts/lab"), "demo", "--no-build", "--out", out, "--lcm-url",
                  testing::UniqueLcmUrl(8500), "--speed", "2", "--png-every", "0", "--no-video",
                  "--width", "320", "--height", "240"},
                 tmp + "/lab.log", {std::string("RMSLAB_BUILD=") + RMSLAB_BUILD_DIR});
  ASSERT_TRUE(testing::WaitForFile(out + "/run/operator_station.ready", 90))
      << ReadFile(tmp + "/lab.log");
  std::this_thread::sleep_for(std::chrono::seconds(3));
  const pid_t recorder = PidOf(out, "lcm-logger");
  ASSERT_GT(recorder, 0);
  std::printf("SIGSTOP to the recorder (pid %d) for 10 s\n", recorder);
  ASSERT_EQ(kill(recorder, SIGSTOP), 0);
  std::this_thread::sleep_for(std::chrono::seconds(10));
  ASSERT_EQ(kill(recorder, SIGCONT), 0);
  ASSERT_EQ(lab.Wait(240), 0) << ReadFile(tmp + "/lab.log");
  const std::string said = ReadFile(tmp + "/lab.log");

  const nlohmann::json s = ReadJson(out + "/summary.json");
  const nlohmann::json record = ReadJson(out + "/record.json");
  std::printf("the network's recorder missed %s; record %s\n",
              record["wire"]["missed"].dump().c_str(), record["lcmlog"].dump().c_str());
  // The recorder was stopped for most of the flight: it missed frames...
  EXPECT_GT(s["record"]["network"]["missed"].get<long>(), 30) << s["record"].dump();
  EXPECT_GT(record["wire"]["missed"]["by_channel"]["RMS_DCP_FRAME"].get<long>(), 30);
  // ... and the record has every one each process published (by its
  // journal) and sent (by its own count).
  EXPECT_EQ(s["record"]["source"], "journals");
  EXPECT_EQ(s["record"]["lost"].get<long>(), 0) << s["record"].dump();
  for (const auto& [channel, r] : s["record"]["by_channel"].items()) {
    EXPECT_GT(r["published"].get<long>(), 0) << channel;
    EXPECT_EQ(r["logged"], r["published"]) << channel;
  }
  // Each numbered stream's distinct frame numbers, which the summary holds
  // the log against: here every number was sent once.
  ASSERT_TRUE(record.contains("frames_by_channel")) << record.dump();
  EXPECT_EQ(record["frames_by_channel"].size(), 4u) << record["frames_by_channel"].dump();
  for (const auto& [channel, n] : record["frames_by_channel"].items()) {
    long messages = 0;
    for (const auto& jf : record["journals"]) messages += jf["by_channel"].value(channel, 0L);
    EXPECT_EQ(n.get<long>(), messages) << channel;
    EXPECT_EQ(s["record"]["by_channel"][channel]["published"], n) << channel;
  }
  EXPECT_EQ(s["log"]["dcp_frames"], s["frames"]["dcp_published"]);
  EXPECT_EQ(s["log"]["operator_frames"], s["frames"]["operator_published"]);
  EXPECT_EQ(s["log"]["esg_frames"], s["frames"]["esg_published"]);
  EXPECT_EQ(s["record"]["journal_failed"].get<long>(), 0);
  EXPECT_FALSE(fs::exists(out + "/journal")) << "the journals are in lcmlog and gone";
  EXPECT_TRUE(fs::exists(out + "/wire.lcmlog"));
  EXPECT_NE(said.find("the network's recorder missed"), std::string::npos) << said;

  // It says last that it re-simulates, and it does.
  EXPECT_EQ(LastLine(said).rfind("lab: re-simulates: identical (", 0), 0u) << said;
  const nlohmann::json v = ReadJson(out + "/resimulation.json");
  EXPECT_EQ(v["verdict"], "identical") << v.dump(2);
  EXPECT_TRUE(v["exact"].get<bool>()) << v.dump(2);
  EXPECT_EQ(v["frames_compared"], s["frames"]["dcp_published"]);
  EXPECT_EQ(s["resimulation"]["verdict"], "identical");
  const auto again =
      testing::Script({testing::BuildPath("tools/rms_resim"), out, "--quiet"}, tmp + "/resim.log");
  EXPECT_EQ(again.rc, 0) << again.out;
  fs::remove_all(tmp);
}

}  // namespace
}  // namespace rms
