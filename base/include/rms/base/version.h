#pragma once
// The software's version, for --version and session manifests: the project
// version, and the source tree's git description and commit at build time
// ("unknown" outside a git checkout), with "-dirty" when it had changes.
#include <string>

namespace rms {

struct SoftwareVersion {
  std::string project;   // "0.1.0"
  std::string describe;  // git describe --always --dirty --tags
  std::string commit;    // the full commit hash
  std::string build_type;
  std::string compiler;
};
const SoftwareVersion& Version();
// "rmslab 0.1.0 (ec5eaf9-dirty, Release, GCC 12.2.0)"
std::string VersionString();

}  // namespace rms
