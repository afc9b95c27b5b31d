#include "mapped_log.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <sys/mman.h>
#include <sys/stat.h>

#include "rms/base/check.h"

namespace rms::session {

namespace {

constexpr std::uint8_t kSync[4] = {0xED, 0xA1, 0xDA, 0x01};
constexpr std::size_t kHeaderBytes = 8 + 8 + 4 + 4;  // event number, time, two lengths

std::uint64_t BigEndian(const std::uint8_t* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return v;
}

}  // namespace

MappedLog::MappedLog(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError("cannot read the LCM log '" + path + "': " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int err = errno;
    ::close(fd);
    throw InputError("cannot read the LCM log '" + path + "': " + std::strerror(err));
  }
  size_ = static_cast<std::size_t>(st.st_size);
  if (size_ > 0) {
    void* m = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
    if (m == MAP_FAILED) {
      const int err = errno;
      ::close(fd);
      throw InputError("cannot map the LCM log '" + path + "': " + std::strerror(err));
    }
    base_ = static_cast<const std::uint8_t*>(m);
  }
  ::close(fd);
}

MappedLog::~MappedLog() {
  if (base_) ::munmap(const_cast<std::uint8_t*>(base_), size_);
}

bool MappedLog::Next(MappedEvent* ev) {
  // The sync word: the first place at or after the last event's end where
  // its four bytes stand (liblcm reads byte by byte until they do).
  const void* found = size_ - at_ >= 4 ? ::memmem(base_ + at_, size_ - at_, kSync, 4) : nullptr;
  if (!found) return false;
  std::size_t p = static_cast<std::size_t>(static_cast<const std::uint8_t*>(found) - base_) + 4;
  if (size_ - p < kHeaderBytes) return false;
  ev->timestamp_us = static_cast<std::int64_t>(BigEndian(base_ + p + 8, 8));
  const auto channel_len = static_cast<std::int32_t>(BigEndian(base_ + p + 16, 4));
  const auto data_len = static_cast<std::int32_t>(BigEndian(base_ + p + 20, 4));
  p += kHeaderBytes;
  if (channel_len <= 0 || channel_len >= 1000 || data_len < 0) return false;
  const auto c = static_cast<std::size_t>(channel_len), d = static_cast<std::size_t>(data_len);
  if (size_ - p < c || size_ - p - c < d) return false;
  // liblcm takes an event only when the next one's sync word (or the end,
  // or fewer than four bytes) follows it.
  const std::size_t end = p + c + d;
  if (size_ - end >= 4 && std::memcmp(base_ + end, kSync, 4) != 0) return false;
  ev->channel = std::string_view(reinterpret_cast<const char*>(base_ + p), c);
  ev->data = base_ + p + c;
  ev->size = data_len;
  at_ = good_end_ = end;
  return true;
}

}  // namespace rms::session
