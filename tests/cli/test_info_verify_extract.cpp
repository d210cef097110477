// End-to-end: `vtbake info --json`, `verify` and `extract` on page files written by the library.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "common/srgb.h"
#include "format/page_file.h"
#include "tests/cli/cli_test_util.h"
#include "tests/format/page_file_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;

using vt::testing::RunResult;
RunResult run(const std::string& args) {
  return vt::testing::run_vtbake(args, false);
}

// A two-layer file with every page of every level cut from known level images; level 1 of
// the albedo layer has one absent and one constant page.
struct TestFile {
  PageFileDesc desc;
  std::vector<std::vector<uint8_t>> albedo, height;
  std::string path;
};

TestFile make_file() {
  TestFile t;
  t.desc.geometry = {45, 30, 12, 2};  // 4x3 -> 2x2 -> 1x1 pages
  t.desc.layers = {layer("albedo", 3, TexelType::kU8, PageCodec::kRawZstd),
                   layer("height", 1, TexelType::kF32, PageCodec::kRaw)};
  t.desc.layers[0].runtime_format = RuntimeFormat::kBc1;
  t.desc.layers[0].color_space = ColorSpace::kSrgb;
  t.desc.layers[1].semantic = LayerSemantic::kCustom;
  t.desc.metadata_json = R"({"tool":"test","settings":{"quality":75}})";
  const PageGeometry& g = t.desc.geometry;
  t.albedo = random_levels(g, 3, 1);
  t.height = random_levels(g, 4, 2);
  // Finite floats only: the EXR round trip compares bits.
  for (auto& level : t.height)
    for (size_t i = 3; i < level.size(); i += 4) level[i] &= 0x3F;
  t.path = temp_path("cli.vtpf");
  auto w = PageFileWriter::create(t.path, t.desc);
  EXPECT_TRUE(w.ok());
  for (uint32_t l = 0; l < g.level_count(); ++l)
    for (uint32_t y = 0; y < g.pages_y(l); ++y)
      for (uint32_t x = 0; x < g.pages_x(l); ++x) {
        const PageId id{l, x, y};
        if (l == 1 && x == 0 && y == 1) {
          const uint8_t grey[3] = {9, 8, 7};
          EXPECT_TRUE((*w)->add_constant_page(id, 0, grey).ok());
        } else if (!(l == 1 && x == 1 && y == 1)) {  // (1, 1, 1) stays absent
          auto a = cut_page(t.albedo[l], g.level_width(l), g.level_height(l), 3, g, id);
          std::vector<uint8_t> z;
          EXPECT_TRUE(zstd_compress(a, 1, z).ok());
          EXPECT_TRUE((*w)->add_page(id, 0, z).ok());
        }
        auto h = cut_page(t.height[l], g.level_width(l), g.level_height(l), 4, g, id);
        EXPECT_TRUE((*w)->add_page(id, 1, h).ok());
      }
  EXPECT_TRUE((*w)->finish().ok());
  return t;
}

TEST(CliInfo, JsonDescribesTheFile) {
  TestFile t = make_file();
  RunResult r = run("info --json " + t.path);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["payload"], 12);
  EXPECT_EQ(j["border"], 2);
  EXPECT_EQ(j["width"], 45);
  EXPECT_EQ(j["height"], 30);
  EXPECT_EQ(j["version"], 1);
  ASSERT_EQ(j["layers"].size(), 2u);
  EXPECT_EQ(j["layers"][0]["semantic"], "albedo");
  EXPECT_EQ(j["layers"][0]["name"], "albedo");
  EXPECT_EQ(j["layers"][0]["channels"], 3);
  EXPECT_EQ(j["layers"][0]["codec"], "raw+zstd");
  EXPECT_EQ(j["layers"][0]["runtime_format"], "bc1");
  EXPECT_EQ(j["layers"][0]["color_space"], "srgb");
  EXPECT_EQ(j["layers"][1]["texel_type"], "f32");
  EXPECT_EQ(j["layers"][1]["codec"], "raw");
  ASSERT_EQ(j["levels"].size(), 3u);
  EXPECT_EQ(j["levels"][0]["pages_x"], 4);
  EXPECT_EQ(j["levels"][0]["pages_y"], 3);
  EXPECT_EQ(j["levels"][0]["stored"], 24);  // 12 pages x 2 layers
  EXPECT_EQ(j["levels"][1]["stored"], 6);   // 4 height + 2 albedo
  EXPECT_EQ(j["levels"][1]["constant"], 1);
  EXPECT_EQ(j["levels"][1]["absent"], 1);
  EXPECT_EQ(j["levels"][1]["bytes"].get<uint64_t>() > 3 * 16 * 16 * 4, true);
  EXPECT_EQ(j["metadata"]["settings"]["quality"], 75);
  uint64_t bytes = 0;
  for (auto& level : j["levels"]) bytes += level["bytes"].get<uint64_t>();
  EXPECT_EQ(j["bytes"]["stored"].get<uint64_t>(), bytes);
  EXPECT_EQ(j["bytes"]["file"].get<uint64_t>(), std::filesystem::file_size(t.path));
  EXPECT_EQ(j["pages"]["total"].get<uint64_t>(), j["pages"]["stored"].get<uint64_t>() +
                                                     j["pages"]["constant"].get<uint64_t>() +
                                                     j["pages"]["absent"].get<uint64_t>());

  RunResult text = run("info " + t.path);
  EXPECT_EQ(text.exit_code, 0);
  EXPECT_NE(text.out.find("compression ratio"), std::string::npos);
  EXPECT_EQ(run("info " + t.path + ".missing").exit_code, 2);
}

TEST(CliVerify, ExitStatusSaysTheResult) {
  TestFile t = make_file();
  RunResult ok = run("verify " + t.path);
  EXPECT_EQ(ok.exit_code, 0) << ok.out;
  RunResult json = run("--json verify " + t.path);
  ASSERT_EQ(json.exit_code, 0);
  auto j = nlohmann::json::parse(json.out);
  EXPECT_EQ(j["ok"], true);
  EXPECT_EQ(j["pages"]["checked"], 24 + 6 + 2);
  EXPECT_EQ(j["pages"]["bad"], 0);

  // One flipped data byte: a bad page, exit 1, and the page is named.
  std::vector<uint8_t> bytes = read_bytes(t.path);
  bytes[le64(bytes, 64) + 5] ^= 0x40;
  const std::string bad = temp_path("bad.vtpf");
  write_bytes(bad, bytes);
  RunResult r = run("verify --json " + bad);
  EXPECT_EQ(r.exit_code, 1) << r.out;
  auto jb = nlohmann::json::parse(r.out);
  EXPECT_EQ(jb["ok"], false);
  ASSERT_EQ(jb["bad_pages"].size(), 1u);
  EXPECT_EQ(jb["bad_pages"][0]["level"], 2);  // the coarsest level's pages come first

  // Not a page file at all: exit 2.
  write_bytes(bad, {'n', 'o', 'p', 'e'});
  EXPECT_EQ(run("verify " + bad).exit_code, 2);
  bytes = read_bytes(t.path);
  bytes[20] ^= 1;  // header bit: the file cannot be trusted at all
  write_bytes(bad, bytes);
  EXPECT_EQ(run("verify " + bad).exit_code, 2);
}

TEST(CliExtract, RoundTripsEveryLevelExactly) {
  TestFile t = make_file();
  const PageGeometry& g = t.desc.geometry;
  for (uint32_t l = 0; l < g.level_count(); ++l) {
    if (l == 1) continue;  // level 1 has an absent and a constant page, checked below
    const std::string png = temp_path("level.png");
    RunResult r = run("extract " + t.path + " --level " + std::to_string(l) + " -o " + png);
    ASSERT_EQ(r.exit_code, 0) << r.out;
    auto in = OIIO::ImageInput::open(png);
    ASSERT_TRUE(in);
    const OIIO::ImageSpec& spec = in->spec();
    ASSERT_EQ(uint32_t(spec.width), g.level_width(l));
    ASSERT_EQ(uint32_t(spec.height), g.level_height(l));
    ASSERT_EQ(spec.nchannels, 3);
    std::vector<uint8_t> pixels(t.albedo[l].size());
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, pixels.data()));
    EXPECT_EQ(pixels, t.albedo[l]) << "level " << l;

    const std::string exr = temp_path("level.exr");
    r = run("extract " + t.path + " --level " + std::to_string(l) + " --layer 1 -o " + exr);
    ASSERT_EQ(r.exit_code, 0) << r.out;
    auto fin = OIIO::ImageInput::open(exr);
    ASSERT_TRUE(fin);
    ASSERT_EQ(fin->spec().format, OIIO::TypeDesc::FLOAT);
    std::vector<uint8_t> floats(t.height[l].size());
    ASSERT_TRUE(fin->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, floats.data()));
    EXPECT_EQ(floats, t.height[l]) << "level " << l;
  }

  // Level 1: stored pages exact, the constant page its value, the absent page (1, 1) nearest-
  // upsampled from level 2.
  const std::string png = temp_path("level1.png");
  ASSERT_EQ(run("extract " + t.path + " --level 1 -o " + png).exit_code, 0);
  auto in = OIIO::ImageInput::open(png);
  ASSERT_TRUE(in);
  const uint32_t w = g.level_width(1), h = g.level_height(1), w2 = g.level_width(2);
  std::vector<uint8_t> pixels(size_t(w) * h * 3);
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, pixels.data()));
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x)
      for (uint32_t c = 0; c < 3; ++c) {
        const uint32_t px = x / 12, py = y / 12;
        uint8_t expected = t.albedo[1][(size_t(y) * w + x) * 3 + c];
        if (px == 0 && py == 1) expected = uint8_t(9 - c);
        if (px == 1 && py == 1) expected = t.albedo[2][(size_t(y / 2) * w2 + x / 2) * 3 + c];
        ASSERT_EQ(pixels[(size_t(y) * w + x) * 3 + c], expected) << x << "," << y << "," << c;
      }

  EXPECT_EQ(run("extract " + t.path + " --level 9 -o " + png).exit_code, 2);
  EXPECT_EQ(run("extract " + t.path + " --level 0 --layer 5 -o " + png).exit_code, 2);
  EXPECT_EQ(run("extract " + t.path + ".missing --level 0 -o " + png).exit_code, 2);
  EXPECT_EQ(run("extract " + t.path + " -o " + png).exit_code, 2);  // --level is required
}

// A one-layer file at `path` whose level 0 pages are cut from `level` (texel_bytes each).
void write_level0(const std::string& path, const PageFileDesc& desc,
                  const std::vector<uint8_t>& level, uint32_t texel_bytes) {
  const PageGeometry& g = desc.geometry;
  auto w = PageFileWriter::create(path, desc);
  ASSERT_TRUE(w.ok());
  for (uint32_t y = 0; y < g.pages_y(0); ++y)
    for (uint32_t x = 0; x < g.pages_x(0); ++x) {
      auto p = cut_page(level, g.level_width(0), g.level_height(0), texel_bytes, g, {0, x, y});
      std::vector<uint8_t> z;
      ASSERT_TRUE(zstd_compress(p, 1, z).ok());
      ASSERT_TRUE((*w)->add_page({0, x, y}, 0, z).ok());
    }
  ASSERT_TRUE((*w)->finish().ok());
}

// OpenEXR stores colour premultiplied by alpha: an RGBA colour layer goes in multiplied (and
// vtbake's reader divides it out again); alpha as stored.
TEST(CliExtract, AlphaColourLayerToExrIsPremultiplied) {
  PageFileDesc desc;
  desc.geometry = {20, 12, 8, 2};
  desc.layers = {layer("albedo", 4, TexelType::kU8, PageCodec::kRawZstd)};
  const PageGeometry& g = desc.geometry;
  auto levels = random_levels(g, 4, 11);
  const std::string path = temp_path("rgba.vtpf");
  write_level0(path, desc, levels[0], 4);
  const std::string exr = temp_path("rgba.exr");
  ASSERT_EQ(run("-q extract " + path + " --level 0 -o " + exr).exit_code, 0);
  auto in = OIIO::ImageInput::open(exr);
  ASSERT_TRUE(in);
  ASSERT_EQ(in->spec().nchannels, 4);
  std::vector<float> f(levels[0].size());
  ASSERT_TRUE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, f.data()));
  for (size_t i = 0; i < f.size(); i += 4) {
    const float a = levels[0][i + 3] / 255.0f;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[i + c], levels[0][i + c] / 255.0f * a, 1e-3f) << i;
    EXPECT_NEAR(f[i + 3], a, 1e-3f) << i;
  }
}

// OpenEXR holds linear light: an sRGB layer's colour goes in decoded (then premultiplied), so
// that readers (vtbake's build among them) take it as the colour it is. Other formats get the
// stored values, tagged sRGB.
TEST(CliExtract, SrgbColourLayerToExrIsLinearLight) {
  PageFileDesc desc;
  desc.geometry = {20, 12, 8, 2};
  desc.layers = {layer("albedo", 4, TexelType::kU8, PageCodec::kRawZstd)};
  desc.layers[0].color_space = ColorSpace::kSrgb;
  auto levels = random_levels(desc.geometry, 4, 13);
  const std::string path = temp_path("srgb.vtpf");
  write_level0(path, desc, levels[0], 4);
  const std::string exr = temp_path("srgb.exr"), tif = temp_path("srgb.tif");
  ASSERT_EQ(run("-q extract " + path + " --level 0 -o " + exr).exit_code, 0);
  ASSERT_EQ(run("-q extract " + path + " --level 0 -o " + tif).exit_code, 0);
  auto in = OIIO::ImageInput::open(exr);
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().get_string_attribute("oiio:ColorSpace"), "Linear");
  std::vector<float> f(levels[0].size());
  ASSERT_TRUE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, f.data()));
  for (size_t i = 0; i < f.size(); i += 4) {
    const float a = levels[0][i + 3] / 255.0f;
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(f[i + c], srgb_to_linear(levels[0][i + c] / 255.0f) * a, 1e-3f) << i;
    EXPECT_NEAR(f[i + 3], a, 1e-3f) << i;
  }
  OIIO::ImageSpec straight;
  straight.attribute("oiio:UnassociatedAlpha", 1);
  auto tin = OIIO::ImageInput::open(tif, &straight);
  ASSERT_TRUE(tin);
  EXPECT_EQ(tin->spec().get_string_attribute("oiio:ColorSpace"), "sRGB");
  std::vector<uint8_t> stored(levels[0].size());
  ASSERT_TRUE(tin->read_image(0, 0, 0, 4, OIIO::TypeDesc::UINT8, stored.data()));
  EXPECT_EQ(stored, levels[0]);
}

TEST(CliExtract, HalfFloatLayerToExrIsExact) {
  PageFileDesc desc;
  desc.geometry = {20, 12, 8, 2};
  desc.layers = {layer("emissive", 3, TexelType::kF16, PageCodec::kRawZstd)};
  const PageGeometry& g = desc.geometry;
  auto levels = random_levels(g, 6, 9);
  for (auto& level : levels)
    for (size_t i = 1; i < level.size(); i += 2) level[i] &= 0xBB;  // finite halves only
  const std::string path = temp_path("half.vtpf");
  write_level0(path, desc, levels[0], 6);
  const std::string exr = temp_path("half.exr");
  ASSERT_EQ(run("-q extract " + path + " --level 0 -o " + exr).exit_code, 0);
  auto in = OIIO::ImageInput::open(exr);
  ASSERT_TRUE(in);
  ASSERT_EQ(in->spec().format, OIIO::TypeDesc::HALF);
  ASSERT_EQ(in->spec().nchannels, 3);
  std::vector<uint8_t> halves(levels[0].size());
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::HALF, halves.data()));
  EXPECT_EQ(halves, levels[0]);
}

// A 4-channel layer's last channel is alpha only in colour layers: lit albedo's is (an RGBA
// radiance), lighting with ambient occlusion's is not (irradiance + AO).
TEST(CliExtract, ExrNamesAlphaOnlyInColourLayers) {
  for (const LayerSemantic semantic : {LayerSemantic::kLitAlbedo, LayerSemantic::kLighting}) {
    PageFileDesc desc;
    desc.geometry = {20, 12, 8, 2};
    desc.layers = {layer(to_string(semantic), 4, TexelType::kF16, PageCodec::kRawZstd)};
    desc.layers[0].semantic = semantic;
    const PageGeometry& g = desc.geometry;
    const std::string path = temp_path("light.vtpf");
    {
      auto w = PageFileWriter::create(path, desc);
      ASSERT_TRUE(w.ok());
      ASSERT_TRUE((*w)->finish().ok());
    }
    const std::string exr = temp_path("light.exr");
    ASSERT_EQ(run("-q extract " + path + " --level 0 -o " + exr).exit_code, 0);
    auto in = OIIO::ImageInput::open(exr);
    ASSERT_TRUE(in);
    ASSERT_EQ(uint32_t(in->spec().width), g.level_width(0));
    ASSERT_EQ(in->spec().nchannels, 4);
    const bool colour = semantic == LayerSemantic::kLitAlbedo;
    EXPECT_EQ(in->spec().alpha_channel, colour ? 3 : -1) << to_string(semantic);
    EXPECT_EQ(in->spec().channelnames[3], colour ? "A" : "W") << to_string(semantic);
  }
}

}  // namespace
}  // namespace vt
