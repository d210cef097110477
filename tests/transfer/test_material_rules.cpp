// The material rules of the transfer on small scenes the tests make: texture transforms, the
// nearest magnification filter, emissive strength and the report of values above 1, missing
// textures, vertex colours, UV sets, and which charts count as contesting a texel.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "bake/scene_bake.h"
#include "bake/transfer.h"
#include "bake/update_scene.h"
#include "common/srgb.h"
#include "format/page_file.h"
#include "tests/transfer/transfer_test_util.h"

namespace vt {
namespace {

constexpr uint32_t kAtlas = 64;

// A unit quad whose TEXCOORD_0 and atlas UVs (set 1) both span [0,1]^2: atlas texel (x, y)
// reads the source at ((x + 0.5) / 64, (y + 0.5) / 64).
scene::Primitive atlas_quad() {
  scene::Primitive p;
  p.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  p.normals.assign(4, {0, 0, 1});
  std::vector<scene::Vec2> uv = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  p.uvs = {uv, uv};
  p.indices = {0, 1, 2, 0, 2, 3};
  return p;
}

TransferOptions atlas_options() {
  TransferOptions o;
  o.width = o.height = kAtlas;
  o.threads = 2;
  return o;
}

// An 8-bit RGB image of w x h texels; returns its bytes.
std::vector<uint8_t> write_rgb(const std::string& path, int w, int h,
                               const std::function<void(int, int, uint8_t*)>& texel) {
  std::vector<uint8_t> bytes(size_t(w) * h * 3);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) texel(i, j, &bytes[(size_t(j) * w + i) * 3]);
  auto out = OIIO::ImageOutput::create(path);
  EXPECT_TRUE(out);
  OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::UINT8);
  EXPECT_TRUE(out->open(path, spec) && out->write_image(OIIO::TypeDesc::UINT8, bytes.data()) &&
              out->close());
  return bytes;
}

const TransferLayer* find(const TransferResult& r, LayerSemantic s) {
  for (const auto& l : r.layers)
    if (l.semantic == s) return &l;
  return nullptr;
}

// Bilinear lookup of an 8-bit image with periodic wrap, texel centres at (i + 0.5) / w.
float bilinear_repeat(const std::vector<uint8_t>& img, int w, int h, double u, double v, int c) {
  double x = u * w - 0.5, y = v * h - 0.5;
  double fx = std::floor(x), fy = std::floor(y), ax = x - fx, ay = y - fy;
  auto at = [&](int64_t i, int64_t j) {
    i = ((i % w) + w) % w, j = ((j % h) + h) % h;
    return img[(size_t(j) * w + size_t(i)) * 3 + c] / 255.0;
  };
  int64_t i = int64_t(fx), j = int64_t(fy);
  return float((at(i, j) * (1 - ax) + at(i + 1, j) * ax) * (1 - ay) +
               (at(i, j + 1) * (1 - ax) + at(i + 1, j + 1) * ax) * ay);
}

TEST(TransferRules, TextureTransformMovesTheLookup) {
  test::ScratchDir dir;
  const int w = 32, h = 32;
  auto img = write_rgb(dir.file("wave.png"), w, h, [](int i, int j, uint8_t* t) {
    t[0] = uint8_t(std::lround(128 + 100 * std::sin(2 * std::numbers::pi * (i + 0.5) / 32)));
    t[1] = uint8_t(std::lround(128 + 100 * std::cos(2 * std::numbers::pi * (j + 0.5) / 32)));
    t[2] = uint8_t(std::lround(128 + 80 * std::sin(2 * std::numbers::pi * (i + 2 * j + 1.0) / 32)));
  });
  scene::Scene s = test::textured_scene(atlas_quad(), dir.file("wave.png"));
  scene::TextureTransform& tf = s.materials[0].base_color_texture.transform;
  tf.offset = {0.25f, 0.1f};
  tf.rotation = 0.5f;
  tf.scale = {1.5f, 0.75f};
  auto r = transfer_materials(s, atlas_options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  const TransferLayer* albedo = find(*r, LayerSemantic::kAlbedo);
  ASSERT_NE(albedo, nullptr);
  ASSERT_EQ(albedo->channels, 3u);
  double err = 0, err_untransformed = 0, worst = 0;
  for (uint32_t y = 0; y < kAtlas; ++y) {
    for (uint32_t x = 0; x < kAtlas; ++x) {
      const double u = (x + 0.5) / kAtlas, v = (y + 0.5) / kAtlas;
      const auto t = tf.apply(u, v);
      for (int c = 0; c < 3; ++c) {
        const float got = albedo->texels[(size_t(y) * kAtlas + x) * 3 + c];
        const double d = got - srgb_to_linear(bilinear_repeat(img, w, h, t[0], t[1], c));
        err += std::abs(d), worst = std::max(worst, std::abs(d));
        err_untransformed += std::abs(got - srgb_to_linear(bilinear_repeat(img, w, h, u, v, c)));
      }
    }
  }
  const double n = 3.0 * kAtlas * kAtlas;
  EXPECT_LT(err / n, 0.002);
  EXPECT_LT(worst, 0.02);
  EXPECT_GT(err_untransformed / n, 0.05);  // the transform really moved the lookup
}

// A PNG's gAMA chunk (OpenImageIO reads "Gamma2.2") does not decide how a scene's colour texture
// decodes: glTF says such metadata MUST be ignored, and the slot makes it sRGB.
TEST(TransferRules, PngGammaTagDoesNotChangeASceneTexture) {
  test::ScratchDir dir;
  const std::string png = dir.file("tagged.png");
  const std::vector<uint8_t> texels(4 * 4 * 3, 30);
  {
    auto out = OIIO::ImageOutput::create(png);
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(4, 4, 3, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "Gamma2.2");
    spec.attribute("oiio:Gamma", 2.2f);
    ASSERT_TRUE(out->open(png, spec) && out->write_image(OIIO::TypeDesc::UINT8, texels.data()) &&
                out->close());
  }
  ASSERT_EQ(OIIO::ImageInput::open(png)->spec().get_string_attribute("oiio:ColorSpace"),
            "Gamma2.2");
  scene::Scene s = test::textured_scene(atlas_quad(), png);
  auto r = transfer_materials(s, atlas_options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  const TransferLayer* albedo = find(*r, LayerSemantic::kAlbedo);
  ASSERT_NE(albedo, nullptr);
  // sRGB 30 is 0.0137 in linear light; as a 2.2 power it would be 0.0090.
  for (float v : albedo->texels) ASSERT_NEAR(v, srgb_to_linear(30 / 255.0f), 2e-4f);
}

TEST(TransferRules, NearestMagFilterTakesWholeTexels) {
  test::ScratchDir dir;
  auto img = write_rgb(dir.file("cells.png"), 4, 4, [](int i, int j, uint8_t* t) {
    t[0] = uint8_t(20 + 60 * i), t[1] = uint8_t(30 + 50 * j), t[2] = uint8_t(16 * (i + 4 * j));
  });
  scene::Scene s = test::textured_scene(atlas_quad(), dir.file("cells.png"));
  s.materials[0].base_color_texture.mag_filter = scene::FilterMode::kNearest;
  auto nearest = transfer_materials(s, atlas_options());
  ASSERT_TRUE(nearest.ok()) << nearest.status().message();
  s.materials[0].base_color_texture.mag_filter = scene::FilterMode::kLinear;
  auto linear = transfer_materials(s, atlas_options());
  ASSERT_TRUE(linear.ok()) << linear.status().message();
  const auto& a = find(*nearest, LayerSemantic::kAlbedo)->texels;
  const auto& b = find(*linear, LayerSemantic::kAlbedo)->texels;
  float largest_blend = 0;
  for (uint32_t y = 0; y < kAtlas; ++y)
    for (uint32_t x = 0; x < kAtlas; ++x)
      for (int c = 0; c < 3; ++c) {
        const size_t i = (size_t(y) * kAtlas + x) * 3 + c;
        const float want = srgb_to_linear(img[(size_t(y / 16) * 4 + x / 16) * 3 + c] / 255.0f);
        ASSERT_NEAR(a[i], want, 1e-6f) << x << "," << y << "," << c;
        largest_blend = std::max(largest_blend, std::abs(b[i] - want));
      }
  EXPECT_GT(largest_blend, 0.02f);  // bilinear blends neighbouring texels
}

TEST(TransferRules, EmissiveStrengthMultipliesAndIsCounted) {
  scene::Material m;
  m.emissive_factor = {1.0f, 0.5f, 0.25f};
  m.emissive_strength = 4.0f;
  scene::Scene s = test::single_mesh_scene(atlas_quad(), m);
  auto r = transfer_materials(s, atlas_options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  const TransferLayer* e = find(*r, LayerSemantic::kEmissive);
  ASSERT_NE(e, nullptr);
  ASSERT_EQ(r->stats.covered_texels, uint64_t(kAtlas) * kAtlas);
  for (size_t i = 0; i < size_t(kAtlas) * kAtlas; ++i) {
    ASSERT_EQ(e->texels[3 * i], 4.0f);
    ASSERT_EQ(e->texels[3 * i + 1], 2.0f);
    ASSERT_EQ(e->texels[3 * i + 2], 1.0f);
  }
  EXPECT_TRUE(e->hdr);
  EXPECT_EQ(e->texels_above_one, uint64_t(kAtlas) * kAtlas);
  EXPECT_EQ(e->max_value, 4.0f);
  const TransferLayer* albedo = find(*r, LayerSemantic::kAlbedo);
  EXPECT_EQ(albedo->texels_above_one, 0u);

  s.materials[0].emissive_strength = 0;  // no emission: no emissive layer
  auto dark = transfer_materials(s, atlas_options());
  ASSERT_TRUE(dark.ok());
  EXPECT_EQ(find(*dark, LayerSemantic::kEmissive), nullptr);
}

TEST(TransferRules, VertexColoursMultiplyBaseColour) {
  scene::Primitive p = atlas_quad();
  // Affine in (u, v), so interpolation over either triangle gives it exactly.
  auto colour = [](double u, double v) {
    return scene::Vec4{float(0.2 + 0.6 * u), float(0.9 - 0.5 * v), 0.3f, 1.0f};
  };
  for (size_t i = 0; i < 4; ++i) p.colors.push_back(colour(p.uvs[0][i][0], p.uvs[0][i][1]));
  scene::Material m;
  m.base_color_factor = {0.5f, 0.8f, 1.0f, 1.0f};
  auto r = transfer_materials(test::single_mesh_scene(p, m), atlas_options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  const TransferLayer* albedo = find(*r, LayerSemantic::kAlbedo);
  ASSERT_EQ(albedo->channels, 3u);
  for (uint32_t y = 0; y < kAtlas; ++y)
    for (uint32_t x = 0; x < kAtlas; ++x) {
      const scene::Vec4 c = colour((x + 0.5) / kAtlas, (y + 0.5) / kAtlas);
      const float* t = &albedo->texels[(size_t(y) * kAtlas + x) * 3];
      ASSERT_NEAR(t[0], 0.5f * c[0], 1e-5f) << x << "," << y;
      ASSERT_NEAR(t[1], 0.8f * c[1], 1e-5f) << x << "," << y;
      ASSERT_NEAR(t[2], c[2], 1e-5f) << x << "," << y;
    }
}

// Material 'Brick': a base colour factor and a texture file that does not exist.
scene::Scene brick_scene(const test::ScratchDir& dir) {
  scene::Material m;
  m.name = "Brick";
  m.base_color_factor = {0.5f, 0.25f, 1.0f, 1.0f};
  return test::textured_scene(atlas_quad(), dir.file("missing.png"), m);
}

TEST(TransferRules, MissingTextureIsAnErrorNamingMaterialSlotAndPath) {
  test::ScratchDir dir;
  scene::Scene s = brick_scene(dir);
  auto r = transfer_materials(s, atlas_options());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kNotFound);
  const std::string want =
      "material 'Brick' baseColorTexture: cannot read image 'missing' (tried " +
      dir.file("missing.png") + "): ";
  EXPECT_EQ(r.status().message().substr(0, want.size()), want) << r.status().message();
  EXPECT_GT(r.status().message().size(), want.size());  // OpenImageIO's reason follows
}

// An image the scene holds no data for (a glTF image without uri or bufferView) is a missing
// texture like a missing file: refused by default, the factor alone under kWarn.
TEST(TransferRules, AnImageWithoutDataIsAMissingTexture) {
  test::ScratchDir dir;
  scene::Scene s = brick_scene(dir);
  const Expected<TransferResult> missing_file = [&] {
    TransferOptions o = atlas_options();
    o.missing_textures = MissingTextures::kWarn;
    return transfer_materials(s, o);
  }();
  ASSERT_TRUE(missing_file.ok()) << missing_file.status().message();
  scene::Image& im = s.images[0];
  im.path.clear(), im.uri.clear(), im.name = "lost";
  ASSERT_TRUE(im.has_no_data());
  auto refused = transfer_materials(s, atlas_options());
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), ErrorCode::kNotFound);
  EXPECT_EQ(refused.status().message(),
            "material 'Brick' baseColorTexture: cannot read image 'lost': the scene holds no data "
            "for it (--missing-textures warn bakes the slot from its factor)");
  TransferOptions o = atlas_options();
  o.missing_textures = MissingTextures::kWarn;
  auto warned = transfer_materials(s, o);
  ASSERT_TRUE(warned.ok()) << warned.status().message();
  ASSERT_EQ(warned->missing_textures.size(), 1u);
  ASSERT_TRUE(find(*warned, LayerSemantic::kAlbedo) && find(*missing_file, LayerSemantic::kAlbedo));
  EXPECT_EQ(find(*warned, LayerSemantic::kAlbedo)->texels,
            find(*missing_file, LayerSemantic::kAlbedo)->texels);
}

// With a band cache, the textures load on a thread of their own beside the cached bands (issue
// 16): the texels are those of a transfer without a cache whether every band is cached, none is
// (the texture repainted) or the texture is gone (an error naming it, or its factor alone).
TEST(TransferRules, TexturesLoadedBesideTheCachedBandsGiveTheSameTexelsAndErrors) {
  test::ScratchDir dir;
  const std::string paint = dir.file("paint.png");
  auto draw = [&](int shift) {
    write_rgb(paint, 16, 16, [&](int i, int j, uint8_t* t) {
      t[0] = uint8_t(i * 16 + shift), t[1] = uint8_t(j * 16), t[2] = uint8_t((i ^ j) * 16);
    });
  };
  draw(0);
  scene::Material m;
  m.name = "Brick";
  const scene::Scene s = test::textured_scene(atlas_quad(), paint, m);
  auto plain = [&](MissingTextures policy) {
    TransferOptions o = atlas_options();
    o.missing_textures = policy;
    return transfer_materials(s, o);
  };
  auto cached = [&](MissingTextures policy) {
    TransferOptions o = atlas_options();
    o.missing_textures = policy;
    o.cache_in = o.cache_out = dir.file("bands.bin");
    o.image_keys = image_content_keys(s);
    return transfer_materials(s, o);
  };
  auto albedo = [](const Expected<TransferResult>& r) {
    return r.ok() && find(*r, LayerSemantic::kAlbedo) ? find(*r, LayerSemantic::kAlbedo)->texels
                                                      : std::vector<float>{};
  };
  auto first = cached(MissingTextures::kError);  // writes the cache (none to read yet)
  ASSERT_TRUE(first.ok()) << first.status().message();
  EXPECT_EQ(first->stats.bands_cached, 0u);
  const std::vector<float> want = albedo(plain(MissingTextures::kError));
  ASSERT_FALSE(want.empty());
  EXPECT_EQ(albedo(first), want);
  auto again = cached(MissingTextures::kError);  // every band from the cache
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_EQ(again->stats.bands_cached, again->stats.bands);
  EXPECT_EQ(albedo(again), want);

  draw(7);  // repainted: no band's key holds, every band waits for the texture
  auto repainted = cached(MissingTextures::kError);
  ASSERT_TRUE(repainted.ok()) << repainted.status().message();
  EXPECT_EQ(repainted->stats.bands_cached, 0u);
  const std::vector<float> want_repainted = albedo(plain(MissingTextures::kError));
  EXPECT_NE(want_repainted, want);
  EXPECT_EQ(albedo(repainted), want_repainted);

  std::filesystem::remove(paint);  // gone: the loading thread's error is the transfer's
  auto missing = cached(MissingTextures::kError);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), ErrorCode::kNotFound);
  const std::string named = "material 'Brick' baseColorTexture: cannot read image 'paint'";
  EXPECT_EQ(missing.status().message().substr(0, named.size()), named)
      << missing.status().message();
  auto warned = cached(MissingTextures::kWarn);
  ASSERT_TRUE(warned.ok()) << warned.status().message();
  EXPECT_EQ(warned->missing_textures.size(), 1u);
  EXPECT_EQ(albedo(warned), albedo(plain(MissingTextures::kWarn)));
}

// An embedded PNG with a damaged IDAT is one kCorrupt error naming the material, the slot and
// the embedded image before OpenImageIO sees it, whatever the missing-texture policy.
TEST(TransferRules, DamagedEmbeddedPngIsAnErrorNamingMaterialSlotAndImage) {
  test::ScratchDir dir;
  const std::string png = dir.file("e.png");
  {
    auto out = OIIO::ImageOutput::create(png);
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(8, 8, 3, OIIO::TypeDesc::UINT8);
    std::vector<uint8_t> texels(8 * 8 * 3, 77);
    ASSERT_TRUE(out->open(png, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, texels.data()));
    out->close();
  }
  std::ifstream f(png, std::ios::binary);
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const std::string text(bytes.begin(), bytes.end());
  const size_t idat = text.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  bytes[idat + 6] ^= 0xFF;
  scene::Scene s = brick_scene(dir);
  scene::Image& im = s.images[0];
  im.bytes = bytes, im.path.clear(), im.uri.clear(), im.name = "paint", im.mime_type = "image/png";
  for (MissingTextures policy : {MissingTextures::kError, MissingTextures::kWarn}) {
    TransferOptions o = atlas_options();
    o.missing_textures = policy;
    o.scratch_dir = dir.file("");
    auto r = transfer_materials(s, o);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().code(), ErrorCode::kCorrupt);
    const std::string want =
        "material 'Brick' baseColorTexture: embedded image 0 'paint': corrupt PNG: chunk 'IDAT'";
    EXPECT_EQ(r.status().message().substr(0, want.size()), want) << r.status().message();
  }
  EXPECT_EQ(check_scene_textures(s).code(), ErrorCode::kCorrupt);
  bytes[idat + 6] ^= 0xFF;
  im.bytes = bytes;
  EXPECT_TRUE(check_scene_textures(s).ok());
}

// The texture cache's share of a bake's memory limit: a quarter, 32 MiB to 2 GiB.
TEST(TransferRules, TextureCacheFollowsTheMemoryLimit) {
  constexpr uint64_t MiB = uint64_t(1) << 20;
  EXPECT_EQ(texture_cache_bytes(64 * MiB), 32 * MiB);
  EXPECT_EQ(texture_cache_bytes(256 * MiB), 64 * MiB);
  EXPECT_EQ(texture_cache_bytes(uint64_t(8) << 30), uint64_t(2) << 30);  // the bake's default
  EXPECT_EQ(texture_cache_bytes(uint64_t(64) << 30), uint64_t(2) << 30);
}

TEST(TransferRules, MissingTextureWarnBakesTheFactorAlone) {
  test::ScratchDir dir;
  scene::Scene s = brick_scene(dir);
  s.materials[0].emissive_texture.image = s.materials[0].base_color_texture.image;
  s.materials[0].emissive_factor = {1, 1, 1};
  TransferOptions o = atlas_options();
  o.missing_textures = MissingTextures::kWarn;
  auto r = transfer_materials(s, o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  ASSERT_EQ(r->missing_textures.size(), 2u);
  const MissingTexture& miss = r->missing_textures[0];
  EXPECT_EQ(miss.material, "Brick");
  EXPECT_EQ(miss.material_index, 0);
  EXPECT_EQ(miss.slot, "baseColorTexture");
  EXPECT_EQ(miss.image, "missing");
  EXPECT_EQ(miss.path, dir.file("missing.png"));
  EXPECT_FALSE(miss.reason.empty());
  EXPECT_EQ(r->missing_textures[1].slot, "emissiveTexture");
  const TransferLayer* albedo = find(*r, LayerSemantic::kAlbedo);
  for (size_t i = 0; i < size_t(kAtlas) * kAtlas; ++i) {
    ASSERT_EQ(albedo->texels[3 * i], 0.5f);
    ASSERT_EQ(albedo->texels[3 * i + 1], 0.25f);
    ASSERT_EQ(albedo->texels[3 * i + 2], 1.0f);
  }
  const TransferLayer* emissive = find(*r, LayerSemantic::kEmissive);
  ASSERT_NE(emissive, nullptr);
  EXPECT_EQ(emissive->texels[0], 1.0f);
}

TEST(TransferRules, MissingUvSetIsNamedWithItsSlot) {
  scene::Primitive p = atlas_quad();
  p.uvs.resize(1);  // TEXCOORD_0 only, before unwrapping
  scene::Material m;
  m.name = "Stone";
  scene::Scene s = test::single_mesh_scene(p, m);
  s.materials[0].occlusion_texture.image = test::add_image(s, "ao.png");
  s.materials[0].occlusion_texture.texcoord = 1;
  Status st = check_texcoord_sets(s);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.message(),
            "mesh 'mesh' primitive 0: material 'Stone' occlusionTexture reads TEXCOORD_1, which "
            "the primitive lacks (it has 1 UV set)");
  s.materials[0].occlusion_texture.texcoord = 0;
  EXPECT_TRUE(check_texcoord_sets(s).ok());
}

// A flat grid of n x n cells whose every triangle has vertices of its own (as flat-shaded or
// per-face-UV exports give), laid out as one chart in the atlas.
scene::Primitive split_grid(int n, float margin) {
  scene::Primitive p;
  p.uvs.resize(2);
  auto corner = [&](int i, int j) {
    const float a = float(i) / n, b = float(j) / n;
    p.positions.push_back({a, b, 0});
    p.normals.push_back({0, 0, 1});
    p.uvs[0].push_back({a, b});
    p.uvs[1].push_back({margin + (1 - 2 * margin) * a, margin + (1 - 2 * margin) * b});
    p.indices.push_back(uint32_t(p.positions.size() - 1));
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      corner(i, j), corner(i + 1, j), corner(i + 1, j + 1);
      corner(i, j), corner(i + 1, j + 1), corner(i, j + 1);
    }
  return p;
}

TEST(TransferRules, SplitVerticesOfOneChartDoNotContest) {
  scene::Scene s = test::single_mesh_scene(split_grid(6, 0.1f), {});
  auto r = transfer_materials(s, atlas_options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->stats.contested_texels, 0u);
  EXPECT_GT(r->stats.covered_texels, 2000u);

  TransferOptions o = atlas_options();
  o.charts.assign(72, 0);  // the unwrapper's word: one chart
  r = transfer_materials(s, o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->stats.contested_texels, 0u);

  for (size_t t = 0; t < o.charts.size(); ++t) o.charts[t] = int32_t(t % 2);  // two charts
  r = transfer_materials(s, o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_GT(r->stats.contested_texels, 0u);

  o.charts.resize(5);
  r = transfer_materials(s, o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().message(), "transfer: 5 chart ids for 72 triangles");
}

// A scene bake of the split grid with emissive strength 4, a scene warning and a missing
// base colour texture in warn mode: what the summary and its JSON report.
TEST(TransferRules, SceneBakeReportsClippingMissesAndWarnings) {
  test::ScratchDir dir;
  scene::Material m;
  m.name = "Lamp";
  m.emissive_factor = {1.0f, 0.5f, 0.25f};
  m.emissive_strength = 4.0f;
  scene::Scene s = test::textured_scene(split_grid(6, 0.0f), dir.file("gone.png"), m);
  s.warnings = {"lamp.gltf: KHR_materials_sheen: sheen is not baked; the base layer is"};
  SceneBakeOptions o;
  o.build.output = dir.file("lamp.vtpf");
  o.build.threads = 2;
  o.unwrapped = "-";
  o.unwrap.size_pages = 1;
  o.missing_textures = MissingTextures::kWarn;
  auto summary = bake_scene(s, o);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  const uint64_t covered = summary->transfer.covered_texels;
  EXPECT_GT(covered, 10000u);
  EXPECT_EQ(summary->transfer.contested_texels, 0u);  // one chart, split vertices
  ASSERT_EQ(summary->above_one.size(), 1u);
  const LayerRange& range = summary->above_one[0];
  EXPECT_EQ(range.layer, "emissive");
  EXPECT_EQ(range.texels_above_one, covered);
  EXPECT_EQ(range.max_value, 4.0f);
  EXPECT_TRUE(range.clipped);
  ASSERT_EQ(summary->missing_textures.size(), 1u);
  // The scene's, the unwrap's (the missing image does not size the atlas), the transfer's, the
  // build's.
  ASSERT_EQ(summary->warnings.size(), 4u);
  EXPECT_EQ(summary->warnings[0], s.warnings[0]);
  EXPECT_EQ(summary->warnings[1].rfind("1 image(s) gave no size", 0), 0u) << summary->warnings[1];
  EXPECT_EQ(summary->warnings[2].rfind("material 'Lamp' baseColorTexture: cannot read image", 0),
            0u)
      << summary->warnings[2];
  // The clipped layer's line is the build's (red 4 and green 2 of each covered texel).
  EXPECT_EQ(summary->warnings[3], "layer 'emissive': " + std::to_string(covered) + " texels (" +
                                      std::to_string(2 * covered) +
                                      " values) outside [0, 1], up to 4, clipped by its 8-bit dct "
                                      "storage; its PSNR counts the clipping (--float-texels half "
                                      "or float keeps the range)");
  const LayerSummary* emissive = nullptr;
  for (const LayerSummary& l : summary->build.layers)
    if (l.name == "emissive") emissive = &l;
  ASSERT_NE(emissive, nullptr);
  EXPECT_EQ(emissive->clipped.texels, covered);
  EXPECT_EQ(emissive->clipped.max_value, 4.0f);
  // Against the unclipped values: sRGB(4) is code 465 where 255 is stored, so the PSNR is low.
  EXPECT_LT(emissive->psnr_db, 20.0);

  nlohmann::json j = to_json(*summary);
  ASSERT_EQ(j["transfer"]["above_one"].size(), 1u);
  EXPECT_EQ(j["transfer"]["above_one"][0]["layer"], "emissive");
  EXPECT_EQ(j["transfer"]["above_one"][0]["clipped_texels"], covered);
  EXPECT_EQ(j["transfer"]["above_one"][0]["max_value"], 4.0);
  EXPECT_EQ(j["transfer"]["missing_textures"][0]["slot"], "baseColorTexture");
  EXPECT_EQ(j["transfer"]["missing_textures"][0]["path"], dir.file("gone.png"));
  EXPECT_EQ(j["warnings"].size(), 4u);

  // Raw storage keeps floats: nothing is clipped and level 0 holds the values.
  o.build.codec.codec = CodecKind::kRaw;
  summary = bake_scene(s, o);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  ASSERT_EQ(summary->above_one.size(), 1u);
  EXPECT_FALSE(summary->above_one[0].clipped);
  EXPECT_EQ(summary->above_one[0].texels_above_one, covered);
  auto reader = PageFileReader::open(o.build.output);
  ASSERT_TRUE(reader.ok());
  const int e = test::find_layer(**reader, LayerSemantic::kEmissive);
  ASSERT_GE(e, 0);
  test::Level0 level = test::read_level0(**reader, uint32_t(e));
  EXPECT_EQ(*std::max_element(level.texels.begin(), level.texels.end()), 4.0f);

  // Half-float storage keeps them too, whatever the codec (here the default DCT).
  o.build.codec.codec = CodecKind::kDct;
  o.build.codec.float_texels = FloatTexels::kHalf;
  summary = bake_scene(s, o);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  ASSERT_EQ(summary->above_one.size(), 1u);
  EXPECT_FALSE(summary->above_one[0].clipped);
  reader = PageFileReader::open(o.build.output);
  ASSERT_TRUE(reader.ok());
  const int h = test::find_layer(**reader, LayerSemantic::kEmissive);
  ASSERT_GE(h, 0);
  EXPECT_EQ((*reader)->layers()[h].texel_type, TexelType::kF16);
  EXPECT_EQ((*reader)->layers()[h].runtime_format, RuntimeFormat::kBc6hUf16);  // RGB half
  level = test::read_level0(**reader, uint32_t(h));
  EXPECT_EQ(*std::max_element(level.texels.begin(), level.texels.end()), 4.0f);
}

}  // namespace
}  // namespace vt
