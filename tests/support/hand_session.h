#pragma once
// `scripts/lab demo --by-hand` in a real terminal (tmux), as a person starts
// it from the README, on a private port; flown by the scripted operator
// (scripted_operator.h). The budgets the whole flight is held to.
#include <unistd.h>

#include <filesystem>
#include <gtest/gtest.h>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "scripted_operator.h"
#include "subprocess.h"
#include "tmux.h"

namespace rms::testing {

inline constexpr double kReactionS = 0.3;      // after every look at the screen
inline constexpr int kKeyBudget = 100;         // key actions for the whole flight
inline constexpr double kTimeBudgetS = 150.0;  // session time for the whole flight

struct HandSession {
  std::string dir, out;
  std::unique_ptr<Tmux> tmux;
  explicit HandSession(const std::string& tag, int port)
      : dir(MakeTempDir(tag)), out(dir + "/session") {
    tmux = std::make_unique<Tmux>(dir);
    // As a person starts it from the README, on a private port.
    const std::string cmd =
        "RMSLAB_BUILD=" + std::string(RMSLAB_BUILD_DIR) + " " + SourcePath("scripts/lab") +
        " demo --by-hand --no-build --no-video --png-every 0 --out " + out + " --lcm-url '" +
        UniqueLcmUrl(port) + "' 2>" + dir + "/lab.log; echo $? >" + dir + "/lab.rc.tmp; mv " + dir +
        "/lab.rc.tmp " + dir + "/lab.rc";  // whole when it is there
    tmux->Start(cmd, 132, 50);
  }
  // Q, and the launcher's summary.
  nlohmann::json Quit() {
    tmux->Send({"Q"});
    for (int i = 0; i < 300 && !std::filesystem::exists(dir + "/lab.rc"); ++i) usleep(100000);
    if (!std::filesystem::exists(out + "/summary.json")) return nullptr;
    return nlohmann::json::parse(ReadFile(out + "/summary.json"));
  }
  ~HandSession() {
    tmux->Stop();
    if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
  }
};

inline std::string Transcript(const FlightReport& r) {
  std::string t;
  for (const auto& l : r.transcript) t += l + "\n";
  return t;
}

}  // namespace rms::testing
