#pragma once
// Network namespaces joined by veth pairs to a bridge (scripts/netns-lab)
// that stand for a lab's machines in the tests: "netns:PREFIX-1" ...
// "netns:PREFIX-N". Up when made, down when destroyed.
#include <string>
#include <utility>

#include "subprocess.h"

namespace rms::testing {

class NetnsLab {
 public:
  NetnsLab(std::string prefix, std::string dir, int hosts = 4)
      : prefix_(std::move(prefix)), dir_(std::move(dir)) {
    Subprocess up({SourcePath("scripts/netns-lab"), "up", prefix_, std::to_string(hosts)},
                  dir_ + "/netns.log");
    ok_ = up.Wait(60) == 0;
  }
  ~NetnsLab() { Down(); }
  NetnsLab(const NetnsLab&) = delete;
  NetnsLab& operator=(const NetnsLab&) = delete;
  void Down() {
    if (down_) return;
    down_ = true;
    Subprocess down({SourcePath("scripts/netns-lab"), "down", prefix_}, "/dev/null");
    down.Wait(60);
  }
  bool ok() const { return ok_; }
  std::string host(int i) const { return "netns:" + prefix_ + "-" + std::to_string(i); }

 private:
  std::string prefix_, dir_;
  bool ok_ = false, down_ = false;
};

}  // namespace rms::testing
