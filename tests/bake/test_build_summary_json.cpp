// The one JSON form of a build summary (bake/build_summary_json.h, docs/JSON.md) and the
// numbers it derives: raw texel bytes and the compression ratio.
#include <gtest/gtest.h>

#include <limits>
#include <nlohmann/json.hpp>

#include "bake/build_summary_json.h"

namespace vt {
namespace {

// 45 x 30 texels in 12-texel pages: levels of 45x30, 23x15 and 12x8 texels (4x3, 2x2, 1x1 pages).
BuildSummary two_layer_summary() {
  BuildSummary s;
  s.geometry = {45, 30, 12, 2};
  s.levels.resize(3);
  s.levels[1] = {23, 15, 2, 2, 5, 2, 1, 900, true};
  LayerSummary albedo;
  albedo.name = "albedo";
  albedo.spec.channels = 3;
  albedo.spec.codec = PageCodec::kDct;
  albedo.psnr_db = 41.5;
  albedo.max_error = 9;
  albedo.alpha_dropped = true;
  LayerSummary emissive;
  emissive.name = "emissive";
  emissive.spec.semantic = LayerSemantic::kEmissive;
  emissive.spec.channels = 4;
  emissive.spec.texel_type = TexelType::kF16;
  emissive.psnr_db = std::numeric_limits<double>::infinity();  // lossless
  emissive.non_finite.non_finite = 2;
  emissive.non_finite.first_x = 7;
  emissive.non_finite.first_y = 3;
  emissive.non_finite.first_channel = 1;
  s.layers = {albedo, emissive};
  s.pages = 36, s.stored = 30, s.constant = 4, s.absent = 2;
  s.stored_bytes = 5000, s.file_bytes = 6000, s.scratch_bytes = 77, s.level_memory_bytes = 88;
  s.stages = {{"pyramid+encode", 1.5}, {"finish", 0.25}};
  return s;
}

TEST(BuildSummaryJson, RawBytesCountEveryLevelOfEveryLayerWithoutBorders) {
  const BuildSummary s = two_layer_summary();
  const uint64_t texels = 45 * 30 + 23 * 15 + 12 * 8;
  EXPECT_EQ(raw_texel_bytes(s), texels * 3 + texels * 8);
  EXPECT_DOUBLE_EQ(compression_ratio(s), double(texels * 11) / 6000.0);
  BuildSummary unwritten = s;
  unwritten.file_bytes = 0;
  EXPECT_EQ(compression_ratio(unwritten), 0.0);
}

TEST(BuildSummaryJson, NestedSchema) {
  const BuildSummary s = two_layer_summary();
  const nlohmann::json j = to_json(s);
  EXPECT_EQ(j["width"], 45);
  EXPECT_EQ(j["height"], 30);
  EXPECT_EQ(j["payload"], 12);
  EXPECT_EQ(j["border"], 2);
  EXPECT_EQ(j["pages"],
            nlohmann::json({{"total", 36}, {"stored", 30}, {"constant", 4}, {"absent", 2}}));
  EXPECT_EQ(j["bytes"]["file"], 6000);
  EXPECT_EQ(j["bytes"]["stored"], 5000);
  EXPECT_EQ(j["bytes"]["raw"], raw_texel_bytes(s));
  EXPECT_DOUBLE_EQ(j["bytes"]["ratio"].get<double>(), compression_ratio(s));
  EXPECT_EQ(j["bytes"]["scratch_peak"], 77);
  EXPECT_EQ(j["bytes"]["level_memory_peak"], 88);
  ASSERT_EQ(j["levels"].size(), 3u);
  EXPECT_EQ(j["levels"][1], nlohmann::json({{"level", 1},
                                            {"width", 23},
                                            {"height", 15},
                                            {"pages_x", 2},
                                            {"pages_y", 2},
                                            {"stored", 5},
                                            {"constant", 2},
                                            {"absent", 1},
                                            {"bytes", 900},
                                            {"scratch", true}}));
  ASSERT_EQ(j["layers"].size(), 2u);
  const nlohmann::json& a = j["layers"][0];
  EXPECT_EQ(a["name"], "albedo");
  EXPECT_EQ(a["semantic"], "albedo");
  EXPECT_EQ(a["channels"], 3);
  EXPECT_EQ(a["codec"], "dct");
  EXPECT_EQ(a["psnr_db"], 41.5);
  EXPECT_EQ(a["max_error"], 9);
  EXPECT_EQ(a["alpha_dropped"], true);
  EXPECT_FALSE(a.contains("first_bad_texel"));
  const nlohmann::json& e = j["layers"][1];
  EXPECT_EQ(e["texel_type"], "f16");
  EXPECT_TRUE(e["psnr_db"].is_null());  // JSON has no infinity
  EXPECT_EQ(e["non_finite"], 2);
  EXPECT_EQ(e["first_bad_texel"], nlohmann::json({{"x", 7}, {"y", 3}, {"channel", 1}}));
  EXPECT_EQ(j["seconds"], nlohmann::json({{"pyramid+encode", 1.5}, {"finish", 0.25}}));
  // Nothing else: the schema is exactly what docs/JSON.md lists.
  EXPECT_EQ(j.size(), 9u);
}

}  // namespace
}  // namespace vt
