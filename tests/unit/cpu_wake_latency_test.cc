// CpuWakeLatencyRequest (docs/performance.md "Wake latency"): the request
// is written as the kernel reads it (a binary 32-bit integer), held open
// for the request's life and closed with it; one that cannot be made says
// why; RMSLAB_CPU_WAKE_LATENCY_US is read strictly. The device itself is
// exercised by the session test (LabDemo), where the machine allows it.
#include "rms/base/cpu_wake_latency.h"

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <iterator>
#include <string>

#include "rms/base/check.h"

namespace rms {
namespace {

namespace fs = std::filesystem;

// Whether this process holds a file open on `path`.
bool HoldsOpen(const fs::path& path) {
  for (const auto& e : fs::directory_iterator("/proc/self/fd")) {
    std::error_code ec;
    if (fs::read_symlink(e.path(), ec) == path) return true;
  }
  return false;
}

fs::path TempPath(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rms_wake_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return dir / name;
}

TEST(CpuWakeLatency, TheRequestIsWrittenAsABinaryIntegerAndHeldOpenUntilItEnds) {
  const fs::path device = TempPath("device");
  std::ofstream(device).close();
  {
    CpuWakeLatencyRequest wake(250, device.string());
    EXPECT_TRUE(wake.asked());
    ASSERT_TRUE(wake.held()) << wake.state();
    EXPECT_EQ(wake.state(), "held at 250 us (" + device.string() + ")");
    std::ifstream in(device, std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), {}};
    ASSERT_EQ(bytes.size(), 4u);
    std::int32_t v = -1;
    std::memcpy(&v, bytes.data(), 4);
    EXPECT_EQ(v, 250);
    EXPECT_TRUE(HoldsOpen(device));
    CpuWakeLatencyRequest moved(std::move(wake));
    EXPECT_FALSE(wake.held());  // NOLINT(bugprone-use-after-move): moved-from is defined
    EXPECT_TRUE(moved.held());
    EXPECT_TRUE(HoldsOpen(device));
  }
  EXPECT_FALSE(HoldsOpen(device)) << "the request outlived its holder";
  fs::remove_all(device.parent_path());
}

TEST(CpuWakeLatency, ARequestThatCannotBeMadeSaysWhyAndHoldsNothing) {
  const fs::path dir = TempPath("a-folder");
  fs::create_directories(dir);
  const CpuWakeLatencyRequest folder(0, dir.string());
  EXPECT_TRUE(folder.asked());
  EXPECT_FALSE(folder.held());
  EXPECT_EQ(folder.state(), "not held at 0 us: " + dir.string() + ": Is a directory");
  const CpuWakeLatencyRequest missing(0, (dir / "none").string());
  EXPECT_EQ(missing.state(),
            "not held at 0 us: " + (dir / "none").string() + ": No such file or directory");
  const CpuWakeLatencyRequest none;
  EXPECT_FALSE(none.asked());
  EXPECT_EQ(none.state(), "off");
  fs::remove_all(dir.parent_path());
}

TEST(CpuWakeLatency, TheLaunchersRequestIsReadStrictly) {
  const auto with = [](const char* v) {
    if (v)
      setenv(kCpuWakeLatencyEnv, v, 1);
    else
      unsetenv(kCpuWakeLatencyEnv);
    return CpuWakeLatencyFromEnv();
  };
  EXPECT_EQ(with(nullptr), std::nullopt);
  EXPECT_EQ(with(""), std::nullopt);
  EXPECT_EQ(with("off"), std::nullopt);
  EXPECT_EQ(with("0"), 0);
  EXPECT_EQ(with("1000000"), 1000000);
  for (const char* bad : {"-1", "-0", "+5", "1000001", "0001000001", "12us", " 5", "5 ", "0x10",
                          "on", "OFF", "\xd9\xa3", "99999999999999999999"}) {
    try {
      with(bad);
      ADD_FAILURE() << bad << " was taken";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), std::string("RMSLAB_CPU_WAKE_LATENCY_US='") + bad +
                                           "': must be \"off\" or a whole number of "
                                           "microseconds, 0..1000000");
    }
  }
  unsetenv(kCpuWakeLatencyEnv);
}

}  // namespace
}  // namespace rms
