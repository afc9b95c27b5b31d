#include "tmux.h"

#include <unistd.h>

#include <exception>

#include "subprocess.h"

namespace rms::testing {

Tmux::Tmux(std::string dir)
    : dir_(std::move(dir)), socket_("rmslab_test_" + std::to_string(getpid())) {}

Tmux::~Tmux() { Stop(); }

void Tmux::Stop() {
  if (stopped_) return;
  stopped_ = true;
  try {
    Run({"kill-server"});
  } catch (const std::exception&) {
  }
}

int Tmux::Run(std::vector<std::string> args) {
  args.insert(args.begin(), {"/usr/bin/tmux", "-L", socket_});
  Subprocess p(args, dir_ + "/tmux.log");
  return p.Wait(10);
}

int Tmux::Start(const std::string& command, int width, int height) {
  return Run({"new-session", "-d", "-s", "op", "-x", std::to_string(width), "-y",
              std::to_string(height), command});
}

int Tmux::Send(const std::vector<std::string>& keys) {
  std::vector<std::string> args = {"send-keys", "-t", "op"};
  args.insert(args.end(), keys.begin(), keys.end());
  return Run(args);
}

std::string Tmux::Capture() {
  const std::string path = dir_ + "/pane.txt";
  Subprocess p({"/usr/bin/tmux", "-L", socket_, "capture-pane", "-p", "-t", "op"}, path);
  p.Wait(10);
  return ReadFile(path);
}

int Tmux::Resize(int width, int height) {
  return Run(
      {"resize-window", "-t", "op", "-x", std::to_string(width), "-y", std::to_string(height)});
}

}  // namespace rms::testing
