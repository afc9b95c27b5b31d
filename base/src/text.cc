#include "rms/base/text.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sys/stat.h>
#include <vector>

#include "rms/base/check.h"

namespace rms {

void WriteWholeFile(const std::string& path, const std::string& text) {
  // A regular file (or a new one) is written beside it and renamed over it,
  // so a failure (a full disk) leaves the old file, or none, never a part;
  // anything else (a device, a pipe) is written directly.
  struct stat st {};
  const bool regular = stat(path.c_str(), &st) != 0 || S_ISREG(st.st_mode);
  const std::string target = regular ? path + ".tmp" : path;
  {
    std::ofstream f(target, std::ios::binary | std::ios::trunc);
    if (!f) throw InputError("cannot write '" + path + "': " + std::strerror(errno));
    f << text;
    f.close();
    if (!f) {
      const int err = errno ? errno : EIO;
      if (regular) std::remove(target.c_str());
      throw InputError("could not write all of '" + path + "': " + std::strerror(err));
    }
  }
  if (regular && std::rename(target.c_str(), path.c_str()) != 0) {
    const int err = errno;
    std::remove(target.c_str());
    throw InputError("could not write '" + path + "': " + std::strerror(err));
  }
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
