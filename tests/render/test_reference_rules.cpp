// The validator's reference pass follows the bake's material rules (scene/material_rules.h):
// per-axis samplers (MIRRORED_REPEAT, CLAMP_TO_EDGE), the nearest magFilter,
// KHR_texture_transform, TEXCOORD_1, COLOR_0 and alpha MASK. For each rule the reference image
// of a screen-filling quad is checked against the texture sampled on the CPU, and a small box
// written here as glTF bakes and validates. Skips cleanly where no Vulkan device exists.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "bake/scene_bake.h"
#include "common/srgb.h"
#include "render/coverage_tolerance.h"
#include "render/renderer.h"
#include "render/scene_draws.h"
#include "render/validate.h"
#include "render/vulkan_context.h"
#include "scene/gltf_export.h"
#include "scene/material_rules.h"
#include "scene/scene.h"
#include "tests/process_temp_dir.h"
#include "tests/render/one_primitive_scene.h"
#include "tests/render/png_file.h"

namespace vt::render {
namespace {

constexpr uint32_t kSize = 64;  // reference render, pixels per side
constexpr int kTexels = 8;      // texture side

VulkanContext* vulkan() {
  static Expected<std::unique_ptr<VulkanContext>> ctx = VulkanContext::create();
  return ctx.ok() ? ctx->get() : nullptr;
}

#define REQUIRE_VULKAN() \
  if (!vulkan()) GTEST_SKIP() << "no Vulkan device"

std::string test_dir(const std::string& name) {
  auto d = test::process_temp_dir("vt_reference_rules") / name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d.string();
}

using Texel = std::array<uint8_t, 4>;
using TexelFn = std::function<Texel(int x, int y)>;

// 2x2-texel cells of one colour each: a bilinear tap within half a texel of a cell's centre
// reads that cell alone. Alpha 40 on cells with an odd cx + cy when `alpha`.
Texel cell_texel(int x, int y, bool alpha) {
  const int cx = x / 2, cy = y / 2;
  return {uint8_t(40 + 60 * cx), uint8_t(40 + 60 * cy), uint8_t(220 - 30 * (cx + cy)),
          uint8_t(alpha && (cx + cy) % 2 ? 40 : 255)};
}
// Every texel its own colour (the nearest-filter case).
Texel distinct_texel(int x, int y) {
  return {uint8_t(20 + 30 * x), uint8_t(20 + 30 * y), 128, 255};
}
// Smooth ramps (the bake cases: no edge for two resamplings to disagree on).
Texel ramp_texel(int x, int y) {
  return {uint8_t(255 * x / (kTexels - 1)), uint8_t(255 * y / (kTexels - 1)), 96,
          uint8_t(255 * x / (kTexels - 1))};
}

std::string write_png(const std::string& dir, const TexelFn& texel) {
  const std::string path = dir + "/tex.png";
  std::vector<uint8_t> px;
  for (int y = 0; y < kTexels; ++y)
    for (int x = 0; x < kTexels; ++x) {
      const Texel t = texel(x, y);
      px.insert(px.end(), t.begin(), t.end());
    }
  return write_png_file(path, kTexels, kTexels, 4, px) ? path : "";
}

std::string cell_png(const std::string& name, bool alpha = false) {
  return write_png(test_dir(name), [alpha](int x, int y) { return cell_texel(x, y, alpha); });
}

// A quad over the whole clip space (identity camera); mesh UV (u0, v0) at the top-left corner
// and `span` across, in UV set `set` (the other sets, if any, are zeros).
scene::Primitive screen_quad(double u0, double v0, double span, int set = 0) {
  scene::Primitive p;
  p.positions = {{-1, -1, 0.5f}, {1, -1, 0.5f}, {1, 1, 0.5f}, {-1, 1, 0.5f}};
  p.uvs.assign(size_t(set) + 1, std::vector<scene::Vec2>(4, {0, 0}));
  for (size_t v = 0; v < 4; ++v) {
    const double s = (p.positions[v][0] + 1) / 2, t = (p.positions[v][1] + 1) / 2;
    p.uvs[set][v] = {float(u0 + s * span), float(v0 + t * span)};
  }
  p.indices = {0, 1, 2, 0, 2, 3};
  return p;
}

// The mesh UV at a pixel's centre of the screen quad.
std::array<double, 2> quad_uv(uint32_t px, uint32_t py, double u0, double v0, double span) {
  return {u0 + (px + 0.5) / kSize * span, v0 + (py + 0.5) / kSize * span};
}

Expected<ReferenceFrame> render_reference_of(const scene::Scene& sc) {
  VT_ASSIGN_OR_RETURN(SceneDraws draws, reference_scene_draws(sc));
  RenderOptions o;
  o.width = o.height = kSize;
  VT_ASSIGN_OR_RETURN(auto renderer, Renderer::create(*vulkan(), o));
  VT_RETURN_IF_ERROR(renderer->set_meshes(draws.meshes));
  VT_RETURN_IF_ERROR(renderer->set_reference_textures(draws.textures));
  return renderer->render_reference(Camera{});
}

// Where a pixel's sample lands in the texture, in texels, after the slot's transform and wrap.
std::array<double, 2> texel_position(const scene::TextureRef& ref, std::array<double, 2> uv) {
  const auto t = scene::texture_uv(ref, uv[0], uv[1]);
  return {scene::wrap_coordinate(ref.wrap_s, t[0]) * kTexels,
          scene::wrap_coordinate(ref.wrap_t, t[1]) * kTexels};
}

// Compares the reference render with `expected(texel position)` at every pixel `usable` admits;
// returns how many pixels were compared. `expected` returns nothing where the pixel must be
// empty (alpha test).
using Expect = std::function<std::optional<Texel>(std::array<double, 2>)>;
int compare_pixels(const ReferenceFrame& f, const scene::TextureRef& ref, double u0, double v0,
                   double span, const std::function<bool(std::array<double, 2>)>& usable,
                   const Expect& expected, int tolerance) {
  int compared = 0;
  for (uint32_t py = 0; py < kSize; ++py)
    for (uint32_t px = 0; px < kSize; ++px) {
      const auto pos = texel_position(ref, quad_uv(px, py, u0, v0, span));
      if (!usable(pos)) continue;
      ++compared;
      const size_t i = size_t(py) * kSize + px;
      const std::optional<Texel> want = expected(pos);
      EXPECT_EQ(f.covered[i], want ? 1u : 0u) << "pixel " << px << "," << py;
      if (!want) continue;
      for (int c = 0; c < 4; ++c) {
        EXPECT_NEAR(f.color.texels[i * 4 + c], (*want)[c], tolerance)
            << "pixel " << px << "," << py << " channel " << c << " at texel " << pos[0] << ","
            << pos[1];
      }
    }
  return compared;
}

// Within 0.3 texels of a cell's centre on both axes (cells are 2 texels, centred on odd ones).
bool near_cell_centre(std::array<double, 2> pos) {
  for (double p : pos) {
    if (std::abs(p - (2.0 * std::floor(p / 2.0) + 1.0)) > 0.3) return false;
  }
  return true;
}

Texel cell_at(std::array<double, 2> pos, bool alpha = false) {
  auto texel = [](double p) { return std::min(kTexels - 1, std::max(0, int(std::floor(p)))); };
  return cell_texel(texel(pos[0]), texel(pos[1]), alpha);
}

scene::Material textured(scene::WrapMode s, scene::WrapMode t) {
  scene::Material m;
  m.name = "m";
  m.base_color_texture.image = 0;
  m.base_color_texture.wrap_s = s;
  m.base_color_texture.wrap_t = t;
  m.metallic_factor = 0;
  return m;
}

// Only drawn materials read their image; one that cannot be read names the material and slot,
// or (a bake with --missing-textures warn) is drawn from the factor alone and listed. No Vulkan.
TEST(ReferenceRules, ImagesThatCannotBeReadNameTheMaterialOrDrawTheFactor) {
  const std::string png = cell_png("missing_ref");
  ASSERT_FALSE(png.empty());
  scene::Material m = textured(scene::WrapMode::kRepeat, scene::WrapMode::kRepeat);
  m.base_color_factor = {0.5f, 0.5f, 0.5f, 1};
  scene::Scene sc = one_primitive_scene(screen_quad(0, 0, 1), m, png);
  scene::Material unused = m;
  unused.name = "unused";
  unused.base_color_texture.image = 1;
  sc.materials.push_back(unused);
  sc.images.push_back(sc.images[0]);
  sc.images[1].path = png + ".gone.png";
  auto draws = reference_scene_draws(sc);
  ASSERT_TRUE(draws.ok()) << draws.status().message();
  EXPECT_EQ(draws->textures[0].width, uint32_t(kTexels));
  EXPECT_TRUE(draws->missing_textures.empty());

  sc.materials[0].base_color_texture.image = 1;
  draws = reference_scene_draws(sc);
  ASSERT_FALSE(draws.ok());
  EXPECT_EQ(draws.status().message().rfind("material 'm' baseColorTexture: cannot open image", 0),
            0u)
      << draws.status().message();
  draws = reference_scene_draws(sc, {.missing_as_factor = true});
  ASSERT_TRUE(draws.ok()) << draws.status().message();
  ASSERT_EQ(draws->missing_textures.size(), 1u);
  EXPECT_NE(draws->missing_textures[0].find("drawn from its factor"), std::string::npos);
  EXPECT_EQ(draws->textures[0].width, 1u);  // the factor: 0.5 linear, 188 in sRGB
  EXPECT_EQ(draws->textures[0].levels[0], (std::vector<uint8_t>{188, 188, 188, 255}));
}

TEST(ReferenceRules, MirroredRepeatAndClampPerAxis) {
  REQUIRE_VULKAN();
  const std::string png = cell_png("mirror_ref");
  ASSERT_FALSE(png.empty());
  // Mesh UV -0.5 .. 1.5: mirrored across both period edges in u, clamped in v.
  const scene::Material m =
      textured(scene::WrapMode::kMirroredRepeat, scene::WrapMode::kClampToEdge);
  auto f = render_reference_of(one_primitive_scene(screen_quad(-0.5, -0.5, 2), m, png));
  ASSERT_TRUE(f.ok()) << f.status().message();
  // Clamped rows read the edge cells: usable where u is near a cell centre and v either is or
  // lies outside the texture.
  auto usable = [](std::array<double, 2> pos) {
    const bool v_clamped = pos[1] <= 0.0 || pos[1] >= kTexels;
    return near_cell_centre({pos[0], v_clamped ? 1.0 : pos[1]});
  };
  const int n = compare_pixels(
      *f, m.base_color_texture, -0.5, -0.5, 2, usable, [](auto pos) { return cell_at(pos); }, 1);
  EXPECT_GT(n, 600);
  // The mirror: the pixel column at mesh u = -0.125 reads the same cell as u = +0.125.
  const size_t row = size_t(kSize / 2) * kSize;
  EXPECT_EQ(f->color.texels[(row + 12) * 4], f->color.texels[(row + 19) * 4]);
}

TEST(ReferenceRules, NearestMagFilterReadsOneTexel) {
  REQUIRE_VULKAN();
  const std::string png = write_png(test_dir("nearest_ref"), distinct_texel);
  ASSERT_FALSE(png.empty());
  scene::Material m = textured(scene::WrapMode::kRepeat, scene::WrapMode::kRepeat);
  m.base_color_texture.mag_filter = scene::FilterMode::kNearest;
  auto f = render_reference_of(one_primitive_scene(screen_quad(0, 0, 1), m, png));
  ASSERT_TRUE(f.ok()) << f.status().message();
  // Off-centre but inside one texel: a linear filter would blend in 15-35% of a neighbour.
  auto usable = [](std::array<double, 2> pos) {
    for (double p : pos) {
      const double d = std::abs(p - std::floor(p) - 0.5);
      if (d < 0.15 || d > 0.35) return false;
    }
    return true;
  };
  const int n = compare_pixels(
      *f, m.base_color_texture, 0, 0, 1, usable,
      [](auto pos) { return distinct_texel(int(pos[0]), int(pos[1])); }, 1);
  EXPECT_GT(n, 200);
}

TEST(ReferenceRules, TextureTransformAndSecondUvSet) {
  REQUIRE_VULKAN();
  const std::string png = cell_png("transform_ref");
  ASSERT_FALSE(png.empty());
  scene::Material m = textured(scene::WrapMode::kRepeat, scene::WrapMode::kMirroredRepeat);
  m.base_color_texture.texcoord = 1;
  m.base_color_texture.transform.offset = {0.1f, -0.2f};
  m.base_color_texture.transform.rotation = 0.3f;
  m.base_color_texture.transform.scale = {1.5f, 0.75f};
  auto f = render_reference_of(one_primitive_scene(screen_quad(0.2, 0.1, 1.2, 1), m, png));
  ASSERT_TRUE(f.ok()) << f.status().message();
  const int n = compare_pixels(
      *f, m.base_color_texture, 0.2, 0.1, 1.2, near_cell_centre,
      [](auto pos) { return cell_at(pos); }, 1);
  EXPECT_GT(n, 200);
}

TEST(ReferenceRules, VertexColoursMultiplyInLinearLight) {
  REQUIRE_VULKAN();
  const std::string png = cell_png("colors_ref");
  ASSERT_FALSE(png.empty());
  const scene::Material m = textured(scene::WrapMode::kRepeat, scene::WrapMode::kRepeat);
  scene::Primitive quad = screen_quad(0, 0, 1);
  const scene::Vec4 colour = {0.5f, 0.25f, 1.0f, 0.5f};  // alpha ignored: the material is OPAQUE
  quad.colors.assign(4, colour);
  auto f = render_reference_of(one_primitive_scene(quad, m, png));
  ASSERT_TRUE(f.ok()) << f.status().message();
  auto expected = [&](std::array<double, 2> pos) -> std::optional<Texel> {
    const Texel t = cell_at(pos);
    scene::Vec4 lin;
    for (int c = 0; c < 3; ++c) lin[c] = srgb_to_linear(t[c] / 255.0f);
    lin[3] = t[3] / 255.0f;
    const scene::Vec4 out = scene::base_color(m, lin, colour);
    Texel e;
    for (int c = 0; c < 3; ++c) e[c] = uint8_t(std::lround(linear_to_srgb(out[c]) * 255.0f));
    e[3] = uint8_t(std::lround(out[3] * 255.0f));
    return e;
  };
  const int n = compare_pixels(*f, m.base_color_texture, 0, 0, 1, near_cell_centre, expected, 2);
  EXPECT_GT(n, 200);
}

TEST(ReferenceRules, AlphaMaskDiscardsBelowTheCutoff) {
  REQUIRE_VULKAN();
  const std::string png = cell_png("mask_ref", true);
  ASSERT_FALSE(png.empty());
  scene::Material m = textured(scene::WrapMode::kRepeat, scene::WrapMode::kRepeat);
  m.alpha_mode = scene::AlphaMode::kMask;
  m.alpha_cutoff = 0.5f;
  auto f = render_reference_of(one_primitive_scene(screen_quad(0, 0, 1), m, png));
  ASSERT_TRUE(f.ok()) << f.status().message();
  int empty = 0;
  const int n = compare_pixels(
      *f, m.base_color_texture, 0, 0, 1, near_cell_centre,
      [&](auto pos) -> std::optional<Texel> {
        const Texel t = cell_at(pos, true);
        if (t[3] >= 128) return t;
        ++empty;
        return std::nullopt;
      },
      1);
  EXPECT_GT(n, 200);
  EXPECT_GT(empty, 100);
}

// A blended material is written as it composites: colour premultiplied by alpha (the cells at
// alpha 40 read 40/255 of their colour), alpha as sampled.
TEST(ReferenceRules, AlphaBlendWritesColourPremultiplied) {
  REQUIRE_VULKAN();
  const std::string png = cell_png("blend_ref", true);
  ASSERT_FALSE(png.empty());
  scene::Material m = textured(scene::WrapMode::kRepeat, scene::WrapMode::kRepeat);
  m.alpha_mode = scene::AlphaMode::kBlend;
  auto f = render_reference_of(one_primitive_scene(screen_quad(0, 0, 1), m, png));
  ASSERT_TRUE(f.ok()) << f.status().message();
  int translucent = 0;
  const int n = compare_pixels(
      *f, m.base_color_texture, 0, 0, 1, near_cell_centre,
      [&](auto pos) -> std::optional<Texel> {
        Texel t = cell_at(pos, true);
        translucent += t[3] < 255;
        for (int c = 0; c < 3; ++c) t[c] = uint8_t(std::lround(t[c] * (t[3] / 255.0)));
        return t;
      },
      2);
  EXPECT_GT(n, 200);
  EXPECT_GT(translucent, 100);
}

// A UV-sphere pole seen from above (earthCylindrical.DAE's cap): one pole vertex at u = 0.5
// shared by a fan of kPoleFan triangles whose ring vertices run u = 0 .. 1 at t = 1, so each
// triangle but the middle ones shears up to half the texture across its height. The texture is
// kStripes horizontal stripes, constant along u: whatever stretch of u a pixel's footprint
// sweeps, the pixel's box average is the stripe at its t. The footprint's minor axis taken as the
// shorter of dx and dy (both point along u there) blurred the stripes into each other.
constexpr int kPoleFan = 16, kStripes = 8, kStripeTexels = 4;
constexpr int kPoleWidth = 1024, kPoleHeight = kStripes * kStripeTexels;
constexpr double kPoleRadius = 1.5;  // clip units: the fan covers the whole render

Texel stripe_texel(int stripe) {
  return {uint8_t(30 + 28 * stripe), uint8_t(220 - 25 * stripe), uint8_t(stripe % 2 ? 200 : 60),
          255};
}

scene::Primitive pole_fan() {
  scene::Primitive p;
  p.uvs.resize(1);
  p.positions.push_back({0, 0, 0.5f});
  p.uvs[0].push_back({0.5f, 0});
  for (int i = 0; i <= kPoleFan; ++i) {  // the seam: ring vertex kPoleFan repeats 0 at u = 1
    const double a = 2 * std::numbers::pi * i / kPoleFan;
    p.positions.push_back(
        {float(kPoleRadius * std::cos(a)), float(kPoleRadius * std::sin(a)), 0.5f});
    p.uvs[0].push_back({float(i) / kPoleFan, 1});
  }
  for (uint32_t i = 0; i < kPoleFan; ++i) p.indices.insert(p.indices.end(), {0, i + 1, i + 2});
  return p;
}

// The fan triangle under clip point (x, y) and t there (t = 1 minus the pole's barycentric).
std::pair<int, double> pole_fan_t(double x, double y) {
  double a = std::atan2(y, x);
  if (a < 0) a += 2 * std::numbers::pi;
  const int i = std::min(kPoleFan - 1, int(a / (2 * std::numbers::pi / kPoleFan)));
  const double a0 = 2 * std::numbers::pi * i / kPoleFan,
               a1 = 2 * std::numbers::pi * (i + 1) / kPoleFan;
  const double x1 = kPoleRadius * std::cos(a0), y1 = kPoleRadius * std::sin(a0);
  const double x2 = kPoleRadius * std::cos(a1), y2 = kPoleRadius * std::sin(a1);
  // (x, y) = b1 (x1, y1) + b2 (x2, y2): the ring's weights; the pole's is 1 - b1 - b2.
  const double det = x1 * y2 - x2 * y1;
  const double b1 = (x * y2 - x2 * y) / det, b2 = (x1 * y - x * y1) / det;
  return {i, b1 + b2};
}

TEST(ReferenceRules, PoleFanShearKeepsStripesSharp) {
  REQUIRE_VULKAN();
  const std::string dir = test_dir("pole_ref");
  const std::string png = dir + "/stripes.png";
  {
    std::vector<uint8_t> px;
    for (int y = 0; y < kPoleHeight; ++y)
      for (int x = 0; x < kPoleWidth; ++x) {
        const Texel t = stripe_texel(y / kStripeTexels);
        px.insert(px.end(), t.begin(), t.end());
      }
    ASSERT_TRUE(write_png_file(png, kPoleWidth, kPoleHeight, 4, px));
  }
  const scene::Material m = textured(scene::WrapMode::kRepeat, scene::WrapMode::kClampToEdge);
  auto f = render_reference_of(one_primitive_scene(pole_fan(), m, png));
  ASSERT_TRUE(f.ok()) << f.status().message();
  // Pixels whose t lies within 0.6 texels of a stripe's centre: the footprint spans 0.7 texels
  // of t there (32 texels over 47 pixels), so every tap reads that stripe alone.
  int compared = 0, sheared = 0, bad = 0;
  for (uint32_t py = 0; py < kSize; ++py)
    for (uint32_t px = 0; px < kSize; ++px) {
      const double x = (px + 0.5) / kSize * 2 - 1, y = (py + 0.5) / kSize * 2 - 1;
      const auto [tri, t] = pole_fan_t(x, y);
      const double texel = t * kPoleHeight;
      const int stripe = std::min(kStripes - 1, int(texel / kStripeTexels));
      if (std::abs(texel - (stripe + 0.5) * kStripeTexels) > 0.6) continue;
      ++compared;
      // Ring u at least a quarter from the pole's 0.5: at least 256 texels of shear.
      if (std::abs((tri + 0.5) / kPoleFan - 0.5) >= 0.25) ++sheared;
      const size_t i = size_t(py) * kSize + px;
      const Texel want = stripe_texel(stripe);
      int worst = 0;
      for (int c = 0; c < 3; ++c)
        worst = std::max(worst, std::abs(int(f->color.texels[i * 4 + c]) - int(want[c])));
      if (worst > 2 && ++bad <= 10) {
        ADD_FAILURE() << "pixel " << px << "," << py << " (triangle " << tri << ", t " << texel
                      << " texels) differs from stripe " << stripe << " by " << worst;
      }
    }
  EXPECT_EQ(bad, 0) << "of " << compared << " pixels";
  EXPECT_GT(compared, 400);
  EXPECT_GT(sheared, 150);
}

TEST(CoverageTolerance, ExplainsOnlyAlphaNearACutoff) {
  // Pixels: both drew (alphas 0.60 / 0.62, then opaque twice), the virtual render alone at
  // alpha 0.51 (explained by the cutoff 0.5), the reference alone at 0.90 (not), neither.
  ReferenceFrame r;
  VirtualFrame v;
  const uint8_t ra[] = {153, 255, 255, 0, 230, 0}, va[] = {158, 255, 255, 130, 0, 0};
  const bool rc[] = {1, 1, 1, 0, 1, 0}, vc[] = {1, 1, 1, 1, 0, 0};
  r.color.width = v.color.width = 6;
  r.color.height = v.color.height = 1;
  for (int i = 0; i < 6; ++i) {
    r.color.texels.insert(r.color.texels.end(), {0, 0, 0, ra[i]});
    v.color.texels.insert(v.color.texels.end(), {0, 0, 0, va[i]});
    r.covered.push_back(rc[i]);
    v.status.push_back(vc[i] ? 0x80000000u : 0u);
  }
  const float cutoffs[] = {0.5f};
  const CoverageMismatch m = classify_coverage(r, v, cutoffs);
  EXPECT_EQ(m.either, 5u);
  EXPECT_EQ(m.explained, 1u);
  EXPECT_EQ(m.unexplained, 1u);
  EXPECT_NEAR(m.alpha_tolerance, 5.0 / 255.0, 1e-9);  // the one non-opaque pair differs by 5
  // No MASK material: nothing is explained.
  EXPECT_EQ(classify_coverage(r, v, {}).unexplained, 2u);
}

// A unit box (its first `faces` faces) whose faces each map mesh UV -0.5 .. 1.5, with a vertex
// colour per corner when `colours`.
scene::Primitive box(bool colours, int set, int faces = 6) {
  scene::Primitive p;
  p.uvs.resize(size_t(set) + 1);
  const int axes[6][3] = {{0, 1, 2}, {0, 1, 2}, {1, 2, 0}, {1, 2, 0}, {2, 0, 1}, {2, 0, 1}};
  for (int f = 0; f < faces; ++f) {
    const float side = f % 2 ? 0.5f : -0.5f;
    const uint32_t base = uint32_t(p.positions.size());
    for (int c = 0; c < 4; ++c) {
      const float a = c == 1 || c == 2 ? 0.5f : -0.5f, b = c >= 2 ? 0.5f : -0.5f;
      scene::Vec3 pos;
      pos[axes[f][0]] = a, pos[axes[f][1]] = b, pos[axes[f][2]] = side;
      p.positions.push_back(pos);
      for (int s = 0; s <= set; ++s)
        p.uvs[s].push_back(s == set ? scene::Vec2{a * 2 + 0.5f, b * 2 + 0.5f} : scene::Vec2{0, 0});
      if (colours) p.colors.push_back({c == 1 ? 1.0f : 0.3f, c == 2 ? 1.0f : 0.4f, 0.8f, 1});
    }
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) p.indices.push_back(base + i);
  }
  return p;
}

// Writes the box scene as glTF (with `patch` applied to the JSON), bakes it and validates it.
void bake_and_validate(const std::string& name, const scene::Primitive& prim,
                       const scene::Material& m,
                       const std::function<void(nlohmann::json&)>& patch = {},
                       const TexelFn& texel = ramp_texel) {
  const std::string dir = test_dir(name);
  const std::string png = write_png(dir, texel);
  ASSERT_FALSE(png.empty());
  scene::Scene sc = one_primitive_scene(prim, m, png);
  scene::Material& mat = sc.materials[0];
  mat.double_sided = true;
  const std::string gltf = dir + "/scene.gltf";
  ASSERT_TRUE(scene::save_gltf(sc, gltf).ok());
  if (patch) {
    nlohmann::json doc;
    std::ifstream(gltf) >> doc;
    patch(doc);
    std::ofstream(gltf) << doc.dump();
  }
  SceneBakeOptions o;
  o.build.output = dir + "/bake.vtpf";
  o.unwrap.size_pages = 4;
  auto baked = bake_scene(gltf, o);
  ASSERT_TRUE(baked.ok()) << baked.status().message();
  BakeValidationOptions v;
  v.scene = gltf;
  v.page_file = o.build.output;
  v.views = 3;
  v.width = 192;
  v.height = 128;
  auto r = validate_bake(v);
  ASSERT_TRUE(r.ok()) << r.status().message();
  for (const ViewReport& view : r->views) {
    std::string why;
    for (const std::string& f : view.failures) why += f + "; ";
    if (view.view < r->exact.views.size()) {  // the figures behind the bounds
      const StreamingViewMetrics& e = r->exact.views[view.view].metrics;
      std::printf(
          "%s view %u: %.2f dB, coarser %.2f%%; exact max %d, beyond %llu, alpha edge %llu\n",
          name.c_str(), view.view, view.metrics.psnr_rgb, 100 * view.metrics.coarser_share,
          e.max_abs, (unsigned long long)e.pixels_beyond,
          (unsigned long long)e.excluded_alpha_edge);
    }
    EXPECT_TRUE(view.failures.empty())
        << name << " view " << view.view << " (" << view.metrics.psnr_rgb << " dB): " << why;
  }
  EXPECT_TRUE(r->passed());
}

TEST(ReferenceRulesBake, MirroredRepeatBoardValidates) {
  REQUIRE_VULKAN();
  bake_and_validate("mirror", box(false, 0),
                    textured(scene::WrapMode::kMirroredRepeat, scene::WrapMode::kMirroredRepeat));
}

TEST(ReferenceRulesBake, ClampToEdgeValidates) {
  REQUIRE_VULKAN();
  bake_and_validate("clamp", box(false, 0),
                    textured(scene::WrapMode::kClampToEdge, scene::WrapMode::kClampToEdge));
}

TEST(ReferenceRulesBake, TextureTransformValidates) {
  REQUIRE_VULKAN();
  scene::Material m = textured(scene::WrapMode::kClampToEdge, scene::WrapMode::kMirroredRepeat);
  bake_and_validate("transform", box(false, 0), m, [](nlohmann::json& doc) {
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = {
        {"KHR_texture_transform",
         {{"offset", {0.1, -0.2}}, {"rotation", 0.3}, {"scale", {1.5, 0.75}}}}};
    doc["extensionsUsed"] = {"KHR_texture_transform"};
  });
}

TEST(ReferenceRulesBake, SecondUvSetValidates) {
  REQUIRE_VULKAN();
  scene::Material m = textured(scene::WrapMode::kMirroredRepeat, scene::WrapMode::kRepeat);
  m.base_color_texture.texcoord = 1;
  bake_and_validate("texcoord1", box(false, 1), m);
}

TEST(ReferenceRulesBake, VertexColoursValidate) {
  REQUIRE_VULKAN();
  bake_and_validate("colors", box(true, 0),
                    textured(scene::WrapMode::kMirroredRepeat, scene::WrapMode::kMirroredRepeat));
}

TEST(ReferenceRulesBake, AlphaMaskValidates) {
  REQUIRE_VULKAN();
  scene::Material m = textured(scene::WrapMode::kMirroredRepeat, scene::WrapMode::kMirroredRepeat);
  m.alpha_mode = scene::AlphaMode::kMask;
  m.alpha_cutoff = 0.5f;
  bake_and_validate("mask", box(false, 0, 1), m);
}

// A blended face whose colour under zero alpha (column 0: blue 255, where the rest is 96) is
// not what the bake keeps there (colour bled from the texels with alpha): invisible, so both
// renders write colour premultiplied and it does not count.
TEST(ReferenceRulesBake, BlendedColourUnderZeroAlphaValidates) {
  REQUIRE_VULKAN();
  scene::Material m = textured(scene::WrapMode::kMirroredRepeat, scene::WrapMode::kMirroredRepeat);
  m.alpha_mode = scene::AlphaMode::kBlend;
  bake_and_validate("blend", box(false, 0, 1), m, {}, [](int x, int y) {
    Texel t = ramp_texel(x, y);
    if (x == 0) t[2] = 255;
    return t;
  });
}

// A closed box with holes: the faces seen through them stream the levels they want only when the
// feedback pass alpha-tests as the colour pass does (without it, 18.8% of the box's pixels
// sampled a coarser level than wanted). Its alpha ramp crosses the cutoff on every face, in front
// of another face: masked fragments a rounding above the cutoff in one render and below in the
// other show different surfaces there, which the exact check must tell from a wrong texel.
TEST(ReferenceRulesBake, ClosedMaskedBoxValidates) {
  REQUIRE_VULKAN();
  scene::Material m = textured(scene::WrapMode::kMirroredRepeat, scene::WrapMode::kMirroredRepeat);
  m.alpha_mode = scene::AlphaMode::kMask;
  m.alpha_cutoff = 0.5f;
  bake_and_validate("mask_box", box(false, 0), m);
}

TEST(ReferenceRulesBake, NearestMagFilterValidates) {
  REQUIRE_VULKAN();
  bake_and_validate(
      "nearest", box(false, 0), textured(scene::WrapMode::kRepeat, scene::WrapMode::kRepeat),
      [](nlohmann::json& doc) {
        for (auto& s : doc["samplers"]) s["magFilter"] = 9728;  // NEAREST
      },
      // Low contrast: the virtual texture filters its atlas linearly, so texel
      // edges are as sharp as the atlas density allows, not as nearest draws them.
      [](int x, int y) {
        return Texel{uint8_t(100 + 8 * x), uint8_t(100 + 8 * y), 96, 255};
      });
}

}  // namespace
}  // namespace vt::render
