#pragma once
// A subject of a study, scripted: `scripts/lab study run STUDY --subject
// NAME` in a real terminal (tmux), as an experimenter starts it from
// docs/studies.md; at each trial's prompt the subject presses Enter, then
// the scripted operator (scripted_operator.h) flies the trial from the
// status screen alone, and quits it (or, docked, lets it end by itself).
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "scripted_operator.h"
#include "subprocess.h"
#include "tmux.h"

namespace rms::testing {

class StudySubject {
 public:
  // Starts the study run in a terminal of its own; its stderr (the
  // launcher's lines) also goes to DIR/study.log, its exit code to
  // DIR/study.rc.
  StudySubject(const std::string& dir, const std::string& study, const std::string& subject,
               const std::string& study_dir, const std::string& lcm_url)
      : dir_(dir), tmux_(std::make_unique<Tmux>(dir)) {
    const std::string cmd = "RMSLAB_BUILD=" + std::string(RMSLAB_BUILD_DIR) + " " +
                            SourcePath("scripts/lab") + " study run " + study + " --subject " +
                            subject + " --dir " + study_dir +
                            " --no-build --no-video --png-every 0 --lcm-url '" + lcm_url +
                            "' 2> >(tee -a " + dir + "/study.log >&2); echo $? >" + dir +
                            "/study.rc.tmp; mv " + dir + "/study.rc.tmp " + dir + "/study.rc";
    tmux_->Start("bash -c \"" + Escape(cmd) + "\"", 132, 50);
  }
  ~StudySubject() { tmux_->Stop(); }
  Tmux* tmux() { return tmux_.get(); }

  // Waits for `text` on the terminal; true when it came.
  bool WaitFor(const std::string& text, double limit_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
    while (std::chrono::steady_clock::now() < end) {
      if (tmux_->Capture().find(text) != std::string::npos) return true;
      if (Finished()) return tmux_->Capture().find(text) != std::string::npos;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    return false;
  }
  // How many times the launcher has said `text` (its log).
  int Said(const std::string& text) const {
    const std::string log = ReadFile(dir_ + "/study.log");
    int n = 0;
    for (auto at = log.find(text); at != std::string::npos; at = log.find(text, at + 1)) ++n;
    return n;
  }
  // The study's n-th prompt before a trial (from 1), answered: Enter; true
  // once the station's status screen has taken the terminal.
  bool StartTrial(int n, double limit_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
    while (Said("the subject is ready?") < n) {
      if (std::chrono::steady_clock::now() > end || Finished()) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the prompt is waiting for a key
    tmux_->Send({"Enter"});
    while (std::chrono::steady_clock::now() < end) {
      const std::string screen = tmux_->Capture();
      if (ParseScreen(screen).valid && screen.find("the subject is ready?") == std::string::npos)
        return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    return false;
  }
  bool Finished() const { return std::filesystem::exists(dir_ + "/study.rc"); }
  int WaitExit(double limit_s) {
    for (int i = 0; i < limit_s * 10 && !Finished(); ++i) usleep(100000);
    return Finished() ? std::stoi(ReadFile(dir_ + "/study.rc")) : -1;
  }

 private:
  static std::string Escape(const std::string& s) {
    std::string out;
    for (char c : s) {
      if (c == '"' || c == '\\' || c == '$' || c == '`') out += '\\';
      out += c;
    }
    return out;
  }
  std::string dir_;
  std::unique_ptr<Tmux> tmux_;
};

}  // namespace rms::testing
