#include "rms/base/check.h"

#include <cstdio>
#include <cstdlib>

namespace rms {

void AbortOnBrokenInvariant(const char* condition, const char* file, int line,
                            const char* message) {
  std::fprintf(stderr, "rmslab: internal invariant broken: %s at %s:%d %s\n", condition, file, line,
               message);
  std::fflush(stderr);
  std::abort();
}

}  // namespace rms
