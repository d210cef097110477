// End-to-end: `vtbake bake` on an OBJ whose MTL names a texture that is not there: an error
// naming the material, slot and path by default; with --missing-textures warn a bake from the
// factor alone, the miss printed as a warning and listed in --json.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/cli/cli_test_util.h"
#include "tests/format/page_file_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;

// A textured quad whose map_Kd file does not exist; returns the .obj path.
std::string quad_with_missing_texture(const std::string& map_kd = "textures/brick.png") {
  const std::string obj = temp_path("quad.obj");
  const std::string dir = obj.substr(0, obj.rfind('/'));
  std::ofstream(obj) << "mtllib quad.mtl\n"
                        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                        "usemtl Brick\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
  std::ofstream(dir + "/quad.mtl") << "newmtl Brick\nKd 0.5 0.25 1.0\nmap_Kd " << map_kd << "\n";
  return obj;
}

TEST(CliBake, MissingTextureIsAnErrorNamingMaterialSlotAndPath) {
  const std::string obj = quad_with_missing_texture();
  const std::string dir = obj.substr(0, obj.rfind('/'));
  RunResult r = run_vtbake("bake " + obj + " -o " + dir + "/q.vtpf --size 1 --unwrapped -", true);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("material 'Brick' baseColorTexture: cannot read image"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("(tried " + dir + "/textures/brick.png)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(--missing-textures warn bakes the slot from its factor)"),
            std::string::npos)
      << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir + "/q.vtpf"));
}

// OpenImageIO's "null" plugin makes up a 1024x1024 image for any name ending in .nul, there or not:
// such a texture baked silently from nothing, and an MTL map_d packed from it crashed the loader.
TEST(CliBake, ATextureNamedForOpenImageIOsNullPluginIsNotAnImage) {
  for (const bool present : {false, true}) {
    const std::string obj = quad_with_missing_texture("brick.nul");
    const std::string dir = obj.substr(0, obj.rfind('/'));
    if (present) std::ofstream(dir + "/brick.nul") << "not an image";
    if (present) std::ofstream(dir + "/alpha.nul") << "not an image";
    std::ofstream(dir + "/quad.mtl", std::ios::app) << "map_d alpha.nul\n";  // packed into map_Kd
    RunResult r = run_vtbake("bake " + obj + " -o " + dir + "/q.vtpf --size 1 --unwrapped -", true);
    EXPECT_EQ(r.exit_code, 2) << r.out;
    EXPECT_NE(r.out.find("material 'Brick' baseColorTexture: cannot read image"), std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find(present ? "not an image file" : "Could not open file"), std::string::npos)
        << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir + "/q.vtpf"));
  }
}

TEST(CliBake, MissingTextureWarnBakesAndReports) {
  const std::string obj = quad_with_missing_texture();
  const std::string dir = obj.substr(0, obj.rfind('/'));
  const std::string args =
      "bake " + obj + " -o " + dir + "/q.vtpf --size 1 --unwrapped - --missing-textures warn";
  RunResult r = run_vtbake("-q " + args, true);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  // The unwrap's line (the image does not size the atlas), then the transfer's.
  EXPECT_EQ(r.out.rfind("warning: 1 image(s) gave no size", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("\nwarning: material 'Brick' baseColorTexture: cannot read image"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("(baked from the factor alone)"), std::string::npos) << r.out;

  r = run_vtbake("--json " + args, false);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["transfer"]["missing_textures"].size(), 1u);
  const auto& miss = j["transfer"]["missing_textures"][0];
  EXPECT_EQ(miss["material"], "Brick");
  EXPECT_EQ(miss["slot"], "baseColorTexture");
  EXPECT_EQ(miss["path"], dir + "/textures/brick.png");
  ASSERT_EQ(j["warnings"].size(), 2u);

  EXPECT_EQ(run_vtbake(args + "x", false).exit_code, 2);  // an unknown policy is bad usage
}

// `vtbake validate` repeats what the bake did: a slot baked from its factor (the bake's metadata
// says so) is drawn from its factor, with a warning; the texture back in place, the bake no longer
// matches the scene and fails. A bake that read the texture, validated after the texture is gone,
// is an error naming the material and slot. --atlas-only: the references without Vulkan.
TEST(CliBake, ValidateDrawsASlotBakedFromItsFactorTheSameWay) {
  const std::string obj = quad_with_missing_texture();
  const std::string dir = obj.substr(0, obj.rfind('/'));
  const std::string bake = "-q bake " + obj + " -o " + dir + "/q.vtpf --size 1";
  const std::string validate = "validate " + obj + " " + dir + "/q.vtpf --atlas-only";
  ASSERT_EQ(run_vtbake(bake + " --missing-textures warn", true).exit_code, 0);
  RunResult r = run_vtbake(validate, true);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("material 'Brick' baseColorTexture: cannot open image"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("(drawn from its factor, as the bake did)"), std::string::npos) << r.out;

  // A 2 x 2 checker of red and blue: far from the factor the bake used.
  std::filesystem::create_directories(dir + "/textures");
  const uint8_t texels[] = {255, 0, 0, 0, 0, 255, 0, 0, 255, 255, 0, 0};
  auto out = OIIO::ImageOutput::create(dir + "/textures/brick.png");
  ASSERT_TRUE(out);
  ASSERT_TRUE(
      out->open(dir + "/textures/brick.png", OIIO::ImageSpec(2, 2, 3, OIIO::TypeDesc::UINT8)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, texels));
  out->close();
  r = run_vtbake(validate, true);
  EXPECT_EQ(r.exit_code, 1) << r.out;  // the scene changed since the bake

  ASSERT_EQ(run_vtbake(bake, true).exit_code, 0);
  std::filesystem::remove(dir + "/textures/brick.png");
  r = run_vtbake(validate, true);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("material 'Brick' baseColorTexture: cannot open image"), std::string::npos)
      << r.out;
}

}  // namespace
}  // namespace vt
