#pragma once
// An LCM log file read into memory whole (once, so a file cut short or
// overwritten meanwhile cannot harm the reading) and walked event by event
// as liblcm 1.3's lcm_eventlog_read_next_event reads it (docs/sessions.md
// "The log"): the sync word 0xEDA1DA01 searched for from the start, then
// the event number, the time (us), the channel's length (1..999) and the
// data's length (>= 0), big-endian, then the channel and the data; a length
// out of range, an event cut short, or an event not followed by the next
// one's sync word (or the file's last bytes) ends the log there, that event
// not taken. An event's channel and data point into the bytes read; a
// reader skips a channel it does not want by its length alone.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace rms::session {

struct RawLogEvent {
  std::int64_t timestamp_us = 0;  // the recorder's receive time
  std::string_view channel;       // as logged, every byte of it
  const std::uint8_t* data = nullptr;
  std::int32_t size = 0;
};

class RawLogReader {
 public:
  // Throws rms::InputError naming the file when it cannot be read.
  explicit RawLogReader(const std::string& path);
  RawLogReader(const RawLogReader&) = delete;
  RawLogReader& operator=(const RawLogReader&) = delete;

  // The next event; false at the log's end (or where it stops being a log).
  bool Next(RawLogEvent* ev);
  // Where the last whole event read ends, bytes from the start; and the
  // file's size: the bytes after good_end() are no whole event.
  std::size_t good_end() const { return good_end_; }
  std::size_t size() const { return size_; }

 private:
  std::string bytes_;
  const std::uint8_t* base_ = nullptr;
  std::size_t size_ = 0, at_ = 0, good_end_ = 0;
};

}  // namespace rms::session
