#pragma once
// The three kinds of check (after Drake's common/drake_assert.h):
//  - RMS_DASSERT(cond): debug-only assert for internal invariants; compiled
//    out of Release builds.
//  - RMS_CHECK(cond): always on; a broken invariant aborts with file, line and
//    the condition. Never used for user input.
//  - Bad user input (config files, command lines, timelines, messages) is
//    reported by exceptions (rms::InputError and friends) or error values
//    with a clear message, never by these macros.
#include <stdexcept>
#include <string>

namespace rms {

[[noreturn]] void AbortOnBrokenInvariant(const char* condition, const char* file, int line,
                                         const char* message);

// Thrown for bad user input: the message names what was wrong.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace rms

#define RMS_CHECK(cond)                                                        \
  do {                                                                         \
    if (!(cond)) ::rms::AbortOnBrokenInvariant(#cond, __FILE__, __LINE__, ""); \
  } while (0)

#define RMS_CHECK_MSG(cond, msg)                                                \
  do {                                                                          \
    if (!(cond)) ::rms::AbortOnBrokenInvariant(#cond, __FILE__, __LINE__, msg); \
  } while (0)

#ifdef NDEBUG
#define RMS_DASSERT(cond) \
  do {                    \
  } while (0)
#else
#define RMS_DASSERT(cond) RMS_CHECK(cond)
#endif
