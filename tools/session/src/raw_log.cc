#include "raw_log.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <sys/stat.h>

#include "rms/base/check.h"
#include "rms/base/folder_file.h"

namespace rms::session {

namespace {

constexpr std::uint8_t kSync[4] = {0xED, 0xA1, 0xDA, 0x01};
constexpr std::size_t kHeaderBytes = 8 + 8 + 4 + 4;  // event number, time, two lengths
constexpr std::size_t kBlockBytes = 1 << 16;         // read in blocks of 64 KiB
// No rmslab message is larger (lcmtypes' bounds): a header saying more is
// damage, not an event to buffer.
constexpr std::int32_t kMaxDataBytes = 64 << 20;

std::uint64_t BigEndian(const std::uint8_t* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return v;
}

}  // namespace

RawLogReader::RawLogReader(const std::string& path) : path_(path) {
  // A regular file, no link followed: a FIFO or a device is refused, not
  // waited on or read without end (docs/security.md).
  fd_ = OpenRegularFile(path, "the LCM log", kMaxLogBytes);
  struct stat st {};
  if (::fstat(fd_, &st) == 0 && st.st_size > 0) file_size_ = static_cast<std::size_t>(st.st_size);
  capacity_ = std::min<std::size_t>(std::max<std::size_t>(file_size_, 4), kBlockBytes);
  buf_ = std::make_unique_for_overwrite<std::uint8_t[]>(capacity_);
}

RawLogReader::RawLogReader(const std::string& path, std::size_t from) : RawLogReader(path) {
  from = std::min(from, file_size_);
  if (::lseek(fd_, static_cast<off_t>(from), SEEK_SET) < 0)
    throw InputError("cannot read the LCM log '" + path + "': " + std::strerror(errno));
  offset_ = good_end_ = from;
  from_start_ = from == 0;
}

RawLogReader::~RawLogReader() {
  if (fd_ >= 0) ::close(fd_);
}

bool RawLogReader::Have(std::size_t n) {
  if (end_ - begin_ >= n) return true;
  if (offset_ + begin_ + n > file_size_) return false;  // past the end of the file as opened
  // The unread bytes to the front; a larger buffer for an event larger than it.
  if (n > capacity_) {
    const std::size_t grown = std::max(n + 4, 2 * capacity_);  // + the next sync word
    auto bigger = std::make_unique_for_overwrite<std::uint8_t[]>(grown);
    std::memcpy(bigger.get(), buf_.get() + begin_, end_ - begin_);
    buf_ = std::move(bigger);
    capacity_ = grown;
  } else if (begin_ > 0) {
    std::memmove(buf_.get(), buf_.get() + begin_, end_ - begin_);
  }
  offset_ += begin_;
  end_ -= begin_;
  begin_ = 0;
  while (end_ < n) {
    const std::size_t want = std::min(capacity_ - end_, file_size_ - offset_ - end_);
    const ssize_t got = ::read(fd_, buf_.get() + end_, want);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0)
      throw InputError("cannot read the LCM log '" + path_ + "': " + std::strerror(errno));
    if (got == 0) {  // cut short since it was opened
      file_size_ = offset_ + end_;
      return false;
    }
    end_ += static_cast<std::size_t>(got);
  }
  return true;
}

bool RawLogReader::WholeEventAt(std::size_t* total) {
  if (!Have(4 + kHeaderBytes)) return false;
  const std::uint8_t* h = buf_.get() + begin_ + 4;
  const auto channel_len = static_cast<std::int32_t>(BigEndian(h + 16, 4));
  const auto data_len = static_cast<std::int32_t>(BigEndian(h + 20, 4));
  if (channel_len <= 0 || channel_len >= 1000 || data_len < 0 || data_len > kMaxDataBytes)
    return false;
  *total =
      4 + kHeaderBytes + static_cast<std::size_t>(channel_len) + static_cast<std::size_t>(data_len);
  return Have(*total);
}

// Damage passed over before the event taken at `start`.
void RawLogReader::NoteTaken(std::size_t start) {
  const bool first = first_event_start_ == kNoStop;
  if (first) first_event_start_ = start;
  if ((first && !from_start_) || start <= good_end_) return;
  skipped_bytes_ += start - good_end_;
  ++skipped_count_;
  if (stretches_.size() < kMaxStretches) stretches_.push_back({good_end_, start - good_end_});
}

bool RawLogReader::Next(RawLogEvent* ev) {
  std::size_t total = 0;
  for (;;) {
    // The sync word: the first place at or after the last event's end where
    // its four bytes stand (liblcm reads byte by byte until they do).
    for (;;) {
      if (!Have(4)) return false;
      // Where the last event ended, as a whole log has it (memmem's set-up
      // costs more than the event's own reading).
      if (std::memcmp(buf_.get() + begin_, kSync, 4) == 0) break;
      const void* found = ::memmem(buf_.get() + begin_, end_ - begin_, kSync, 4);
      if (found) {
        begin_ = static_cast<std::size_t>(static_cast<const std::uint8_t*>(found) - buf_.get());
        break;
      }
      begin_ = end_ - 3;  // a sync word may begin in the last three bytes
    }
    if (offset_ + begin_ >= stop_at_) {
      stopped_ = true;
      stopped_at_ = offset_ + begin_;
      return false;
    }
    if (WholeEventAt(&total)) break;
    if (!Have(4)) return false;
    ++begin_;  // no event starts here: the next sync word after this one
  }
  // A whole log has the next event's sync word after this one, or fewer than
  // four bytes (which liblcm's look for the sync word takes up). (Have may
  // move the buffer: the pointers into it are taken after.)
  const std::size_t start = offset_ + begin_;
  std::size_t end = start + total;
  if (!Have(total + 4)) end = file_size_;
  NoteTaken(start);
  const std::uint8_t* h = buf_.get() + begin_ + 4;
  const auto timestamp_us = static_cast<std::int64_t>(BigEndian(h + 8, 8));
  const auto channel_len = static_cast<std::int32_t>(BigEndian(h + 16, 4));
  const auto data_len = static_cast<std::int32_t>(BigEndian(h + 20, 4));
  const std::uint8_t* p = buf_.get() + begin_ + 4 + kHeaderBytes;
  ev->timestamp_us = timestamp_us;
  ev->channel = std::string_view(reinterpret_cast<const char*>(p), channel_len);
  ev->data = p + channel_len;
  ev->size = data_len;
  begin_ += total;
  good_end_ = end;
  return true;
}

}  // namespace rms::session
