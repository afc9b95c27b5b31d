#pragma once
// printf-style formatting into a std::string, for status screens and
// monitors (lines of fixed columns).
#include <cstdarg>
#include <cstdio>
#include <string>

namespace rms {

std::string Sprintf(const char* format, ...) __attribute__((format(printf, 1, 2)));

// Writes `text` as the whole of the file at `path` and closes it; throws
// rms::InputError naming the file and why when any of it could not be
// written (a full disk shows only at the flush): a tool must not end as if
// its output were there.
void WriteWholeFile(const std::string& path, const std::string& text);

}  // namespace rms
