#include "rms/base/other_core.h"

#include <algorithm>
#include <thread>

namespace rms {

int OtherCore::UsableCpus() {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) return 1;
  return std::max(1, CPU_COUNT(&allowed));
}

OtherCore::OtherCore(bool always_start) : always_start_(always_start) {
  pthread_attr_t attr;
  if (pthread_attr_init(&attr) != 0) return;
  // Placed first on a CPU other than this thread's (Body lifts it).
  CPU_ZERO(&allowed_);
  const int here = sched_getcpu();
  if (sched_getaffinity(0, sizeof allowed_, &allowed_) == 0 && here >= 0) {
    cpu_set_t others = allowed_;
    CPU_CLR(here, &others);
    placed_ =
        CPU_COUNT(&others) > 0 && pthread_attr_setaffinity_np(&attr, sizeof others, &others) == 0;
  }
  made_ = pthread_create(&thread_, &attr, &OtherCore::Body, this) == 0;
  pthread_attr_destroy(&attr);
}

OtherCore::~OtherCore() {
  if (!made_) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    int offered = kOffered;
    state_.compare_exchange_strong(offered, kCancelled);
    stop_ = true;
  }
  changed_.notify_all();
  pthread_join(thread_, nullptr);
}

void* OtherCore::Body(void* p) {
  auto* self = static_cast<OtherCore*>(p);
  if (self->placed_) sched_setaffinity(0, sizeof self->allowed_, &self->allowed_);
  self->Loop();
  return nullptr;
}

void OtherCore::Await(const std::function<bool()>& done) {
  const auto spin_until = std::chrono::steady_clock::now() + kIdleSpin;
  while (!done()) {
    if (std::chrono::steady_clock::now() < spin_until) {
      std::this_thread::yield();
      continue;
    }
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, done);
  }
}

void OtherCore::Loop() {
  for (;;) {
    Await([this] { return stop_ || state_ == kOffered; });
    if (stop_) return;
    int offered = kOffered;
    if (!state_.compare_exchange_strong(offered, kRunning)) continue;  // cancelled meanwhile
    try {
      work_();
    } catch (...) {
      error_ = std::current_exception();
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      state_ = kDone;
    }
    changed_.notify_all();
  }
}

void OtherCore::Start(std::function<void()> work) {
  work_ = std::move(work);
  error_ = nullptr;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    state_ = made_ ? kOffered : kCancelled;
  }
  changed_.notify_all();
}

bool OtherCore::Finish() {
  if (always_start_ && made_) Await([this] { return state_ != kOffered; });
  int state = kOffered;
  if (state_.compare_exchange_strong(state, kCancelled))
    return false;                                         // not started: never will be
  if (state != kRunning && state != kDone) return false;  // nothing handed over, or no thread
  Await([this] { return state_ == kDone; });
  return true;
}

}  // namespace rms
