#include "rms/session/session_folder.h"

#include <sodium.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

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

std::string SessionFileSha256(const std::string& dir, const std::string& name) {
  const std::string path = (fs::path(dir) / name).string();
  const int fd = OpenRegularFile(path, "the session's " + name, kMaxLogBytes);
  RMS_CHECK(sodium_init() >= 0);
  crypto_hash_sha256_state state;
  crypto_hash_sha256_init(&state);
  std::vector<unsigned char> block(std::size_t{1} << 20);
  for (;;) {
    const ssize_t n = read(fd, block.data(), block.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      close(fd);
      std::string why = "cannot read the session's " + name;
      why.append(" '").append(path).append("': ").append(std::strerror(err));
      throw InputError(why);
    }
    if (n == 0) break;
    crypto_hash_sha256_update(&state, block.data(), static_cast<unsigned long long>(n));
  }
  close(fd);
  unsigned char digest[crypto_hash_sha256_BYTES];
  crypto_hash_sha256_final(&state, digest);
  char hex[2 * crypto_hash_sha256_BYTES + 1];
  sodium_bin2hex(hex, sizeof hex, digest, sizeof digest);
  return hex;
}

std::string ReadSessionFile(const std::string& dir, const std::string& name,
                            std::uint64_t max_bytes) {
  return ReadRegularFile((fs::path(dir) / name).string(), "the session's " + name, max_bytes);
}

}  // namespace rms::session
