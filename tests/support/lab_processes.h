#pragma once
// The four real executables on a private multicast port, for integration
// tests: start the three downstream processes, fly a timeline with the real
// operator_station while the test listens on LCM, stop them all.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "rms/transport/lcm_interface.h"

#include "subprocess.h"

namespace rms::testing {

class LabProcesses {
 public:
  // dir: where logs and stats go. esg_args: extra esg_renderer arguments.
  LabProcesses(std::string dir, std::string url,
               std::vector<std::string> esg_args = {"--width", "160", "--height", "120"});
  ~LabProcesses();

  // Starts esg_renderer, scene_proc, dynamics_proc (its checkpoints in
  // DIR/checkpoints) and waits for them.
  // Returns false (with the logs in `error`) when one does not come up.
  bool Start(std::string* error);
  // Runs operator_station on `timeline` (extra args appended) to its end,
  // calling lcm.HandleSubscriptions all along; returns its exit code.
  int Fly(transport::UdpLcm& lcm, const std::string& timeline,
          const std::vector<std::string>& extra = {});
  // SIGINT to the three; returns true when all exit 0 (logs in `error` if not).
  bool Stop(std::string* error);

  // Extra environment for esg_renderer (e.g. DISPLAY=:99); before Start.
  void set_esg_env(std::vector<std::string> env) { esg_env_ = std::move(env); }

  const std::string& dir() const { return dir_; }
  const std::string& url() const { return url_; }

 private:
  std::unique_ptr<Subprocess> StartOne(const std::string& name, std::vector<std::string> args,
                                       const std::vector<std::string>& env = {});
  std::string dir_, url_;
  std::vector<std::string> esg_args_, esg_env_;
  std::vector<std::pair<std::string, std::unique_ptr<Subprocess>>> procs_;
};

}  // namespace rms::testing
