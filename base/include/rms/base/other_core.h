#pragma once
// A second core for work done in two shares at once, each a few
// milliseconds (docs/performance.md "Two cores"). On this machine kind a
// new thread waits about 4 ms for the scheduler's load balancer while its
// parent is busy (the idle CPU is not chosen at its start), and an idle
// CPU can take milliseconds to wake: longer than the shares. So the thread
// is made once, started on another CPU than its maker's (then let run on
// any it may), and between shares it waits busily (yielding) for up to
// kIdleSpin before it sleeps. And a share it has not started by the time
// its owner comes for it is never started: the owner does it itself, so
// nothing ever waits on a thread that has not run.
#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>

namespace rms {

class OtherCore {
 public:
  static constexpr std::chrono::milliseconds kIdleSpin{20};

  // The CPUs this thread may run on (its affinity: taskset, a cgroup), at
  // least 1: another core is worth making only when there are two.
  static int UsableCpus();

  // Makes the thread (none when it cannot be made: every Finish() then
  // says the work did not start). With always_start, Finish() waits for a
  // share to start rather than taking it back (a test, or a measurement of
  // two cores, that must see both shares run).
  explicit OtherCore(bool always_start = false);
  // A share not started is not; one running is waited for.
  ~OtherCore();
  OtherCore(const OtherCore&) = delete;
  OtherCore& operator=(const OtherCore&) = delete;

  // Hands `work` to the thread: one share at a time, each Start followed by
  // its Finish.
  void Start(std::function<void()> work);
  // True when the work started: it has ended now (error() holds what it
  // threw). False when it had not started: it never will, and the caller
  // does that share itself (never with always_start, but with no thread).
  bool Finish();
  std::exception_ptr error() const { return error_; }

 private:
  enum State : int { kIdle, kOffered, kRunning, kDone, kCancelled };
  static void* Body(void* self);
  void Loop();
  // Waits, busily for kIdleSpin then asleep, until done() (under mutex_'s
  // notifications).
  void Await(const std::function<bool()>& done);

  std::function<void()> work_;
  std::exception_ptr error_;
  std::atomic<int> state_ = kIdle;
  std::atomic<bool> stop_ = false;
  std::mutex mutex_;
  std::condition_variable changed_;
  cpu_set_t allowed_;    // the CPUs its maker may use: the thread's, once it runs
  bool placed_ = false;  // started on another CPU than its maker's
  bool made_ = false;
  bool always_start_ = false;
  pthread_t thread_{};
};

}  // namespace rms
