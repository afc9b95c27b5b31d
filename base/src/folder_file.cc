#include "rms/base/folder_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <random>
#include <sys/stat.h>

#include "rms/base/check.h"
#include "rms/base/text.h"

namespace rms {

namespace {

std::string KindOf(mode_t m) {
  if (S_ISDIR(m)) return "a folder";
  if (S_ISFIFO(m)) return "a FIFO";
  if (S_ISCHR(m) || S_ISBLK(m)) return "a device";
  if (S_ISSOCK(m)) return "a socket";
  if (S_ISLNK(m)) return "a link";
  return "not a regular file";
}

}  // namespace

int OpenRegularFile(const std::string& path, const std::string& what, std::uint64_t max_bytes,
                    Links links) {
  const std::string cannot = "cannot read " + what + " '" + path + "'";
  const int flags = O_RDONLY | O_CLOEXEC | (links == Links::kRefuse ? O_NOFOLLOW | O_NONBLOCK : 0);
  const int fd = open(path.c_str(), flags);
  if (fd < 0) {
    const int err = errno;
    throw InputError(cannot + ": " +
                     (err == ELOOP && links == Links::kRefuse
                          ? std::string("a link, not followed (a folder's files are read only "
                                        "as regular files)")
                          : std::string(std::strerror(err))));
  }
  struct stat st {};
  if (fstat(fd, &st) != 0) {
    const int err = errno;
    close(fd);
    throw InputError(cannot + ": " + std::strerror(err));
  }
  const bool fifo_given = links == Links::kFollow && S_ISFIFO(st.st_mode);
  if (!S_ISREG(st.st_mode) && !fifo_given) {
    close(fd);
    throw InputError(cannot + ": " + KindOf(st.st_mode) + ", not a regular file");
  }
  if (S_ISREG(st.st_mode) && static_cast<std::uint64_t>(st.st_size) > max_bytes) {
    close(fd);
    throw InputError(cannot + ": " + std::to_string(st.st_size) + " bytes, more than " + what +
                     " can be (" + std::to_string(max_bytes) + ")");
  }
  // Regular from here on: reads do not wait (a FIFO given by the user does).
  if (!fifo_given) fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  return fd;
}

std::string ReadRegularFile(const std::string& path, const std::string& what,
                            std::uint64_t max_bytes, Links links) {
  const int fd = OpenRegularFile(path, what, max_bytes, links);
  const std::string cannot = "cannot read " + what + " '" + path + "': ";
  std::string text;
  char block[65536];
  for (;;) {
    const ssize_t n = read(fd, block, sizeof block);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      close(fd);
      throw InputError(cannot + std::strerror(err));
    }
    if (n == 0) break;
    text.append(block, static_cast<std::size_t>(n));
    if (text.size() > max_bytes) {  // grew since its fstat, or a FIFO
      close(fd);
      throw InputError(cannot + "more than " + std::to_string(max_bytes) + " bytes");
    }
  }
  close(fd);
  return text;
}

Links LinksForOutput(const std::string& out, const std::string& folder) {
  // Where they really are: the output's folder and the session's, links and
  // "a/" or "a/./" resolved (weakly_canonical: what exists, resolved; the
  // rest kept lexically), so neither a trailing slash nor a link to the
  // folder takes an output out of it.
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path parent = fs::absolute(out, ec).lexically_normal().parent_path();
  const fs::path o = fs::weakly_canonical(parent, ec);
  const fs::path f = fs::weakly_canonical(fs::absolute(folder, ec), ec);
  auto parts = [](const fs::path& p) {
    std::vector<std::string> v;
    for (const auto& c : p)
      if (!c.empty() && c != ".") v.push_back(c.string());
    return v;
  };
  const auto op = parts(o), fp = parts(f);
  const bool inside = op.size() >= fp.size() && std::equal(fp.begin(), fp.end(), op.begin());
  return inside ? Links::kRefuse : Links::kFollow;
}

OutputFolder::OutputFolder(const std::string& path, Links links) : path_(path) {
  if (mkdir(path.c_str(), 0755) != 0 && errno != EEXIST)
    throw InputError("cannot make the folder '" + path + "': " + std::strerror(errno));
  dir_fd_ = open(path.c_str(),
                 O_RDONLY | O_DIRECTORY | O_CLOEXEC | (links == Links::kRefuse ? O_NOFOLLOW : 0));
  if (dir_fd_ < 0) {
    const int err = errno;
    throw InputError("cannot write into '" + path + "': " +
                     (err == ELOOP || err == ENOTDIR
                          ? std::string("a link or a file, not a folder (outputs are written "
                                        "only into a real folder)")
                          : std::string(std::strerror(err))));
  }
}

OutputFolder::~OutputFolder() {
  Abandon();
  if (dir_fd_ >= 0) close(dir_fd_);
}

int OutputFolder::Begin(const std::string& name) {
  RMS_CHECK(!name.empty() && name.find('/') == std::string::npos);
  std::random_device rd;
  for (int attempt = 0; attempt < 16; ++attempt) {
    const std::string temp = "." + name + "." + Sprintf("%08x", rd()) + ".tmp";
    const int fd =
        openat(dir_fd_, temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd >= 0) {
      files_.push_back({name, temp, fd});
      return fd;
    }
    if (errno != EEXIST)
      throw InputError("cannot write '" + path_ + "/" + name + "': " + std::strerror(errno));
  }
  throw InputError("cannot write '" + path_ + "/" + name + "': no free temporary name");
}

void OutputFolder::Close(int fd) {
  for (File& f : files_) {
    if (f.fd != fd) continue;
    f.fd = -1;
    if (close(fd) != 0)
      throw InputError("could not write all of '" + path_ + "/" + f.name +
                       "': " + std::strerror(errno));
    return;
  }
  RMS_CHECK(false && "a file this folder did not begin");
}

void OutputFolder::Commit() {
  for (File& f : files_) {
    if (f.fd >= 0) Close(f.fd);
  }
  for (File& f : files_) {
    if (renameat(dir_fd_, f.temp.c_str(), dir_fd_, f.name.c_str()) != 0)
      throw InputError("could not write '" + path_ + "/" + f.name + "': " + std::strerror(errno));
    f.temp.clear();
  }
  files_.clear();
}

void OutputFolder::Abandon() {
  for (File& f : files_) {
    if (f.fd >= 0) close(f.fd);
    if (!f.temp.empty()) unlinkat(dir_fd_, f.temp.c_str(), 0);
  }
  files_.clear();
}

}  // namespace rms
