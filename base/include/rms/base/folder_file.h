#pragma once
// A session's folder is untrusted input (docs/security.md "Session folders
// are untrusted"): anyone who can write it can plant a link to another file,
// a FIFO that hangs a reader, a device that never ends, or a file too large
// to hold. Tools read its files only as regular files of a bounded size,
// and write their outputs without ever writing through what stands at the
// output's name.
#include <cstdint>
#include <string>
#include <vector>

namespace rms {

// Whether a link at the path is followed: a path the user gave (a
// configuration named on the command line) follows it, and may be a FIFO
// (`--config <(...)`); a file of a session folder refuses it, and anything
// but a regular file.
enum class Links { kFollow, kRefuse };

// The whole of a regular file of at most max_bytes. Opened O_NONBLOCK |
// O_CLOEXEC (and O_NOFOLLOW for Links::kRefuse), then checked by fstat.
// Throws InputError "cannot read WHAT 'PATH': WHY" -- a link (not
// followed), a FIFO, a device, a folder, larger than the limit, or the
// open's or read's error.
std::string ReadRegularFile(const std::string& path, const std::string& what,
                            std::uint64_t max_bytes, Links links = Links::kRefuse);

// The same checks, the file left open for reading (a log read in blocks):
// the descriptor, which the caller closes.
int OpenRegularFile(const std::string& path, const std::string& what, std::uint64_t max_bytes,
                    Links links = Links::kRefuse);

// Limits for each kind of folder file (docs/security.md): far above any
// real one, far below what would exhaust a machine.
inline constexpr std::uint64_t kMaxConfigBytes = std::uint64_t{1} << 20;   // config.toml
inline constexpr std::uint64_t kMaxJsonBytes = std::uint64_t{64} << 20;    // *.json
inline constexpr std::uint64_t kMaxRunFileBytes = std::uint64_t{1} << 20;  // run/pids, ...
inline constexpr std::uint64_t kMaxPngBytes = std::uint64_t{32} << 20;     // frames/*.png
inline constexpr std::uint64_t kMaxLogBytes = std::uint64_t{1} << 40;      // lcmlog, journals

// How to treat a link at an output path the user named (--out): followed
// (their own: `--out /dev/stdout`) unless the path lies inside `folder`,
// the session's, where anyone who could write the folder could have
// planted it (the launcher names SESSION/summary.json itself).
Links LinksForOutput(const std::string& out, const std::string& folder);

// A tool's output folder (an export's csv/): opened without following a
// link (made when missing), its files written to fresh temporary files in
// it (O_CREAT | O_EXCL | O_NOFOLLOW, through the folder's descriptor) and
// renamed to their names only by Commit, all at once: a failure (a full
// disk) leaves none of them, and what stood at their names before.
class OutputFolder {
 public:
  // Throws InputError naming the folder: not a folder, a link (with
  // Links::kRefuse: a folder inside a session's; a folder the user named
  // may be reached through one, kFollow), or it cannot be made or opened.
  explicit OutputFolder(const std::string& path, Links links = Links::kRefuse);
  ~OutputFolder();  // unlinks every temporary file not committed
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  // A new file to be NAME (a plain name: no '/'); returns its descriptor,
  // open for writing, which the folder owns (closed by Close or Commit).
  int Begin(const std::string& name);
  // Closes file `fd` (begun here), checking that all of it was written
  // (a full disk shows only at the close): throws InputError naming it.
  void Close(int fd);
  // Renames every file begun to its name (replacing what stood there,
  // link or file, never writing through it).
  void Commit();
  // Removes every file begun and not committed.
  void Abandon();
  const std::string& path() const { return path_; }

 private:
  struct File {
    std::string name, temp;
    int fd = -1;
  };
  std::string path_;
  int dir_fd_ = -1;
  std::vector<File> files_;
};

}  // namespace rms
