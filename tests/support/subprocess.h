#pragma once
// Runs a real executable for integration tests: stdout and stderr to a log
// file, signals, waits with a timeout, and SIGKILL on destruction so a failed
// test leaves no orphans.
#include <functional>
#include <string>
#include <sys/types.h>
#include <vector>

namespace rms::testing {

class Subprocess {
 public:
  Subprocess(const std::vector<std::string>& argv, const std::string& log_path,
             const std::vector<std::string>& extra_env = {});
  ~Subprocess();
  Subprocess(const Subprocess&) = delete;
  Subprocess& operator=(const Subprocess&) = delete;

  void Signal(int sig);
  bool Running();
  // Exit code, 128 + signal when killed by a signal, or -1 on timeout.
  int Wait(double timeout_s);
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
  bool reaped_ = false;
  int status_ = 0;
};

// A script or tool run to its end, its output (stdout and stderr) kept.
struct ScriptRun {
  int rc = -1;
  std::string out;
};
ScriptRun Script(const std::vector<std::string>& argv, const std::string& log,
                 double timeout_s = 300);

bool WaitForFile(const std::string& path, double timeout_s);
// Whether `done` holds within limit_s, asked every poll_ms (and once more
// at the end).
bool WaitUntil(const std::function<bool()>& done, double limit_s, int poll_ms = 50);
std::string ReadFile(const std::string& path);
// A fresh directory under the temp directory.
std::string MakeTempDir(const std::string& tag);
// A multicast URL on loopback with a port unique to this test process.
std::string UniqueLcmUrl(int base);

// Paths of the build's executables and the source tree.
std::string BuildPath(const std::string& rel);
std::string SourcePath(const std::string& rel);

}  // namespace rms::testing
