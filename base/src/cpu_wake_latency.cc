#include "rms/base/cpu_wake_latency.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <utility>

#include "rms/base/check.h"

namespace rms {

CpuWakeLatencyRequest::CpuWakeLatencyRequest(std::int32_t max_us, const std::string& device)
    : asked_(true) {
  RMS_CHECK(max_us >= 0 && max_us <= kMaxCpuWakeLatencyUs);
  const std::string at = " at " + std::to_string(max_us) + " us";
  const int fd = ::open(device.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) {
    state_ = "not held" + at + ": " + device + ": " + std::strerror(errno);
    return;
  }
  // The request is the value as a binary 32-bit integer, written once.
  if (::write(fd, &max_us, sizeof max_us) != static_cast<ssize_t>(sizeof max_us)) {
    state_ = "not held" + at + ": writing " + device + ": " + std::strerror(errno);
    ::close(fd);
    return;
  }
  fd_ = fd;
  state_ = "held" + at + " (" + device + ")";
}

CpuWakeLatencyRequest::~CpuWakeLatencyRequest() {
  if (fd_ >= 0) ::close(fd_);
}

CpuWakeLatencyRequest::CpuWakeLatencyRequest(CpuWakeLatencyRequest&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), asked_(other.asked_), state_(std::move(other.state_)) {
  other.state_ = "off";
  other.asked_ = false;
}

CpuWakeLatencyRequest& CpuWakeLatencyRequest::operator=(CpuWakeLatencyRequest&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    asked_ = std::exchange(other.asked_, false);
    state_ = std::exchange(other.state_, "off");
  }
  return *this;
}

std::optional<std::int32_t> CpuWakeLatencyFromEnv() {
  const char* v = std::getenv(kCpuWakeLatencyEnv);
  if (v == nullptr || *v == '\0' || std::string_view(v) == "off") return std::nullopt;
  const std::string_view s(v);
  // Digits only (from_chars alone would take "-0"), as the launcher's check.
  std::int64_t us = -1;
  if (s.size() <= 7 && s.find_first_not_of("0123456789") == std::string_view::npos)
    std::from_chars(s.data(), s.data() + s.size(), us);
  if (us < 0 || us > kMaxCpuWakeLatencyUs) {
    throw InputError(std::string(kCpuWakeLatencyEnv) + "='" + std::string(s) +
                     "': must be \"off\" or a whole number of microseconds, 0.." +
                     std::to_string(kMaxCpuWakeLatencyUs));
  }
  return static_cast<std::int32_t>(us);
}

}  // namespace rms
