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

TEST(CliFlags, BuildFlagsAreSharedByBuildAndBake) {
  // Each bad value fails at parse time, naming its flag, in both commands.
  for (const char* command : {"build procedural:240x240", "bake missing.gltf"}) {
    for (const char* flag :
         {"--filter gauss", "--fix-nonfinite zero", "--alpha-coverage 2", "--payload x"}) {
      auto r = run_vtbake(std::string(command) + " -o /nonexistent/x.vtpf " + flag, true);
      EXPECT_EQ(r.exit_code, 2) << command << " " << flag << "\n" << r.out;
      const std::string name = std::string(flag).substr(0, std::string(flag).find(' '));
      EXPECT_TRUE(contains(r.out, name)) << r.out;
    }
  }
  // Good values parse, so the bake gets as far as the missing scene.
  auto r = run_vtbake(
      "bake missing.gltf -o /tmp/x.vtpf --filter box --alpha-coverage 0.5 --fix-nonfinite clamp "
      "--scratch-dir /tmp --memory-limit 1G --payload 56 --border 2",
      true);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "missing.gltf: cannot open")) << r.out;
}

TEST(CliFlags, UnwrapFlagsHaveOneRangeInUnwrapAndBake) {
  for (const char* command :
       {"unwrap missing.gltf -o /tmp/x.glb", "bake missing.gltf -o /tmp/x.vtpf"}) {
    // --padding takes the unwrapper's own bound, 0..1024, everywhere (bake stopped at 64).
    auto ok = run_vtbake(std::string(command) + " --padding 100 --chart-angle 45", true);
    EXPECT_EQ(ok.exit_code, 2) << ok.out;
    EXPECT_TRUE(contains(ok.out, "missing.gltf")) << ok.out;
    EXPECT_FALSE(contains(ok.out, "--padding")) << ok.out;
    for (const char* flag : {"--padding 1025", "--size 0", "--size 16385", "--method abf",
                             "--max-stretch 0.5", "--size 4 --texels-per-unit 10"}) {
      auto r = run_vtbake(std::string(command) + " " + flag, true);
      EXPECT_EQ(r.exit_code, 2) << command << " " << flag << "\n" << r.out;
      EXPECT_TRUE(contains(r.out, std::string(flag).substr(0, std::string(flag).find(' '))))
          << r.out;
    }
  }
}

// One exit-code rule (cli/cli_util.h): bad input 2, a failed write 1, whatever the command.
TEST(CliExitCodes, BadInputIsTwoAndAFailedWriteIsOne) {
  for (const char* command :
       {"info /tmp", "verify /tmp", "extract /tmp --level 0 -o /tmp/x.png",
        "unwrap /tmp/missing.gltf -o /tmp/x.glb", "bake /tmp/missing.gltf -o /tmp/x.vtpf",
        "build /tmp/missing.png -o /tmp/x.vtpf"}) {
    auto r = run_vtbake(command, true);
    EXPECT_EQ(r.exit_code, 2) << command << "\n" << r.out;
    EXPECT_TRUE(contains(r.out, "vtbake ")) << r.out;
  }
  auto w = run_vtbake("build procedural:64x64 -o /nonexistent/folder/x.vtpf", true);
  EXPECT_EQ(w.exit_code, 1) << w.out;
  EXPECT_TRUE(contains(w.out, "vtbake build: /nonexistent/folder/x.vtpf")) << w.out;
}

}  // namespace
}  // namespace vt
