#pragma once
// A process's own record of what it publishes (docs/sessions.md "The
// record"): every message, just before it goes on the wire, appended to a
// file of LCM's log format -- the journal -- so the session's log does not
// depend on one listener keeping up. Each event is one write(2) of the whole
// event, nothing held in the process: a kill -9 costs at most the message
// being sent; a write that fails (a full disk) is cut back to the last whole
// event, counted and said once, and the process carries on (the network's
// recorder may still have the message). `rms_session record` joins a
// session's journals and the recorder's log into SESSION/lcmlog.
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace rms::transport {

// One LCM log event as liblcm 1.3's lcm_eventlog_write_event writes it (and
// lcm_eventlog_read_next_event reads it): the sync word 0xEDA1DA01, the
// event number and the time in us (int64), the channel's length and the
// data's (int32), all big-endian, then the channel and the data. Appended to
// `out` (nothing allocated when it has room). The one encoder of log events.
inline constexpr std::uint32_t kLogSyncWord = 0xEDA1DA01u;
inline constexpr std::size_t kLogEventHeaderBytes = 4 + 8 + 8 + 4 + 4;
void AppendLogEvent(std::int64_t event_number, std::int64_t time_us, std::string_view channel,
                    const void* data, std::int32_t size, std::vector<std::uint8_t>* out);

// The journal's file name for a process's run: PROCESS.N.lcmlog, N the run
// (0 the first; the launcher's restarts 1, 2, ...).
std::string JournalFileName(const std::string& process, int run);

class Journal {
 public:
  // Creates DIR/PROCESS.N.lcmlog for the first N from `first_run` on that
  // no file has yet (O_EXCL: a restarted process never writes after a run
  // that may have ended mid-event). Throws rms::InputError naming the folder
  // and the reason when none can be made.
  static std::unique_ptr<Journal> CreateIn(const std::string& dir, const std::string& process,
                                           int first_run = 0);
  ~Journal();
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;

  // Appends one event (channel as sent, with its suffix; time_us the
  // publish time, us since 1970). False when it could not be written whole:
  // the file is cut back to the last whole event and the message counted in
  // failed(); the first failure is said (spdlog warning, with the reason).
  bool Append(std::string_view channel, const void* data, int size, std::int64_t time_us);

  const std::string& path() const { return path_; }
  std::int64_t events() const { return events_; }  // written whole
  std::int64_t failed() const { return failed_; }  // not written

 private:
  Journal(int fd, std::string path);
  int fd_ = -1;
  std::string path_;
  std::int64_t events_ = 0, failed_ = 0;
  std::uint64_t good_end_ = 0;  // bytes written whole
  std::vector<std::uint8_t> buf_;
};

}  // namespace rms::transport
