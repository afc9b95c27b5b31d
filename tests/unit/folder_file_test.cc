// A session folder's files read as untrusted input, and a tool's outputs
// written without writing through what stands at their names
// (docs/security.md "Session folders are untrusted").
#include "rms/base/folder_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <string>
#include <sys/stat.h>

#include "rms/base/check.h"

namespace rms {
namespace {

namespace fs = std::filesystem;

std::string Why(const std::string& path, Links links, std::uint64_t max = 1 << 20) {
  try {
    ReadRegularFile(path, "the file", max, links);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(read)";
}

std::string Slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

TEST(FolderFile, OnlyARegularFileOfItsSizeIsReadAndNothingHangs) {
  const fs::path dir = fs::path(::testing::TempDir()) / "folder_file_read";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "secret") << "root only\n";
  std::ofstream(dir / "ok.json") << "{}\n";
  fs::create_symlink(dir / "secret", dir / "link.json");
  ASSERT_EQ(mkfifo((dir / "fifo.json").c_str(), 0600), 0);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(ReadRegularFile((dir / "ok.json").string(), "x", 100), "{}\n");
  EXPECT_NE(Why((dir / "link.json").string(), Links::kRefuse).find("a link, not followed"),
            std::string::npos);
  EXPECT_NE(Why((dir / "fifo.json").string(), Links::kRefuse).find("a FIFO, not a regular file"),
            std::string::npos);
  EXPECT_NE(Why("/dev/zero", Links::kRefuse).find("a device"), std::string::npos);
  EXPECT_NE(Why("/dev/zero", Links::kFollow).find("a device"), std::string::npos);
  EXPECT_NE(Why(dir.string(), Links::kRefuse).find("a folder"), std::string::npos);
  EXPECT_NE(Why((dir / "ok.json").string(), Links::kRefuse, 2).find("3 bytes, more than"),
            std::string::npos);
  // A path the user gave follows its link.
  EXPECT_EQ(ReadRegularFile((dir / "link.json").string(), "x", 100, Links::kFollow), "root only\n");
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5)) << "something waited";
  fs::remove_all(dir);
}

TEST(FolderFile, AnOutputFolderNeverWritesThroughALinkAndLeavesNothingHalfWritten) {
  const fs::path dir = fs::path(::testing::TempDir()) / "folder_file_write";
  fs::remove_all(dir);
  fs::create_directories(dir / "elsewhere");
  std::ofstream(dir / "target") << "keep me\n";
  // The output folder itself a link: refused.
  fs::create_directory_symlink(dir / "elsewhere", dir / "csv_link");
  EXPECT_THROW(OutputFolder((dir / "csv_link").string()), InputError);
  {
    OutputFolder out((dir / "csv").string());
    fs::create_symlink(dir / "target", dir / "csv" / "a.csv");  // planted at the output's name
    const int fd = out.Begin("a.csv");
    ASSERT_EQ(write(fd, "new\n", 4), 4);
    out.Commit();
  }
  EXPECT_EQ(Slurp(dir / "target"), "keep me\n") << "written through the link";
  EXPECT_FALSE(fs::is_symlink(dir / "csv" / "a.csv"));
  EXPECT_EQ(Slurp(dir / "csv" / "a.csv"), "new\n");
  {
    OutputFolder out((dir / "csv").string());
    const int fd = out.Begin("b.csv");
    ASSERT_EQ(write(fd, "part", 4), 4);
    // Not committed (a failure part way): nothing of it is left.
  }
  EXPECT_FALSE(fs::exists(dir / "csv" / "b.csv"));
  int left = 0;
  for (const auto& e : fs::directory_iterator(dir / "csv"))
    left += e.path() != dir / "csv" / "a.csv";
  EXPECT_EQ(left, 0) << "a temporary file left behind";
  EXPECT_TRUE(fs::is_empty(dir / "elsewhere"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rms
