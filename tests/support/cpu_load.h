#pragma once
// A loaded machine for the tests that must hold on one (DEVELOPERS.md: "at
// least one busy loop per core"): busy processes, `per_core` a core, for as
// long as the object lives.
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "subprocess.h"

namespace rms::testing {

class CpuLoad {
 public:
  explicit CpuLoad(const std::string& dir, int per_core = 1) {
    const long cores = std::max(1L, sysconf(_SC_NPROCESSORS_ONLN));
    for (long i = 0; i < cores * per_core; ++i) {
      busy_.push_back(std::make_unique<Subprocess>(
          std::vector<std::string>{"/usr/bin/timeout", "300", "/bin/sh", "-c",
                                   "while :; do :; done"},
          dir + "/busy.log"));
    }
    std::printf("CPU load: %ld busy processes\n", cores * per_core);
  }
  // SIGTERM, which timeout passes on to its busy loop (a SIGKILL would end
  // timeout alone and leave the loop running); timeout ends it anyway after
  // 300 s if this process dies first.
  ~CpuLoad() {
    for (auto& b : busy_) {
      b->Signal(SIGTERM);
      b->Wait(5);
    }
  }
  CpuLoad(const CpuLoad&) = delete;
  CpuLoad& operator=(const CpuLoad&) = delete;

 private:
  std::vector<std::unique_ptr<Subprocess>> busy_;
};

}  // namespace rms::testing
