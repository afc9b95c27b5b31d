#pragma once
// printf-style formatting into a std::string, for status screens and
// monitors (lines of fixed columns).
#include <cstdarg>
#include <cstdio>
#include <string>

namespace rms {

std::string Sprintf(const char* format, ...) __attribute__((format(printf, 1, 2)));

}  // namespace rms
