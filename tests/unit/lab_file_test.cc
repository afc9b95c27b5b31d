// A lab file's defaults (rms/session/lab_file.h) are the default LCM URL's
// group and port (rms/transport/lcm_interface.h kDefaultLcmUrl: the one home,
// docs/architecture.md "One home for each quantity").
#include "rms/session/lab_file.h"

#include <gtest/gtest.h>
#include <string>

#include "rms/transport/lcm_interface.h"

namespace rms::session {
namespace {

TEST(LabFile, ItsDefaultGroupAndPortAreTheDefaultLcmUrls) {
  const LabFile lab;
  const std::string url = transport::kDefaultLcmUrl;
  EXPECT_EQ(url.rfind("udpm://" + lab.group + ":" + std::to_string(lab.port) + "?", 0), 0u)
      << url << " vs " << lab.group << ":" << lab.port;
  // The example lab file in the tree says the same.
  const LabFile example = LoadLabFile(std::string(RMSLAB_SOURCE_DIR) + "/config/lab.toml");
  EXPECT_EQ(example.group, lab.group);
  EXPECT_EQ(example.port, lab.port);
}

}  // namespace
}  // namespace rms::session
