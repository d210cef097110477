// render::validate_bake: the whole `vtbake validate` job as a library call, on a small bake of
// the procedural sample scene. Input errors come before any Vulkan work, so they run anywhere.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "bake/scene_bake.h"
#include "render/report.h"
#include "render/validate.h"
#include "render/vulkan_context.h"
#include "samples/sample_scene.h"

namespace vt::render {
namespace {

class ValidateBake : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = (std::filesystem::temp_directory_path() /
            ("vt_validate_bake_" + std::to_string(::getpid())))
               .string();
    std::filesystem::remove_all(dir_);
    SampleSceneOptions so;
    so.ground_cells = 4;
    so.sphere_segments = 12;
    so.texture_size = 64;
    Status s = write_sample_scene(dir_ + "/scene", so);
    if (!s.ok()) {
      setup_error_ = s.message();
      return;
    }
    SceneBakeOptions o;
    o.build.output = dir_ + "/bake.vtpf";
    o.unwrap.size_pages = 4;
    auto baked = bake_scene(dir_ + "/scene/scene.gltf", o);
    if (!baked.ok()) setup_error_ = baked.status().message();
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(dir_); }
  void SetUp() override { ASSERT_TRUE(setup_error_.empty()) << setup_error_; }

  static BakeValidationOptions options() {
    BakeValidationOptions o;
    o.scene = dir_ + "/scene/scene.gltf";
    o.page_file = dir_ + "/bake.vtpf";
    o.views = 1;
    o.width = 160;
    o.height = 90;
    return o;
  }

  static std::string dir_, setup_error_;
};
std::string ValidateBake::dir_, ValidateBake::setup_error_;

TEST_F(ValidateBake, InputErrorsSayWhatIsWrong) {
  BakeValidationOptions o = options();
  o.cameras_file = dir_ + "/none.json";
  o.page_file = dir_ + "/none.vtpf";
  auto r = validate_bake(o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kNotFound);  // the camera file is read first
  EXPECT_NE(r.status().message().find("none.json"), std::string::npos);

  o.cameras_file.clear();
  r = validate_bake(o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kNotFound);
  EXPECT_NE(r.status().message().find("none.vtpf"), std::string::npos);

  o = options();
  o.layer = "nope";
  r = validate_bake(o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kNotFound);
  EXPECT_NE(r.status().message().find("'nope'"), std::string::npos);
  // A normal, ORM or emissive layer's name selects the lit check (tests/render/test_lit.cpp).
}

TEST_F(ValidateBake, PassesAndWritesItsReportBesideThePageFile) {
  if (auto ctx = VulkanContext::create(); !ctx.ok()) {
    GTEST_SKIP() << "no Vulkan device: " << ctx.status().message();
  }
  auto r = validate_bake(options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(r->passed());
  EXPECT_EQ(r->page_file, dir_ + "/bake.vtpf");
  EXPECT_EQ(r->out_dir, dir_ + "/bake.validate");  // the default: beside the page file
  EXPECT_FALSE(r->device.empty());
  EXPECT_EQ(r->width, 160u);
  ASSERT_EQ(r->views.size(), 1u);
  EXPECT_EQ(r->thresholds.min_psnr, scene_thresholds().min_psnr);
  for (const std::string& image : r->views[0].images) {
    EXPECT_TRUE(std::filesystem::exists(image)) << image;
  }
  std::ifstream f(r->out_dir + "/report.json", std::ios::binary);
  const std::string written{std::istreambuf_iterator<char>(f), {}};
  EXPECT_EQ(written, report_json(*r) + "\n");

  // Bounds no bake can meet: a report that has not passed, not an error.
  BakeValidationOptions strict = options();
  strict.thresholds.min_psnr = 99;
  strict.out_dir = dir_ + "/strict";
  r = validate_bake(strict);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_FALSE(r->passed());
  EXPECT_TRUE(std::filesystem::exists(dir_ + "/strict/report.json"));
}

}  // namespace
}  // namespace vt::render
