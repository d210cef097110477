// `vtbake build` and the colour config: --colorconfig, else $OCIO, else the built-in config;
// errors name the config file; a gAMA-tagged PNG builds.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "format/page_file.h"
#include "format/page_file_inspect.h"
#include "tests/cli/cli_test_util.h"
#include "tests/process_temp_dir.h"

namespace vt {
namespace {

namespace fs = std::filesystem;
using vt::testing::run_vtbake;

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

fs::path temp_dir() {
  fs::path d = test::process_temp_dir("vt_cli_colour") /
               ::testing::UnitTest::GetInstance()->current_test_info()->name();
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// A config whose file rule sends "*_dim.exr" to a space at a quarter of the working space's
// intensity.
const char* kConfig = R"(ocio_profile_version: 2
roles:
  scene_linear: lin
  default: lin
file_rules:
  - !<Rule> {name: dim, pattern: "*_dim", extension: "exr", colorspace: dim}
  - !<Rule> {name: Default, colorspace: default}
displays:
  sRGB:
    - !<View> {name: Raw, colorspace: lin}
colorspaces:
  - !<ColorSpace>
    name: lin
  - !<ColorSpace>
    name: dim
    to_scene_reference: !<MatrixTransform> {matrix: [0.25, 0, 0, 0, 0, 0.25, 0, 0, 0, 0, 0.25, 0, 0, 0, 0, 1]}
)";

void write_image(const std::string& path, OIIO::TypeDesc type, float value, const char* space) {
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out) << path;
  OIIO::ImageSpec spec(4, 4, 3, type);
  if (space) spec.attribute("oiio:ColorSpace", space);
  std::vector<float> px(4 * 4 * 3, value);
  ASSERT_TRUE(out->open(path, spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, px.data()));
  ASSERT_TRUE(out->close());
}

// The first stored float of level 0 (raw codec, float layer).
float first_texel(const std::string& vtpf) {
  auto reader = PageFileReader::open(vtpf);
  EXPECT_TRUE(reader.ok()) << reader.status().message();
  if (!reader.ok()) return -1;
  auto level = extract_level(**reader, 0, 0);
  EXPECT_TRUE(level.ok() && level->texel_type == TexelType::kF32);
  if (!level.ok() || level->texels.size() < 4) return -1;
  float v;
  std::memcpy(&v, level->texels.data(), 4);
  return v;
}

TEST(CliColour, ConfigFromFlagOrOcioEnvironment) {
  const fs::path dir = temp_dir();
  const std::string config = (dir / "dim.ocio").string();
  std::ofstream(config) << kConfig;
  const std::string exr = (dir / "wall_dim.exr").string();
  write_image(exr, OIIO::TypeDesc::HALF, 0.5f, nullptr);
  const std::string build = "build " + exr + " --codec raw --payload 8 -o " + exr + ".vtpf";

  auto plain = run_vtbake("--quiet " + build, true);
  ASSERT_EQ(plain.exit_code, 0) << plain.out;
  EXPECT_FLOAT_EQ(first_texel(exr + ".vtpf"), 0.5f);  // built-in config: no file rules

  auto flag = run_vtbake("--quiet " + build + " --colorconfig " + config, true);
  ASSERT_EQ(flag.exit_code, 0) << flag.out;
  EXPECT_FLOAT_EQ(first_texel(exr + ".vtpf"), 0.125f);

  const std::string with_env = "env OCIO=" + config + " " + std::string(VTBAKE_BINARY);
  FILE* pipe = ::popen((with_env + " --quiet " + build + " 2>&1").c_str(), "r");
  ASSERT_TRUE(pipe);
  char buf[512];
  std::string out;
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) out.append(buf, n);
  ASSERT_EQ(::pclose(pipe), 0) << out;
  EXPECT_FLOAT_EQ(first_texel(exr + ".vtpf"), 0.125f);

  // --colorspace wins over the file rules.
  auto forced =
      run_vtbake("--quiet " + build + " --colorconfig " + config + " --colorspace lin", true);
  ASSERT_EQ(forced.exit_code, 0) << forced.out;
  EXPECT_FLOAT_EQ(first_texel(exr + ".vtpf"), 0.5f);
}

TEST(CliColour, BadConfigAndUnknownSpaceNameTheProblem) {
  const fs::path dir = temp_dir();
  const std::string png = (dir / "a.png").string();
  write_image(png, OIIO::TypeDesc::UINT8, 0.5f, nullptr);
  auto missing = run_vtbake(
      "build " + png + " -o /tmp/x.vtpf --colorconfig " + (dir / "missing.ocio").string(), true);
  EXPECT_EQ(missing.exit_code, 2) << missing.out;
  EXPECT_TRUE(contains(missing.out, "--colorconfig")) << missing.out;
  EXPECT_TRUE(contains(missing.out, "missing.ocio")) << missing.out;

  const std::string config = (dir / "dim.ocio").string();
  std::ofstream(config) << kConfig;
  auto unknown = run_vtbake("build " + png + " -o " + (dir / "x.vtpf").string() +
                                " --colorconfig " + config + " --colorspace ProPhoto",
                            true);
  EXPECT_EQ(unknown.exit_code, 2) << unknown.out;
  EXPECT_TRUE(contains(unknown.out, "'ProPhoto'")) << unknown.out;
  EXPECT_TRUE(contains(unknown.out, "dim.ocio")) << unknown.out;
  EXPECT_TRUE(contains(unknown.out, "lin, dim")) << unknown.out;
}

TEST(CliColour, GammaTaggedPngBuilds) {
  const fs::path dir = temp_dir();
  const std::string png = (dir / "gamma.png").string();
  write_image(png, OIIO::TypeDesc::UINT8, 0.5f, "Gamma2.2");
  auto r = run_vtbake("build " + png + " -o " + (dir / "gamma.vtpf").string(), true);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_FALSE(contains(r.out, "unknown colour space")) << r.out;
}

}  // namespace
}  // namespace vt
