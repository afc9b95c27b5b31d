#include "rms/text.h"

#include <vector>

#include <cerrno>
#include <cstring>
#include <fstream>

#include "rms/check.h"

namespace rms {

void WriteWholeFile(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) throw InputError("cannot write '" + path + "': " + std::strerror(errno));
  f << text;
  f.close();
  if (!f) throw InputError("could not write all of '" + path + "': " + std::strerror(errno ? errno : EIO));
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

}  // namespace rms
