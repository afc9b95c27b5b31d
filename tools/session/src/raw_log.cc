#include "raw_log.h"

#include <cerrno>
#include <cstring>
#include <fstream>

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

RawLogReader::RawLogReader(const std::string& path) {
  // Read whole, once: a mapping would die of SIGBUS if the file were cut
  // short while it is read (a log overwritten or emptied meanwhile).
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError("cannot read the LCM log '" + path + "': " + std::strerror(errno));
  f.seekg(0, std::ios::end);
  const std::streamoff size = f.tellg();
  f.seekg(0, std::ios::beg);
  bytes_.resize(size > 0 ? static_cast<std::size_t>(size) : 0);
  f.read(bytes_.data(), static_cast<std::streamsize>(bytes_.size()));
  bytes_.resize(static_cast<std::size_t>(f.gcount()));  // less, if it was cut short meanwhile
  if (f.bad()) throw InputError("cannot read the LCM log '" + path + "': a read error");
  base_ = reinterpret_cast<const std::uint8_t*>(bytes_.data());
  size_ = bytes_.size();
}

bool RawLogReader::Next(RawLogEvent* ev) {
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
  // liblcm's look for the next sync word takes up to three bytes after the
  // last event with it: its reader ends past them.
  at_ = end;
  good_end_ = size_ - end < 4 ? size_ : end;
  return true;
}

}  // namespace rms::session
