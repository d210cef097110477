// The lit reference follows the bake's material rules (scene/material_rules.h) for every texture,
// not only the base colour: each slot's own texCoord, KHR_texture_transform and per-axis sampler.
// A screen quad with an occlusion texture on TEXCOORD_1 (CLAMP_TO_EDGE across, MIRRORED_REPEAT
// down) is lit by ambient light alone, so each pixel shows the occlusion it read; a transformed
// normal map's UVs are checked on the CPU. Skips the render where no Vulkan device exists.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "common/srgb.h"
#include "render/lit_pass.h"
#include "render/renderer.h"
#include "render/scene_draws.h"
#include "render/vulkan_context.h"
#include "scene/material_rules.h"
#include "scene/scene.h"
#include "tests/process_temp_dir.h"
#include "tests/render/one_primitive_scene.h"
#include "tests/render/png_file.h"

namespace vt::render {
namespace {

constexpr uint32_t kSize = 64;  // render, pixels per side
constexpr int kTexels = 8;      // occlusion texture side

std::string test_dir(const std::string& name) {
  auto d = test::process_temp_dir("vt_lit_rules") / name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d.string();
}

// 2x2-texel cells of one grey each (a bilinear tap near a cell's centre reads that cell alone).
uint8_t occlusion_cell(int x, int y) {
  return uint8_t(30 + 25 * (x / 2) + 50 * (y / 2));
}

std::string write_occlusion_png(const std::string& dir) {
  const std::string path = dir + "/occlusion.png";
  std::vector<uint8_t> px;
  for (int y = 0; y < kTexels; ++y)
    for (int x = 0; x < kTexels; ++x) px.push_back(occlusion_cell(x, y));
  return write_png_file(path, kTexels, kTexels, 1, px) ? path : "";
}

// A quad over the whole clip space: TEXCOORD_0 spans 0..1, TEXCOORD_1 spans (u0, v0) + 0..span.
scene::Primitive screen_quad(double u0, double v0, double span) {
  scene::Primitive p;
  p.positions = {{-1, -1, 0.5f}, {1, -1, 0.5f}, {1, 1, 0.5f}, {-1, 1, 0.5f}};
  p.uvs.assign(2, std::vector<scene::Vec2>(4));
  for (size_t v = 0; v < 4; ++v) {
    const float s = (p.positions[v][0] + 1) / 2, t = (p.positions[v][1] + 1) / 2;
    p.uvs[0][v] = {s, t};
    p.uvs[1][v] = {float(u0 + s * span), float(v0 + t * span)};
  }
  p.indices = {0, 1, 2, 0, 2, 3};
  return p;
}

scene::Scene quad_scene(const scene::Material& m, const std::string& png) {
  return one_primitive_scene(screen_quad(-0.5, -0.5, 2.0), m, png);
}

TEST(LitReferenceRules, EachTextureReadsItsOwnUvSetAndTransform) {
  scene::Scene sc = quad_scene(scene::Material{}, "unused.png");
  scene::Material& m = sc.materials[0];
  m.occlusion_texture.image = 0;
  m.occlusion_texture.texcoord = 1;
  m.normal_texture.image = 0;
  m.normal_texture.transform.offset = {0.25f, -0.5f};
  m.normal_texture.transform.scale = {2.0f, 0.5f};
  m.emissive_texture.image = 0;
  m.emissive_texture.texcoord = 1;
  m.emissive_texture.transform.rotation = 0.5f;
  auto draws = reference_scene_draws(sc);  // no base colour image: nothing to read
  ASSERT_TRUE(draws.ok()) << draws.status().message();
  ASSERT_TRUE(add_shading_frames(sc, *draws, true).ok());
  const scene::Primitive& p = sc.meshes[0].primitives[0];
  const std::vector<Vertex>& v = draws->meshes[0].vertices;
  for (size_t i = 0; i < v.size(); ++i) {
    const auto n = scene::texture_uv(m.normal_texture, p.uvs[0][i][0], p.uvs[0][i][1]);
    EXPECT_FLOAT_EQ(v[i].tex_uv[kLitNormalUv][0], float(n[0])) << i;
    EXPECT_FLOAT_EQ(v[i].tex_uv[kLitNormalUv][1], float(n[1])) << i;
    EXPECT_FLOAT_EQ(v[i].tex_uv[kLitOcclusionUv][0], p.uvs[1][i][0]) << i;
    EXPECT_FLOAT_EQ(v[i].tex_uv[kLitOcclusionUv][1], p.uvs[1][i][1]) << i;
    const auto e = scene::texture_uv(m.emissive_texture, p.uvs[1][i][0], p.uvs[1][i][1]);
    EXPECT_FLOAT_EQ(v[i].tex_uv[kLitEmissiveUv][0], float(e[0])) << i;
    EXPECT_FLOAT_EQ(v[i].tex_uv[kLitEmissiveUv][1], float(e[1])) << i;
    EXPECT_FLOAT_EQ(v[i].tex_uv[kLitMetalRoughUv][0], 0.0f) << i;  // no such texture
  }
}

TEST(LitReferenceRules, OcclusionOnSecondUvSetWithPerAxisSampler) {
  auto ctx = VulkanContext::create();
  if (!ctx.ok()) GTEST_SKIP() << "no Vulkan device: " << ctx.status().message();
  const std::string png = write_occlusion_png(test_dir("occlusion"));
  ASSERT_FALSE(png.empty());
  scene::Material mat;
  mat.metallic_factor = 0;
  mat.occlusion_texture.image = 0;
  mat.occlusion_texture.texcoord = 1;
  mat.occlusion_texture.wrap_s = scene::WrapMode::kClampToEdge;
  mat.occlusion_texture.wrap_t = scene::WrapMode::kMirroredRepeat;
  const scene::Scene sc = quad_scene(mat, png);
  auto draws = reference_scene_draws(sc);
  ASSERT_TRUE(draws.ok()) << draws.status().message();
  ASSERT_TRUE(add_shading_frames(sc, *draws, true).ok());
  auto materials = lit_materials(sc);
  ASSERT_TRUE(materials.ok()) << materials.status().message();
  RenderOptions o;
  o.width = o.height = kSize;
  auto renderer = Renderer::create(**ctx, o);
  ASSERT_TRUE(renderer.ok()) << renderer.status().message();
  ASSERT_TRUE((*renderer)->set_meshes(draws->meshes).ok());
  ASSERT_TRUE((*renderer)->set_reference_textures(draws->textures).ok());
  ASSERT_TRUE((*renderer)->set_lit_materials(*materials).ok());
  // Ambient alone: a white, non-metallic surface shows occlusion x (diffuse 1 + F0 0.04).
  LitFrameOptions lights;
  lights.key = lights.fill = 0;
  lights.ambient = 1;
  lights.inputs = 1u << uint32_t(LitInput::kOrm);
  auto frame = (*renderer)->render_lit_reference(Camera{}, lights);
  ASSERT_TRUE(frame.ok()) << frame.status().message();
  int compared = 0;
  for (uint32_t py = 0; py < kSize; ++py)
    for (uint32_t px = 0; px < kSize; ++px) {
      // TEXCOORD_1 at the pixel centre, addressed per axis.
      const double u = -0.5 + (px + 0.5) / kSize * 2.0, v = -0.5 + (py + 0.5) / kSize * 2.0;
      const double s = scene::wrap_coordinate(mat.occlusion_texture.wrap_s, u) * kTexels;
      const double t = scene::wrap_coordinate(mat.occlusion_texture.wrap_t, v) * kTexels;
      auto near_centre = [](double x) {
        return std::abs(x - (2.0 * std::floor(x / 2.0) + 1.0)) <= 0.3 || x < 0.5 ||
               x > kTexels - 0.5;
      };
      if (!near_centre(s) || !near_centre(t)) continue;
      const int tx = std::min(kTexels - 1, int(s)), ty = std::min(kTexels - 1, int(t));
      const float occ = occlusion_cell(tx, ty) / 255.0f * 1.04f;  // diffuse 1 + F0 0.04
      const int want = int(std::lround(linear_to_srgb(std::min(1.0f, occ)) * 255.0f));
      const size_t i = size_t(py) * kSize + px;
      ++compared;
      EXPECT_NEAR(frame->color.texels[i * 4], want, 3)
          << "pixel " << px << "," << py << " at occlusion texel " << tx << "," << ty;
    }
  EXPECT_GT(compared, 400);
}

}  // namespace
}  // namespace vt::render
