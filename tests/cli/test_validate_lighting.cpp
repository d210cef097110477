// End-to-end: the atlas check of a baked lighting layer (issue 21). The reference is lit by the
// original scene's lights where the original places them, with shadows always and the bake's
// AO settings; lux are compared after the tone map x / (1 + x). A correct lit bake passes; a
// bake whose light moved, or that skipped shadows, fails on its lighting layer.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/cli/cli_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;

class ValidateLighting : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fresh_test_dir("validate_lighting");
    setup_error_ = write_sample_scene(dir_ + "/scene");
    if (!setup_error_.empty()) return;
    // The sample scene with a sun, a bulb and a spot, as Blender writes them.
    nlohmann::json doc = nlohmann::json::parse(read_file(dir_ + "/scene/scene.gltf"));
    doc["extensionsUsed"].push_back("KHR_lights_punctual");
    doc["extensionsRequired"] = {"KHR_lights_punctual"};
    doc["extensions"]["KHR_lights_punctual"]["lights"] = {
        {{"type", "directional"}, {"intensity", 3.0}, {"color", {1.0, 0.9, 0.8}}},
        {{"type", "point"}, {"intensity", 40.0}, {"range", 20.0}},
        {{"type", "spot"},
         {"intensity", 80.0},
         {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.6}}}}};
    const int first = int(doc["nodes"].size());
    doc["nodes"].push_back({{"name", "sun"},
                            {"rotation", {-0.5, 0.1, 0.1, 0.85}},
                            {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    doc["nodes"].push_back({{"name", "bulb"},
                            {"translation", {1.0, 3.0, 1.0}},
                            {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
    doc["nodes"].push_back({{"name", "spot"},
                            {"translation", {-2.0, 4.0, 0.0}},
                            {"rotation", {-0.7071, 0.0, 0.0, 0.7071}},
                            {"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}});
    for (int n = first; n < first + 3; ++n) doc["scenes"][0]["nodes"].push_back(n);
    std::ofstream(dir_ + "/scene/lit.gltf") << doc.dump();
    doc["nodes"][first + 1]["translation"] = {3.0, 2.0, -2.0};
    std::ofstream(dir_ + "/scene/moved.gltf") << doc.dump();
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
  static nlohmann::json lighting_report(const RunResult& r) {
    const auto j = nlohmann::json::parse(r.out, nullptr, false);
    if (!j.is_object()) return {};
    for (const auto& layer : j["atlas"]["layers"])
      if (layer["name"] == "lighting") return layer;
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

}  // namespace
}  // namespace vt
