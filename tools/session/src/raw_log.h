#pragma once
// An LCM log file read in blocks through one small buffer and walked event
// by event as liblcm 1.3's lcm_eventlog_read_next_event reads it
// (docs/sessions.md "The log"): the sync word 0xEDA1DA01 searched for from
// the start, then the event number, the time (us), the channel's length
// (1..999) and the data's length (>= 0), big-endian, then the channel and
// the data; a length out of range, an event cut short, or an event not
// followed by the next one's sync word (or the file's last bytes) ends the
// log there, that event not taken. The file is read up to the size it had
// when opened. An event's channel and data point into the buffer until the
// next call; a reader skips a channel it does not want by its length alone.
#include <cstddef>
#include <cstdint>
#include <memory>
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
  // Throws rms::InputError naming the file when it cannot be opened.
  explicit RawLogReader(const std::string& path);
  // The same from byte `from` on: the first event is the first whose sync
  // word stands at or after it (where liblcm, reading on from there, would
  // find one). Whether that is where an event of the whole log starts, only
  // a reader from the start can tell (StopAt).
  RawLogReader(const std::string& path, std::size_t from);
  ~RawLogReader();
  RawLogReader(const RawLogReader&) = delete;
  RawLogReader& operator=(const RawLogReader&) = delete;

  // The next event (its channel and data valid until the next call); false
  // at the log's end (or where it stops being a log). Throws InputError on
  // a read error.
  bool Next(RawLogEvent* ev);
  // Where the last whole event taken ends (past up to three bytes after it,
  // as liblcm), bytes from the start; and the file's size when opened: the
  // bytes after good_end() are no whole event.
  std::size_t good_end() const { return good_end_; }
  std::size_t size() const { return file_size_; }
  // Stops before an event whose sync word stands at or past `offset`: Next
  // returns false and stopped() is true, stopped_at() that event's start
  // (byte from the file's start), not taken; Resume() reads on from it.
  void StopAt(std::size_t offset) { stop_at_ = offset; }
  bool stopped() const { return stopped_; }
  std::size_t stopped_at() const { return stopped_at_; }
  void Resume() {
    stop_at_ = kNoStop;
    stopped_ = false;
  }
  // The start (byte from the file's start) of the first event taken.
  std::size_t first_event_start() const { return first_event_start_; }

 private:
  // At least n bytes from begin_ in the buffer: reads on, moving the unread
  // bytes to the front (and growing it for an event larger than it); false
  // when the file (as opened) ends first.
  bool Have(std::size_t n);

  std::string path_;
  int fd_ = -1;
  std::size_t file_size_ = 0;
  std::unique_ptr<std::uint8_t[]> buf_;
  std::size_t capacity_ = 0;
  std::size_t begin_ = 0, end_ = 0;  // the unread bytes in buf_
  std::size_t offset_ = 0;           // the file offset of buf_[0]
  std::size_t good_end_ = 0;
  static constexpr std::size_t kNoStop = ~std::size_t{0};
  std::size_t stop_at_ = kNoStop, stopped_at_ = 0, first_event_start_ = kNoStop;
  bool stopped_ = false;
};

}  // namespace rms::session
