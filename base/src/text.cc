#include "rms/base/text.h"

#include <cerrno>
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

}  // namespace rms
