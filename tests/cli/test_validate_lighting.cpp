// End-to-end: the atlas and screen-space checks of a baked lighting layer (issue 21), on the lit
// sample scene (`vtbake sample-scene --lights`). The reference is lit by the
// original scene's lights where the original places them, with shadows always and the bake's
// AO settings; lux are compared after the tone map x / (1 + x). A correct lit bake passes; a
// bake whose light moved, or that skipped shadows, fails on its lighting layer.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/cli/cli_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;

class ValidateLighting : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fresh_test_dir("validate_lighting");
    // The lit sample scene: a sun, a bulb and a spot, KHR_lights_punctual required, as Blender
    // writes a lit level.
    setup_error_ = write_sample_scene(
        dir_ + "/scene", "--ground-cells 2 --sphere-segments 8 --texture-size 32 --lights");
    if (!setup_error_.empty()) return;
    std::filesystem::rename(dir_ + "/scene/scene.gltf", dir_ + "/scene/lit.gltf");
    nlohmann::json doc = nlohmann::json::parse(read_file(dir_ + "/scene/lit.gltf"));
    if (doc.value("extensionsRequired", nlohmann::json::array()) !=
        nlohmann::json::array({"KHR_lights_punctual"})) {
      setup_error_ = "sample-scene --lights does not require KHR_lights_punctual";
      return;
    }
    for (auto& node : doc["nodes"])
      if (node.value("name", "") == "bulb") {
        // The light nodes are written as matrices: move the translation column.
        node["matrix"][12] = 3.0, node["matrix"][13] = 2.0, node["matrix"][14] = -2.0;
      }
    std::ofstream(dir_ + "/scene/moved.gltf") << doc.dump();
    // The lit scene with its materials' base colours swapped round (a lit albedo baked from
    // another albedo: its light is right, its colour is not).
    doc = nlohmann::json::parse(read_file(dir_ + "/scene/lit.gltf"));
    auto& materials = doc["materials"];
    if (materials.size() < 2) {
      setup_error_ = "the sample scene has fewer than 2 materials";
      return;
    }
    for (size_t m = 0; m + 1 < materials.size(); m += 2)
      std::swap(materials[m]["pbrMetallicRoughness"], materials[m + 1]["pbrMetallicRoughness"]);
    std::ofstream(dir_ + "/scene/recoloured.gltf") << doc.dump();
    // The same scene without its lights (for the light-less check).
    const std::string unlit = write_sample_scene(dir_ + "/unlit");
    if (!unlit.empty()) setup_error_ = unlit;
  }
  static void TearDownTestSuite() { remove_test_dir(dir_); }
  void SetUp() override { ASSERT_TRUE(setup_error_.empty()) << setup_error_; }

  // Bakes SCENE (in the scene folder) into NAME.vtpf with FLAGS; validates it against lit.gltf.
  static RunResult bake_and_check(const std::string& scene, const std::string& name,
                                  const std::string& flags = "") {
    const std::string out = dir_ + "/" + name + ".vtpf";
    const RunResult b = run_vtbake(
        "-q bake " + dir_ + "/scene/" + scene + " -o " + out + " --size 4 --supersample 1 " + flags,
        true);
    EXPECT_EQ(b.exit_code, 0) << b.out;
    return run_vtbake("--json validate " + dir_ + "/scene/lit.gltf " + out +
                          " --atlas-only --out " + dir_ + "/" + name + ".validate",
                      false);
  }
  // Validates NAME.vtpf (made by bake_and_check) against lit.gltf through two rendered views: the
  // screen-space check of the lighting layer runs beside the views' own checks.
  static RunResult views_check(const std::string& name) {
    return run_vtbake("--json validate " + dir_ + "/scene/lit.gltf " + dir_ + "/" + name +
                          ".vtpf --views 2 --size 320x180 --out " + dir_ + "/" + name + ".views",
                      false);
  }
  static bool no_vulkan(const RunResult& r) {
    return r.exit_code == 2 &&
           (r.out.find("Vulkan") != std::string::npos || r.out.find("vulkan") != std::string::npos);
  }
  // Every view's "lighting" object; empty when the output is not a report.
  static std::vector<nlohmann::json> lighting_views(const RunResult& r) {
    const auto j = nlohmann::json::parse(r.out, nullptr, false);
    std::vector<nlohmann::json> out;
    if (!j.is_object() || !j.contains("views")) return out;
    for (const auto& v : j["views"]) out.push_back(v.value("lighting", nlohmann::json()));
    return out;
  }
  // Whether some view failed the lighting check (its failures name it).
  static bool lighting_failed(const RunResult& r) {
    const auto j = nlohmann::json::parse(r.out, nullptr, false);
    if (!j.is_object()) return false;
    for (const auto& v : j["views"])
      for (const auto& why : v["failures"])
        if (why.get<std::string>().rfind("lighting: ", 0) == 0) return true;
    return false;
  }

  static nlohmann::json lighting_report(const RunResult& r, const std::string& name = "lighting") {
    const auto j = nlohmann::json::parse(r.out, nullptr, false);
    if (!j.is_object()) return {};
    for (const auto& layer : j["atlas"]["layers"])
      if (layer["name"] == name) return layer;
    return {};
  }

  static inline std::string dir_, setup_error_;
};

TEST_F(ValidateLighting, ACorrectLitBakePassesOnItsLightingLayer) {
  const RunResult r = bake_and_check("lit.gltf", "lit");
  EXPECT_EQ(r.exit_code, 0) << r.out;
  const nlohmann::json l = lighting_report(r);
  ASSERT_TRUE(l.is_object()) << r.out;
  EXPECT_EQ(l["passed"], true);
  EXPECT_GT(l["pages_checked"].get<int>(), 0);
  EXPECT_EQ(l["pages_failed"], 0);
  // The unwrapped scene keeps the lights (a viewer or a re-bake of it sees them).
  const std::string glb = read_file(dir_ + "/lit.glb");
  EXPECT_NE(glb.find("KHR_lights_punctual"), std::string::npos);
}

TEST_F(ValidateLighting, AoBakeIsCheckedWithItsOwnSamples) {
  const RunResult r = bake_and_check("lit.gltf", "ao", "--ao-samples 8");
  EXPECT_EQ(r.exit_code, 0) << r.out;
  const nlohmann::json l = lighting_report(r);
  ASSERT_TRUE(l.is_object()) << r.out;
  EXPECT_EQ(l["pages_failed"], 0);
}

TEST_F(ValidateLighting, AMovedLightFails) {
  const RunResult r = bake_and_check("moved.gltf", "moved");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  const nlohmann::json l = lighting_report(r);
  ASSERT_TRUE(l.is_object()) << r.out;
  EXPECT_EQ(l["passed"], false);
  EXPECT_GT(l["pages_failed"].get<int>(), 0);
}

TEST_F(ValidateLighting, ShadowsOffFails) {
  const RunResult r = bake_and_check("lit.gltf", "noshadow", "--no-shadows");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  const nlohmann::json l = lighting_report(r);
  ASSERT_TRUE(l.is_object()) << r.out;
  EXPECT_GT(l["pages_failed"].get<int>(), 0);
}

// The screen-space check (views rendered through the virtual-texture path against a per-pixel
// reference from the original scene). Runs after the atlas tests above, reusing their bakes.
TEST_F(ValidateLighting, ViewsOfACorrectLitBakePassTheLightingCheck) {
  bake_and_check("lit.gltf", "lit_views");
  const RunResult r = views_check("lit_views");
  if (no_vulkan(r)) GTEST_SKIP() << "no Vulkan device: " << r.out;
  EXPECT_FALSE(lighting_failed(r)) << r.out;
  const std::vector<nlohmann::json> views = lighting_views(r);
  ASSERT_EQ(views.size(), 2u) << r.out;
  for (const nlohmann::json& l : views) {
    ASSERT_TRUE(l.is_object()) << r.out;
    EXPECT_GT(l["pixels_compared"].get<int>(), 1000);
    EXPECT_GE(l["psnr_rgb"].get<double>(), 30.0);
  }
}

TEST_F(ValidateLighting, ViewsOfAMovedLightFailTheLightingCheck) {
  bake_and_check("moved.gltf", "moved_views");
  const RunResult r = views_check("moved_views");
  if (no_vulkan(r)) GTEST_SKIP() << "no Vulkan device: " << r.out;
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(lighting_failed(r)) << r.out;
}

TEST_F(ValidateLighting, ViewsOfAShadowlessBakeFailTheLightingCheck) {
  bake_and_check("lit.gltf", "noshadow_views", "--no-shadows");
  const RunResult r = views_check("noshadow_views");
  if (no_vulkan(r)) GTEST_SKIP() << "no Vulkan device: " << r.out;
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(lighting_failed(r)) << r.out;
}

// --bounces 1: the metadata records it, the atlas check repeats it (same rays: every page as
// baked) and the views' reference gathers the bounce too.
TEST_F(ValidateLighting, ABouncedBakeValidates) {
  const RunResult atlas = bake_and_check("lit.gltf", "bounce", "--bounces 1 --bounce-samples 8");
  EXPECT_EQ(atlas.exit_code, 0) << atlas.out;
  const nlohmann::json l = lighting_report(atlas);
  ASSERT_TRUE(l.is_object()) << atlas.out;
  EXPECT_EQ(l["pages_failed"], 0);
  const RunResult r = views_check("bounce");
  if (no_vulkan(r)) GTEST_SKIP() << "no Vulkan device: " << r.out;
  EXPECT_FALSE(lighting_failed(r)) << r.out;
  EXPECT_EQ(lighting_views(r).size(), 2u) << r.out;
}

TEST_F(ValidateLighting, AViewsCheckWithoutALightingLayerHasNoLightingObject) {
  const std::string out = dir_ + "/unlit.vtpf";
  const RunResult b = run_vtbake(
      "-q bake " + dir_ + "/unlit/scene.gltf -o " + out + " --size 4 --supersample 1", true);
  ASSERT_EQ(b.exit_code, 0) << b.out;
  const RunResult r = run_vtbake("--json validate " + dir_ + "/unlit/scene.gltf " + out +
                                     " --views 1 --size 160x90 --out " + dir_ + "/unlit.views",
                                 false);
  if (no_vulkan(r)) GTEST_SKIP() << "no Vulkan device: " << r.out;
  for (const nlohmann::json& l : lighting_views(r)) EXPECT_TRUE(l.is_null()) << r.out;
}

// --lighting combined: the lit-albedo layer is judged against base colour x irradiance / pi
// recomputed from the original scene (atlas pages and views); a light moved or a base colour
// changed fails on it.
TEST_F(ValidateLighting, ACombinedBakePassesAndItsWrongVariantsFail) {
  const RunResult ok = bake_and_check("lit.gltf", "combined", "--lighting combined");
  EXPECT_EQ(ok.exit_code, 0) << ok.out;
  const nlohmann::json l = lighting_report(ok, "lit_albedo");
  ASSERT_TRUE(l.is_object()) << ok.out;
  EXPECT_EQ(l["passed"], true);
  EXPECT_GT(l["pages_checked"].get<int>(), 0);
  EXPECT_TRUE(lighting_report(ok).is_null()) << "a combined bake has no lighting layer";
  for (const char* scene : {"moved.gltf", "recoloured.gltf"}) {
    const std::string name = std::string("combined_") + scene;
    const RunResult bad =
        bake_and_check(scene, name.substr(0, name.size() - 5), "--lighting combined");
    EXPECT_EQ(bad.exit_code, 1) << bad.out;
    const nlohmann::json b = lighting_report(bad, "lit_albedo");
    ASSERT_TRUE(b.is_object()) << bad.out;
    EXPECT_EQ(b["passed"], false) << scene;
    EXPECT_GT(b["pages_failed"].get<int>(), 0) << scene;
  }
  const RunResult views = views_check("combined");
  if (no_vulkan(views)) GTEST_SKIP() << "no Vulkan device: " << views.out;
  EXPECT_FALSE(lighting_failed(views)) << views.out;
  EXPECT_EQ(lighting_views(views).size(), 2u) << views.out;
  for (const char* bad : {"combined_moved", "combined_recoloured"}) {
    const RunResult r = views_check(bad);
    EXPECT_EQ(r.exit_code, 1) << r.out;
    EXPECT_TRUE(lighting_failed(r)) << bad << ": " << r.out;
  }
}

}  // namespace
}  // namespace vt
