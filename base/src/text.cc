#include "rms/base/text.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sys/stat.h>
#include <vector>

#include "rms/base/check.h"
#include "rms/base/folder_file.h"

namespace rms {

namespace {

// A stream the user named: a FIFO or a device at the path itself, or
// anything under /dev or /proc (/dev/stdout, /dev/full, /proc/self/fd/N).
// Written directly; anything else is a file, replaced whole.
bool IsStream(const std::string& path, const struct stat& st) {
  return S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode) || path.rfind("/dev/", 0) == 0 ||
         path.rfind("/proc/", 0) == 0;
}

void WriteStream(const std::string& path, const std::string& text) {
  // A FIFO nobody reads is refused (ENXIO), not waited on; a file reached
  // through a link the user named is written from its start, as `>` does.
  const int fd = open(path.c_str(), O_WRONLY | O_TRUNC | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    throw InputError("cannot write '" + path + "': " +
                     (errno == ENXIO ? std::string("a FIFO that nothing reads")
                                     : std::string(std::strerror(errno))));
  }
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = n < 0 ? errno : EIO;
      close(fd);
      throw InputError("could not write all of '" + path + "': " + std::strerror(err));
    }
    done += static_cast<std::size_t>(n);
  }
  if (close(fd) != 0)
    throw InputError("could not write all of '" + path + "': " + std::strerror(errno));
}

}  // namespace

void WriteWholeFile(const std::string& path, const std::string& text, Links links) {
  struct stat st {};
  const bool exists = lstat(path.c_str(), &st) == 0;
  // A stream is written directly only where the user named it: a FIFO or a
  // device planted in a session's folder (an archive unpacked as root keeps
  // device nodes) is replaced like anything else there.
  const bool system = path.rfind("/dev/", 0) == 0 || path.rfind("/proc/", 0) == 0;
  if (exists &&
      (system || (links == Links::kFollow && (IsStream(path, st) || S_ISLNK(st.st_mode))))) {
    WriteStream(path, text);
    return;
  }
  // A fresh temporary file beside it (O_EXCL | O_NOFOLLOW), renamed over
  // its name only when whole: a failure (a full disk) leaves the old file,
  // or none, never a part, and a link planted at the name (or at a
  // temporary name) is replaced, never written through.
  const std::filesystem::path p(path);
  const std::string dir = p.has_parent_path() ? p.parent_path().string() : ".";
  OutputFolder out(dir, Links::kFollow);
  const int fd = out.Begin(p.filename().string());
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw InputError("could not write all of '" + path +
                       "': " + std::strerror(n < 0 ? errno : EIO));
    done += static_cast<std::size_t>(n);
  }
  out.Commit();
}

std::string Sprintf(const char* format, ...) {
  va_list ap;
  va_start(ap, format);
  va_list copy;
  va_copy(copy, ap);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  std::string out(n > 0 ? static_cast<std::size_t>(n) : 0, '\0');
  if (n > 0) std::vsnprintf(out.data(), out.size() + 1, format, ap);
  va_end(ap);
  return out;
}

std::string HumanNumber(double v, int decimals) {
  if (!std::isfinite(v)) return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
  if (v != 0 && std::abs(v) < std::pow(10.0, -decimals)) return Sprintf("%.2g", v);
  std::string s = Sprintf("%.*f", decimals, v);
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s;
}

std::string HtmlText(std::string_view s) {
  std::string o;
  o.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&':
        o += "&amp;";
        break;
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '"':
        o += "&quot;";
        break;
      case '\'':
        o += "&#39;";
        break;
      default:
        o += c;
    }
  }
  return o;
}

namespace {

bool IsNumber(std::string_view s) {
  double v = 0;
  const auto r = std::from_chars(s.data() + (s.size() > 1 && s[0] == '+'), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

}  // namespace

std::string CsvField(std::string_view s) {
  std::string v(s);
  if (!v.empty() && std::string_view("=+-@\t\r").find(v[0]) != std::string_view::npos &&
      !IsNumber(v))
    v.insert(0, 1, '\'');
  if (v.find_first_of(",\"\r\n") == std::string::npos) return v;
  std::string o = "\"";
  for (char c : v) o += c == '"' ? std::string("\"\"") : std::string(1, c);
  return o + "\"";
}

std::string TerminalText(std::string_view s) {
  std::string o;
  o.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    const bool c1_utf8 = c == 0xC2 && i + 1 < s.size() &&
                         static_cast<unsigned char>(s[i + 1]) >= 0x80 &&
                         static_cast<unsigned char>(s[i + 1]) <= 0x9F;
    if ((c < 0x20 && c != '\n' && c != '\t') || c == 0x7F) {
      o += Sprintf("\\x%02x", c);
    } else if (c1_utf8) {
      o += Sprintf("\\u%04x", static_cast<unsigned char>(s[++i]));
    } else {
      o += static_cast<char>(c);
    }
  }
  return o;
}

}  // namespace rms
