// The flag rules shared by subcommands (cli/cli_util.h): one spelling of --codec and
// --memory-limit everywhere, and exit status 2 with a message naming the flag when it is wrong.
#include <gtest/gtest.h>

#include <string>

#include "tests/cli/cli_test_util.h"

namespace vt {
namespace {

using vt::testing::run_vtbake;

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

TEST(CliFlags, BadCodecIsBadUsageInEveryCommand) {
  for (const char* command : {"build procedural:240x240", "bake missing.gltf"}) {
    for (const char* codec : {"dct:0", "dct:101", "dct:", "dct:abc", "dct:50:fast",
                              "dct:adaptive:50", "dct::adaptive", "bc:slow", "raw:1", "jpeg"}) {
      auto r = run_vtbake(std::string(command) + " -o /nonexistent/x.vtpf --codec " + codec, true);
      EXPECT_EQ(r.exit_code, 2) << command << " --codec " << codec << "\n" << r.out;
      EXPECT_TRUE(contains(r.out, "--codec")) << r.out;
    }
  }
}

TEST(CliFlags, BadMemoryLimitIsBadUsageInEveryCommand) {
  for (const char* command : {"build procedural:240x240", "bake missing.gltf"}) {
    for (const char* size : {"0", "-1G", "2X", "G", "1e300G"}) {
      auto r =
          run_vtbake(std::string(command) + " -o /nonexistent/x.vtpf --memory-limit " + size, true);
      EXPECT_EQ(r.exit_code, 2) << command << " --memory-limit " << size << "\n" << r.out;
      EXPECT_TRUE(contains(r.out, "--memory-limit")) << r.out;
    }
  }
}

TEST(CliFlags, GoodCodecAndMemoryLimitReachTheWork) {
  // The flags parse, so the command gets as far as the missing scene and names it.
  auto r = run_vtbake("bake missing.gltf -o /tmp/x.vtpf --codec bc:high --memory-limit 512M", true);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "missing.gltf")) << r.out;
  EXPECT_FALSE(contains(r.out, "--codec")) << r.out;
  for (const char* codec : {"dct:adaptive", "dct:60:adaptive"}) {
    auto d = run_vtbake(std::string("bake missing.gltf -o /tmp/x.vtpf --codec ") + codec, true);
    EXPECT_TRUE(contains(d.out, "missing.gltf")) << codec << "\n" << d.out;
    EXPECT_FALSE(contains(d.out, "--codec")) << codec << "\n" << d.out;
  }
}

}  // namespace
}  // namespace vt
