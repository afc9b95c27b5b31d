#include "subprocess.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <sys/file.h>
#include <sys/wait.h>
#include <thread>

extern char** environ;

namespace rms::testing {

Subprocess::Subprocess(const std::vector<std::string>& argv, const std::string& log_path,
                       const std::vector<std::string>& extra_env) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  std::vector<std::string> env_store;
  // extra_env entries ("KEY=value") replace the inherited ones of that key.
  auto overridden = [&](const std::string& kv) {
    const std::string key = kv.substr(0, kv.find('=') + 1);
    for (const auto& e : extra_env)
      if (e.compare(0, key.size(), key) == 0) return true;
    return false;
  };
  for (char** e = environ; *e; ++e)
    if (!overridden(*e)) env_store.emplace_back(*e);
  for (const auto& e : extra_env) env_store.push_back(e);
  std::vector<char*> env;
  for (auto& e : env_store) env.push_back(e.data());
  env.push_back(nullptr);

  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  const int rc = posix_spawn(&pid_, args[0], &fa, nullptr, args.data(), env.data());
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) throw std::runtime_error("cannot start " + argv[0]);
}

Subprocess::~Subprocess() {
  if (!reaped_ && pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, &status_, 0);
  }
}

void Subprocess::Signal(int sig) {
  if (!reaped_) kill(pid_, sig);
}

bool Subprocess::Running() {
  if (reaped_) return false;
  const pid_t r = waitpid(pid_, &status_, WNOHANG);
  if (r == pid_) reaped_ = true;
  return !reaped_;
}

int Subprocess::Wait(double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (Running()) {
    if (std::chrono::steady_clock::now() > end) return -1;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (WIFEXITED(status_)) return WEXITSTATUS(status_);
  if (WIFSIGNALED(status_)) return 128 + WTERMSIG(status_);
  return -2;
}

bool WaitForFile(const std::string& path, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!std::filesystem::exists(path)) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

bool WaitUntil(const std::function<bool()>& done, double limit_s, int poll_ms) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(poll_ms));
  }
  return done();
}

std::string ReadFile(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::string MakeTempDir(const std::string& tag) {
  std::string tmpl =
      (std::filesystem::temp_directory_path() / ("rmslab_" + tag + "_XXXXXX")).string();
  if (mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  return tmpl;
}

std::string UniqueLcmUrl(int base) {
  // A port no other running test holds: each is claimed by an exclusive
  // lock on a file in the temp directory, held until this process ends
  // (tests run in parallel under ctest -j; a port shared by two of them
  // mixes their sessions). The same base gives the same port within a
  // process.
  static std::map<int, std::string> claimed;
  static std::mutex mu;
  std::lock_guard<std::mutex> lock(mu);
  if (const auto it = claimed.find(base); it != claimed.end()) return it->second;
  constexpr int kFirst = 17000, kCount = 8000;
  const int start = static_cast<int>(
      (static_cast<unsigned>(getpid()) * 131u + static_cast<unsigned>(base)) % kCount);
  for (int i = 0; i < kCount; ++i) {
    const int port = kFirst + (start + i) % kCount;
    const std::string path = std::filesystem::temp_directory_path().string() +
                             "/rmslab-test-port-" + std::to_string(port) + ".lock";
    const int fd = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) continue;
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
      close(fd);
      continue;
    }
    // fd stays open (and the port claimed) until the process ends.
    return claimed[base] = "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0";
  }
  throw std::runtime_error("no free test LCM port in " + std::to_string(kFirst) + ".." +
                           std::to_string(kFirst + kCount - 1));
}

ScriptRun Script(const std::vector<std::string>& argv, const std::string& log, double timeout_s) {
  Subprocess p(argv, log, {std::string("RMSLAB_BUILD=") + RMSLAB_BUILD_DIR});
  ScriptRun r;
  r.rc = p.Wait(timeout_s);
  r.out = ReadFile(log);
  return r;
}

std::string BuildPath(const std::string& rel) { return std::string(RMSLAB_BUILD_DIR) + "/" + rel; }
std::string SourcePath(const std::string& rel) {
  return std::string(RMSLAB_SOURCE_DIR) + "/" + rel;
}

}  // namespace rms::testing
