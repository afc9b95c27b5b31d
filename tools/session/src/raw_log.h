#pragma once
// An LCM log file read in blocks through one small buffer and walked event
// by event as liblcm 1.3's lcm_eventlog_read_next_event reads it
// (docs/sessions.md "The log"): the sync word 0xEDA1DA01 searched for from
// the start, then the event number, the time (us), the channel's length
// (1..999) and the data's length (>= 0), big-endian, then the channel and
// the data. Unlike liblcm, which ends the log at the first damage, the
// reader reads past damage inside the log (docs/sessions.md "A damaged
// log"): a header whose lengths are out of range, or an event that would
// run past the file's end, is no event, and the next sync word after its
// own is looked for; an event followed by bytes that are not the next sync
// word is taken (its bytes are whole; a message damaged inside fails its
// decode or its tag further on), and the search for the next sync word
// skips what follows it. The bytes passed over between events are counted
// (skipped_bytes, and the places in skipped_stretches); those after the
// last whole event are not (size() - good_end()). The file is read up to
// the size it had when opened. An event's channel and data point into the buffer until the
// next call; a reader skips a channel it does not want by its length alone.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

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
  // Bytes passed over between whole events (and before the first, in a
  // reader from the file's start): damage inside the log.
  std::size_t skipped_bytes() const { return skipped_bytes_; }
  // Where they were: the first kMaxStretches stretches, {from, bytes}.
  static constexpr std::size_t kMaxStretches = 16;
  struct Stretch {
    std::size_t from = 0, bytes = 0;
  };
  const std::vector<Stretch>& skipped_stretches() const { return stretches_; }
  std::size_t skipped_count() const { return skipped_count_; }  // stretches, all of them

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
  bool from_start_ = true;
  std::size_t skipped_bytes_ = 0, skipped_count_ = 0;
  std::vector<Stretch> stretches_;
  // Whether the event whose sync word stands at begin_ is whole: its
  // lengths in range and all of it in the file; *total its bytes.
  bool WholeEventAt(std::size_t* total);
  void NoteTaken(std::size_t start);
};

}  // namespace rms::session
