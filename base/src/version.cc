#include "rms/base/version.h"

#include "rms/version_info.h"  // generated: RMSLAB_GIT_DESCRIBE, RMSLAB_GIT_COMMIT

namespace rms {

const SoftwareVersion& Version() {
  static const SoftwareVersion v {
    RMSLAB_PROJECT_VERSION, RMSLAB_GIT_DESCRIBE, RMSLAB_GIT_COMMIT, RMSLAB_BUILD_TYPE,
#if defined(__clang__)
        std::string("Clang ") + __clang_version__
#elif defined(__GNUC__)
        std::string("GCC ") + __VERSION__
#else
        "unknown compiler"
#endif
  };
  return v;
}

std::string VersionString() {
  const SoftwareVersion& v = Version();
  return "rmslab " + v.project + " (" + v.describe + ", " + v.build_type + ", " + v.compiler + ")";
}

}  // namespace rms
