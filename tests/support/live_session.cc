#include "live_session.h"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "rms/transport/lcm_interface.h"

namespace rms::testing {

LiveSession::LiveSession(const std::string& dir, const std::string& url,
                         const std::vector<std::string>& extra)
    : out_(dir + "/session"), url_(url), log_(dir + "/lab.log") {
  std::vector<std::string> argv = {SourcePath("scripts/lab"),
                                   "demo",
                                   "--no-build",
                                   "--out",
                                   out_,
                                   "--lcm-url",
                                   url,
                                   "--png-every",
                                   "0",
                                   "--no-video",
                                   "--width",
                                   "160",
                                   "--height",
                                   "120"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  lab_ = std::make_unique<Subprocess>(
      argv, log_, std::vector<std::string>{std::string("RMSLAB_BUILD=") + BuildPath("")});
}

bool LiveSession::WaitRunning(double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    // The launcher lists a process in run/pids once it has read its ready file.
    if (pid("operator_station") > 0) return true;
    if (!lab_->Running()) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

std::int64_t LiveSession::session_id() const {
  std::ifstream f(out_ + "/manifest.json");
  const auto j = nlohmann::json::parse(f);
  return transport::ParseSessionId(j.at("session_id").get<std::string>(), "manifest session_id");
}

int LiveSession::pid(const std::string& process) const {
  std::ifstream f(out_ + "/run/pids");
  std::string name;
  int p = 0, found = -1;
  while (f >> name >> p) {
    if (name == process) found = p;
  }
  return found;
}

std::vector<int> LiveSession::children() const {
  std::ifstream f(out_ + "/run/children");
  std::vector<int> out;
  for (std::string line; std::getline(f, line);) {
    std::istringstream is(line);
    std::string name;
    int p = 0;
    if (is >> name >> p) out.push_back(p);
  }
  return out;
}

}  // namespace rms::testing
