#pragma once
// A terminal for integration tests: a private tmux server (its own socket),
// one session running a command in a pane of a given size; keys typed into
// it and its text read back, as a person at the terminal types and reads.
#include <string>
#include <vector>

namespace rms::testing {

class Tmux {
 public:
  // dir: where tmux's own output goes.
  explicit Tmux(std::string dir);
  ~Tmux();
  Tmux(const Tmux&) = delete;
  Tmux& operator=(const Tmux&) = delete;
  // Starts `command` (a shell command line) in a detached session "op" of
  // width x height characters. Returns tmux's exit code.
  int Start(const std::string& command, int width, int height);
  // Types keys (tmux send-keys names: "w", "Space", "BSpace", "Q", ...).
  int Send(const std::vector<std::string>& keys);
  // The pane's text, as the operator sees it.
  std::string Capture();
  // Resizes the pane (the status screen follows the terminal).
  int Resize(int width, int height);
  void Stop();

 private:
  int Run(std::vector<std::string> args);
  std::string dir_, socket_;
  bool stopped_ = false;
};

}  // namespace rms::testing
