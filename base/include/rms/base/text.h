#pragma once
// printf-style formatting into a std::string, for status screens and
// monitors (lines of fixed columns).
#include <cstdarg>
#include <cstdio>
#include <string>

namespace rms {

std::string Sprintf(const char* format, ...) __attribute__((format(printf, 1, 2)));

// A number as people write it (docs/sessions.md "Command lines"): at most
// `decimals` decimals, trailing zeros dropped ("20.9", not
// "20.899999999999999"; "3", not "3.000"); two significant digits below
// 10^-decimals; "nan" and "inf" as such.
std::string HumanNumber(double v, int decimals = 3);

// Writes `text` as the whole of the file at `path` and closes it; throws
// rms::InputError naming the file and why when any of it could not be
// written (a full disk shows only at the flush): a tool must not end as if
// its output were there.
void WriteWholeFile(const std::string& path, const std::string& text);

}  // namespace rms
