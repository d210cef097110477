// The --json reports (docs/JSON.md): `vtbake build --json` and `vtbake bake --json` carry one
// schema for the build, the scene bake nesting it under "build".
#include <gtest/gtest.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "tests/cli/cli_test_util.h"

namespace vt {
namespace {

using vt::testing::run_vtbake;
using vt::testing::write_sample_scene;

std::set<std::string> keys(const nlohmann::json& j) {
  std::set<std::string> k;
  for (auto it = j.begin(); it != j.end(); ++it) k.insert(it.key());
  return k;
}

class Reports : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (std::filesystem::temp_directory_path() / ("vt_reports_" + std::to_string(::getpid())))
               .string();
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string dir_;
};

TEST_F(Reports, BuildJsonIsTheNestedSchema) {
  auto r = run_vtbake("--json build procedural:300x200 --codec raw -o " + dir_ + "/b.vtpf", false);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(keys(j), (std::set<std::string>{"output", "width", "height", "payload", "border",
                                            "pages", "bytes", "levels", "layers", "seconds",
                                            "schema", "command", "ok", "exit"}));
  EXPECT_GE(j["seconds"]["total"].get<double>(), 0.0);
  EXPECT_EQ(j["output"], dir_ + "/b.vtpf");
  EXPECT_EQ(j["width"], 300);
  const auto& p = j["pages"];
  EXPECT_EQ(
      p["total"].get<uint64_t>(),
      p["stored"].get<uint64_t>() + p["constant"].get<uint64_t>() + p["absent"].get<uint64_t>());
  EXPECT_EQ(j["bytes"]["file"].get<uint64_t>(), std::filesystem::file_size(dir_ + "/b.vtpf"));
  EXPECT_EQ(j["bytes"]["raw"], (300 * 200 + 150 * 100 + 75 * 50) * 3);  // 3 levels of RGB8
  EXPECT_TRUE(j["layers"][0]["psnr_db"].is_null());                     // raw is lossless
  EXPECT_GT(j["seconds"].size(), 0u);
}

// An HDR EXR in the default (8-bit DCT) layer: one warning naming the file, the JSON's clipped
// counts, a PSNR that counts the clipping; --float-texels half keeps the values.
TEST_F(Reports, ClippedHdrIsWarnedAboutAndHalfKeepsIt) {
  const std::string exr = dir_ + "/hdr.exr";
  {
    std::vector<float> t(64 * 48 * 3, 0.25f);
    for (int x = 0; x < 10; ++x) t[size_t(20 * 64 + x) * 3] = 8.0f;  // ten texels, red at 8
    auto out = OIIO::ImageOutput::create(exr);
    ASSERT_TRUE(out);
    ASSERT_TRUE(out->open(exr, OIIO::ImageSpec(64, 48, 3, OIIO::TypeDesc::HALF)));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, t.data()));
    ASSERT_TRUE(out->close());
  }
  auto r = run_vtbake("build " + exr + " --payload 24 -o " + dir_ + "/h.vtpf", true);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("warning: " + exr +
                       ": layer 'albedo': 10 texels (10 values) outside [0, 1], "
                       "up to 8, clipped by its 8-bit dct storage"),
            std::string::npos)
      << r.out;
  r = run_vtbake("--json build " + exr + " --payload 24 -o " + dir_ + "/h.vtpf", false);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["warnings"].size(), 1u);
  EXPECT_EQ(j["layers"][0]["clipped"]["texels"], 10);
  EXPECT_EQ(j["layers"][0]["clipped"]["max"], 8.0);
  EXPECT_LT(j["layers"][0]["psnr_db"].get<double>(), 40.0);  // sRGB(8) is code 626, not 255

  r = run_vtbake("--json build " + exr + " --payload 24 --float-texels half -o " + dir_ + "/f.vtpf",
                 false);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  j = nlohmann::json::parse(r.out);
  EXPECT_FALSE(j.contains("warnings"));
  EXPECT_EQ(j["layers"][0]["texel_type"], "f16");
  EXPECT_EQ(j["layers"][0]["runtime_format"], "bc6h_uf16");  // RGB half
  // The HDR error after BC6H (codec/hdr_metrics.h), beside the 8-bit figures' absence.
  ASSERT_TRUE(j["layers"][0]["runtime"].contains("hdr")) << j.dump();
  EXPECT_GT(j["layers"][0]["runtime"]["hdr"]["tonemapped_psnr_db"].get<double>(), 30.0);
  EXPECT_LT(j["layers"][0]["runtime"]["hdr"]["log2_error_mean"].get<double>(), 0.1);
  EXPECT_EQ(j["layers"][0]["clipped"]["texels"], 0);
  // Raw halves: the rounding to half, measured against the float source (not "lossless").
  ASSERT_TRUE(j["layers"][0].contains("hdr")) << j.dump();
  EXPECT_LE(j["layers"][0]["hdr"]["relative_error_max"].get<double>(), 0x1p-11);
  r = run_vtbake("build " + exr + " --payload 24 --float-texels half -o " + dir_ + "/f.vtpf", true);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_EQ(r.out.find("lossless"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("raw+zstd -> bc6h_uf16, stored "), std::string::npos) << r.out;
  EXPECT_EQ(
      run_vtbake("build " + exr + " --float-texels bc6h -o " + dir_ + "/g.vtpf", false).exit_code,
      2);
  // --half-runtime rgba16f keeps the halves as they are at run time: no HDR error to report.
  r = run_vtbake("--json build " + exr +
                     " --payload 24 --float-texels half --half-runtime rgba16f "
                     "-o " +
                     dir_ + "/r.vtpf",
                 false);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["layers"][0]["runtime_format"], "rgba16f");
  EXPECT_FALSE(j["layers"][0].contains("runtime"));
  // --codec bc stores BC6H blocks: the text summary gives the stored HDR error.
  r = run_vtbake(
      "build " + exr + " --payload 24 --float-texels half --codec bc -o " + dir_ + "/b.vtpf", true);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("bc+zstd -> bc6h_uf16, stored log2 error mean"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("tone-mapped PSNR"), std::string::npos) << r.out;
  EXPECT_EQ(
      run_vtbake("build " + exr + " --float-texels half --half-runtime bc7 -o " + dir_ + "/x.vtpf",
                 false)
          .exit_code,
      2);
}

TEST_F(Reports, SceneBakeNestsTheBuildSchema) {
  ASSERT_EQ(write_sample_scene(dir_ + "/scene"), "");
  auto r = run_vtbake("--json bake " + dir_ + "/scene/scene.gltf -o " + dir_ +
                          "/s.vtpf --size 2 --payload 56 --unwrapped -",
                      false);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(keys(j), (std::set<std::string>{"output", "unwrapped", "triangles", "atlas", "transfer",
                                            "build", "seconds", "peak_rss_bytes", "warnings",
                                            "input", "schema", "command", "ok", "exit"}));
  EXPECT_EQ(j["unwrapped"], "");
  // --size 2 holds the sample scene under its sources' density, and the bake says so.
  ASSERT_EQ(j["warnings"].size(), 1u) << j["warnings"];
  EXPECT_NE(j["warnings"][0].get<std::string>().find("coarser than its sources"),
            std::string::npos);
  EXPECT_EQ(j["transfer"]["above_one"], nlohmann::json::array());
  EXPECT_EQ(j["transfer"]["missing_textures"], nlohmann::json::array());
  EXPECT_EQ(keys(j["build"]),
            (std::set<std::string>{"width", "height", "payload", "border", "pages", "bytes",
                                   "levels", "layers", "seconds"}));
  EXPECT_EQ(j["build"]["payload"], 56);  // the shared build flags reach the scene bake
  EXPECT_EQ(j["build"]["width"], j["atlas"]["width"]);
  EXPECT_EQ(j["build"]["bytes"]["file"].get<uint64_t>(),
            std::filesystem::file_size(dir_ + "/s.vtpf"));
  EXPECT_EQ(keys(j["build"]["layers"][0]),
            keys(nlohmann::json::parse(
                run_vtbake("--json build procedural:64x64 -o " + dir_ + "/c.vtpf", false)
                    .out)["layers"][0]));
  for (const char* stage : {"load", "unwrap", "transfer", "build"}) {
    EXPECT_TRUE(j["seconds"].contains(stage)) << stage;
  }
}

}  // namespace
}  // namespace vt
