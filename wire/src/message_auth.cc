#include "rms/wire/message_auth.h"

#include <fcntl.h>
#include <sodium.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <sys/stat.h>

#include "rms/base/check.h"

namespace rms::wire {

namespace {

void StartSodium() {
  static const bool ok = sodium_init() >= 0;
  RMS_CHECK(ok);
}

int HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Closes a descriptor on every way out.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) close(fd);
  }
};

}  // namespace

std::array<std::uint8_t, kMacBytes> MessageMac(const SessionKey& key, std::string_view channel,
                                               const void* data, int size) {
  StartSodium();
  crypto_generichash_state st;
  crypto_generichash_init(&st, key.bytes.data(), key.bytes.size(), kMacBytes);
  crypto_generichash_update(&st, reinterpret_cast<const unsigned char*>(channel.data()),
                            channel.size());
  const unsigned char zero = 0;
  crypto_generichash_update(&st, &zero, 1);
  crypto_generichash_update(&st, static_cast<const unsigned char*>(data),
                            static_cast<unsigned long long>(size < 0 ? 0 : size));
  std::array<std::uint8_t, kMacBytes> tag{};
  crypto_generichash_final(&st, tag.data(), tag.size());
  return tag;
}

bool VerifyMessageMac(const SessionKey& key, std::string_view channel, const void* data, int size) {
  if (size < kMacBytes) return false;
  const int body = size - kMacBytes;
  const auto want = MessageMac(key, channel, data, body);
  return sodium_memcmp(want.data(), static_cast<const std::uint8_t*>(data) + body, kMacBytes) == 0;
}

SessionKey ReadSessionKeyFile(const std::string& path) {
  const Fd f{open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK)};
  if (f.fd < 0)
    throw InputError("session key " + path + ": cannot be opened (" + std::strerror(errno) +
                     (errno == ELOOP ? ": a link is not followed" : "") + ")");
  struct stat s {};
  if (fstat(f.fd, &s) != 0 || !S_ISREG(s.st_mode))
    throw InputError("session key " + path + ": not a regular file");
  if (s.st_uid != geteuid() &&
      geteuid() != 0)  // root (a namespace host under sudo) reads the user's
    throw InputError("session key " + path + ": owned by uid " + std::to_string(s.st_uid) +
                     ", not by this user (uid " + std::to_string(geteuid()) + ")");
  if ((s.st_mode & 077) != 0)
    throw InputError("session key " + path +
                     ": readable or writable by others (chmod 600 it, or make the session again)");
  char text[2 * kSessionKeyBytes + 2] = {};
  const ssize_t n = read(f.fd, text, sizeof text);
  if (n != 2 * kSessionKeyBytes + 1 || text[2 * kSessionKeyBytes] != '\n')
    throw InputError("session key " + path + ": not 64 hex digits and a newline");
  SessionKey key;
  for (int i = 0; i < kSessionKeyBytes; ++i) {
    const int hi = HexDigit(text[2 * i]), lo = HexDigit(text[2 * i + 1]);
    if (hi < 0 || lo < 0)
      throw InputError("session key " + path + ": not 64 hex digits and a newline");
    key.bytes[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(hi * 16 + lo);
  }
  sodium_memzero(text, sizeof text);
  return key;
}

std::optional<SessionKey> SessionKeyFromEnv() {
  const char* v = std::getenv("RMSLAB_SESSION_KEY_FILE");
  if (!v || !*v) return std::nullopt;
  return ReadSessionKeyFile(v);
}

}  // namespace rms::wire
