#include "rms/transport/journal.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <spdlog/spdlog.h>
#include <sys/stat.h>

#include "rms/base/check.h"

namespace rms::transport {

namespace {

void Put32(std::uint32_t v, std::vector<std::uint8_t>* out) {
  for (int s = 24; s >= 0; s -= 8) out->push_back(static_cast<std::uint8_t>(v >> s));
}
void Put64(std::uint64_t v, std::vector<std::uint8_t>* out) {
  for (int s = 56; s >= 0; s -= 8) out->push_back(static_cast<std::uint8_t>(v >> s));
}

}  // namespace

void AppendLogEvent(std::int64_t event_number, std::int64_t time_us, std::string_view channel,
                    const void* data, std::int32_t size, std::vector<std::uint8_t>* out) {
  RMS_CHECK(size >= 0);
  Put32(kLogSyncWord, out);
  Put64(static_cast<std::uint64_t>(event_number), out);
  Put64(static_cast<std::uint64_t>(time_us), out);
  Put32(static_cast<std::uint32_t>(channel.size()), out);
  Put32(static_cast<std::uint32_t>(size), out);
  out->insert(out->end(), channel.begin(), channel.end());
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  out->insert(out->end(), bytes, bytes + size);
}

std::string JournalFileName(const std::string& process, int run) {
  return process + "." + std::to_string(run) + ".lcmlog";
}

std::unique_ptr<Journal> Journal::CreateIn(const std::string& dir, const std::string& process,
                                           int first_run) {
  if (dir.empty()) throw InputError("--journal-dir: empty (give the folder for the journal)");
  struct stat st {};
  if (stat(dir.c_str(), &st) != 0)
    throw InputError("--journal-dir " + dir + ": " + std::strerror(errno));
  if (!S_ISDIR(st.st_mode)) throw InputError("--journal-dir " + dir + ": not a folder");
  // A run that ended mid-event (killed during a write that a full disk cut
  // short) is never written after: each run has a file of its own.
  for (int run = first_run; run < first_run + 10000; ++run) {
    const std::string path = dir + "/" + JournalFileName(process, run);
    const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_APPEND, 0644);
    if (fd >= 0) return std::unique_ptr<Journal>(new Journal(fd, path));
    if (errno != EEXIST)
      throw InputError("--journal-dir " + dir + ": cannot create " + JournalFileName(process, run) +
                       ": " + std::strerror(errno));
  }
  throw InputError("--journal-dir " + dir + ": 10000 journals of " + process +
                   " there already: give the session's own folder");
}

Journal::Journal(int fd, std::string path) : fd_(fd), path_(std::move(path)) { buf_.reserve(4096); }

Journal::~Journal() {
  if (fd_ >= 0) close(fd_);
}

bool Journal::Append(std::string_view channel, const void* data, int size, std::int64_t time_us) {
  buf_.clear();
  AppendLogEvent(events_, time_us, channel, data, size, &buf_);
  std::size_t done = 0;
  int error = 0;
  while (done < buf_.size()) {
    const ssize_t n = write(fd_, buf_.data() + done, buf_.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    error = n < 0 ? errno : ENOSPC;
    break;
  }
  if (error == 0) {
    ++events_;
    good_end_ += buf_.size();
    return true;
  }
  // Part of an event is no event: cut back to the last whole one, so the
  // journal stays a log that reads to its end.
  if (done > 0 && ftruncate(fd_, static_cast<off_t>(good_end_)) != 0)
    spdlog::warn("journal {}: could not cut back a part-written event ({})", path_,
                 std::strerror(errno));
  if (failed_++ == 0)
    spdlog::warn(
        "journal {}: a message could not be written ({}): this and every message it cannot "
        "write are counted (journal.failed); the session's recorder may still hold them "
        "(docs/sessions.md \"The record\")",
        path_, std::strerror(error));
  return false;
}

}  // namespace rms::transport
