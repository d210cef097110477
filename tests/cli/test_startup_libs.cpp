// The light commands (info, verify, version, clean, extract to PNG) start without the bake stack:
// the executable links the runtime side only and loads the bake commands module for the other
// commands (docs/ARCHITECTURE.md, "Start-up"). The dynamic loader's own log (LD_DEBUG=libs) says
// which shared objects a process loaded.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "tests/cli/cli_test_util.h"
#include "tests/format/page_file_test_util.h"

namespace vt {
namespace {

// The loader's log of `vtbake ARGS` (on stderr; stdout dropped) and the exit status.
vt::testing::RunResult loader_log(const std::string& args) {
  return vt::testing::run_command("LD_DEBUG=libs " + std::string(VTBAKE_BINARY) + " " + args +
                                  " 2>&1 >/dev/null");
}

// What the bake stack loads: OpenImageIO, OpenColorIO, Vulkan, assimp, Draco, CGAL's GMP,
// oneTBB (OpenImageIO's) and the commands module itself.
const std::vector<std::string> kBakeStack = {"libOpenImageIO", "libOpenColorIO",    "libvulkan",
                                             "libassimp",      "libdraco",          "libgmp",
                                             "libtbb",         "libvtbake-commands"};

std::string small_page_file() {
  const std::string path = vt::testing::temp_path("startup.vtpf");
  const auto r = vt::testing::run_vtbake("-q build procedural:64x64 -o " + path, true);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  return path;
}

TEST(CliStartup, LightCommandsLoadNoBakeLibrary) {
  const std::string file = small_page_file();
  for (const std::string& args : std::vector<std::string>{
           "info " + file, "--json info " + file, "verify " + file, "version", "info --help",
           "clean " + std::filesystem::path(file).parent_path().string(),
           "extract " + file + " --level 0 -o " + file + ".png"}) {
    SCOPED_TRACE(args);
    const auto r = loader_log(args);
    EXPECT_EQ(r.exit_code, 0) << r.out;
    // The log is there and names what was loaded (zstd: the page reader's).
    ASSERT_NE(r.out.find("libzstd"), std::string::npos) << r.out;
    for (const auto& lib : kBakeStack) EXPECT_EQ(r.out.find(lib), std::string::npos) << lib;
  }
}

// The same check sees the bake stack where it is loaded: a bake command and the full --help.
TEST(CliStartup, BakeCommandsLoadTheModule) {
  const std::string file = small_page_file();
  // extract writes 8-bit PNG itself; EXR (and every other format) is OpenImageIO's.
  for (const std::string& args : std::vector<std::string>{
           "sample --help", "--help", "extract " + file + " --level 0 -o " + file + ".exr"}) {
    SCOPED_TRACE(args);
    const auto r = loader_log(args);
    EXPECT_EQ(r.exit_code, 0) << r.out;
    EXPECT_NE(r.out.find("libvtbake-commands"), std::string::npos);
    EXPECT_NE(r.out.find("libOpenImageIO"), std::string::npos);
  }
}

}  // namespace
}  // namespace vt
