// Inputs and outputs that are not regular files (issue 20): a FIFO given to info, verify or
// extract is refused at once (it used to block forever), a FIFO or device at `-o` is refused and
// left as it was, and a symlink at `-o` is written through.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "format/page_file.h"
#include "tests/cli/cli_test_util.h"

namespace vt {
namespace {

using vt::testing::run_vtbake;

std::string fresh_dir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() /
             ("vtbake_cli_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

TEST(CliHostilePaths, FifoInputIsRefusedWithoutBlocking) {
  const std::string dir = fresh_dir("fifo_in");
  const std::string fifo = dir + "/pipe.vtpf";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string command : {"info", "verify", "extract"}) {
    const std::string extra = command == "extract" ? " --level 0 -o " + dir + "/x.png" : "";
    auto r = run_vtbake(command + " " + fifo + extra, true);
    EXPECT_EQ(r.exit_code, 2) << command << "\n" << r.out;
    EXPECT_NE(r.out.find(fifo + ": not a regular file (a FIFO)"), std::string::npos) << r.out;
  }
  std::filesystem::remove_all(dir);
}

TEST(CliHostilePaths, OutputThatIsNotAFileIsRefusedAndALinkIsWrittenThrough) {
  const std::string dir = fresh_dir("out");
  const std::string fifo = dir + "/out.vtpf";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto r = run_vtbake("build procedural:64x64 -q -o " + fifo, true);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find(fifo + " is a FIFO: refusing to replace it with a file"), std::string::npos)
      << r.out;
  struct stat st;
  ASSERT_EQ(::lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  r = run_vtbake("build procedural:64x64 -q -o " + dir, true);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find(dir + " is a directory"), std::string::npos) << r.out;

  const std::string target = dir + "/real.vtpf", link = dir + "/link.vtpf";
  ASSERT_EQ(::symlink("real.vtpf", link.c_str()), 0);  // relative, resolved from its folder
  r = run_vtbake("build procedural:64x64 -q -o " + link, true);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  ASSERT_EQ(::lstat(link.c_str(), &st), 0);
  EXPECT_TRUE(S_ISLNK(st.st_mode));
  EXPECT_TRUE(PageFileReader::open(target).ok());
  size_t entries = 0;
  for ([[maybe_unused]] auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 3u);  // fifo, link, target: no temporary left
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace vt
