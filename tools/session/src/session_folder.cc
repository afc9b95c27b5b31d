#include "rms/session/session_folder.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "rms/base/check.h"

namespace fs = std::filesystem;

namespace rms::session {

std::string CreateSessionFolder(const std::string& dir) {
  const fs::path root(dir);
  if (fs::exists(root / "lcmlog")) throw InputError(dir + " already holds a session");
  std::error_code ec;
  for (const char* sub : kSessionSubfolders) {
    fs::create_directories(root / sub, ec);
    if (ec) {
      throw InputError(dir + ": cannot make the session's folder there (" + ec.message() + ": " +
                       (root / sub).string() + "); give a folder you can write");
    }
  }
  const fs::path probe = root / "run" / ".writable";
  {
    std::ofstream f(probe);
    if (!f || !(f << "x") || !f.flush()) {
      throw InputError(dir + ": cannot write in the session's folder (" + std::strerror(errno) +
                       "); give a folder you can write");
    }
  }
  fs::remove(probe, ec);
  return fs::absolute(root).lexically_normal().string();
}

LabConfig LoadSessionConfig(const std::string& dir) {
  const std::string path = (fs::path(dir) / "config.toml").string();
  return ParseConfig(ReadRegularFile(path, "the session's configuration", kMaxConfigBytes), path);
}

std::string ReadSessionFile(const std::string& dir, const std::string& name,
                            std::uint64_t max_bytes) {
  return ReadRegularFile((fs::path(dir) / name).string(), "the session's " + name, max_bytes);
}

}  // namespace rms::session
