#pragma once
// A session as a user starts it -- `scripts/lab demo` -- running in the
// background while a test acts on it (attacks it, stops its processes,
// kills its launcher): its folder, its session id, its processes' pids.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "subprocess.h"

namespace rms::testing {

class LiveSession {
 public:
  // Starts scripts/lab demo --no-build --out DIR/session --lcm-url URL with
  // small frames, no PNG, no video, and `extra` arguments.
  LiveSession(const std::string& dir, const std::string& url,
              const std::vector<std::string>& extra = {});
  // Until the operator station is up (in run/pids); false if the
  // launcher ended first or timeout_s passed.
  bool WaitRunning(double timeout_s = 60);
  // The launcher's exit code (-1 on timeout).
  int Wait(double timeout_s) { return lab_->Wait(timeout_s); }
  void Signal(int sig) { lab_->Signal(sig); }
  bool Running() { return lab_->Running(); }
  pid_t launcher_pid() const { return lab_->pid(); }

  const std::string& out() const { return out_; }
  const std::string& url() const { return url_; }
  const std::string& log() const { return log_; }
  std::int64_t session_id() const;
  // The latest pid run/pids has for a process (-1: none yet).
  int pid(const std::string& process) const;
  // Every pid run/children lists (the launcher's processes, restarts too).
  std::vector<int> children() const;

 private:
  std::string out_, url_, log_;
  std::unique_ptr<Subprocess> lab_;
};

}  // namespace rms::testing
