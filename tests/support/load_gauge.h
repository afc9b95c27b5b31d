#pragma once
// How loaded the machine is while a real-time test runs (DEVELOPERS.md: no
// test may depend on an idle machine; one that cannot judge says so with
// the delay it measured). A thread wakes every 100 ms and spins for 2 ms of
// its own CPU time: the wall time that took, over the CPU time, is the
// machine's slowdown for a process that wants a CPU now (1 on an idle
// machine; about 3 with two busy loops a core beside it). A test scales a
// time bound by it and prints it, instead of asserting an idle machine's
// figure.
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <vector>

namespace rms::testing {

class LoadGauge {
 public:
  LoadGauge() : thread_([this] { Run(); }) {}
  ~LoadGauge() {
    stop_ = true;
    thread_.join();
  }
  LoadGauge(const LoadGauge&) = delete;
  LoadGauge& operator=(const LoadGauge&) = delete;

  // The slowdown's quantile q (0..1) over the samples so far; 1 with none.
  double Slowdown(double q) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (samples_.empty()) return 1.0;
    std::vector<double> s = samples_;
    std::sort(s.begin(), s.end());
    const auto i = static_cast<std::size_t>(q * static_cast<double>(s.size() - 1));
    return std::max(1.0, s[i]);
  }

 private:
  static double CpuNow() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + t.tv_nsec * 1e-9;
  }
  void Run() {
    using Clock = std::chrono::steady_clock;
    while (!stop_) {
      const double cpu0 = CpuNow();
      const auto wall0 = Clock::now();
      while (CpuNow() - cpu0 < 0.002) {
      }
      const double wall = std::chrono::duration<double>(Clock::now() - wall0).count();
      const double cpu = CpuNow() - cpu0;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        samples_.push_back(wall / cpu);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  std::atomic<bool> stop_{false};
  mutable std::mutex mutex_;
  std::vector<double> samples_;
  std::thread thread_;
};

}  // namespace rms::testing
