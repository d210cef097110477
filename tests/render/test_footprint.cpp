// The validation passes' anisotropic footprint (render/shaders/common.glsl) where a UV mapping
// shears: the pixel's derivatives point nearly the same way, as a sphere map's do near its pole
// or the squeezed UVs of Collada/teapots.DAE's spout. The reference render of a screen-filling
// quad is checked against the mean of point samples over each pixel, computed here. Skips
// cleanly where no Vulkan device exists.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "render/renderer.h"
#include "render/scene_draws.h"
#include "render/vulkan_context.h"
#include "scene/scene.h"
#include "tests/process_temp_dir.h"
#include "tests/render/one_primitive_scene.h"
#include "tests/render/png_file.h"

namespace vt::render {
namespace {

constexpr uint32_t kSize = 64;  // render, pixels per side
constexpr int kTexels = 64;     // texture side
constexpr double kPi = 3.14159265358979;

VulkanContext* vulkan() {
  static Expected<std::unique_ptr<VulkanContext>> ctx = VulkanContext::create();
  return ctx.ok() ? ctx->get() : nullptr;
}

// Rows of grey that vary along t only, with a 16-texel period.
uint8_t row_code(int y) {
  return uint8_t(std::lround(128 + 100 * std::sin(2 * kPi * (y + 0.5) / 16)));
}

std::string write_rows_png(const std::string& dir) {
  const std::string path = dir + "/rows.png";
  std::vector<uint8_t> px;
  for (int y = 0; y < kTexels; ++y)
    for (int x = 0; x < kTexels; ++x) px.insert(px.end(), {row_code(y), row_code(y), 96, 255});
  return write_png_file(path, kTexels, kTexels, 4, px) ? path : "";
}

// Texel rows per pixel: d(s, t)/dx = (16, 1) and d(s, t)/dy = (16, 2) texels. The footprint is
// 22.6 texels long, 0.7 wide; over it t spans +-1.5 texels.
constexpr double kDsDx = 16, kDtDx = 1, kDsDy = 16, kDtDy = 2;

// The quad over the whole clip space (identity camera): pixel (px, py) at texel position
// (kDsDx px + kDsDy py, kDtDx px + kDtDy py), pixel row 0 at clip y = -1.
scene::Primitive sheared_quad() {
  scene::Primitive p;
  p.positions = {{-1, -1, 0.5f}, {1, -1, 0.5f}, {1, 1, 0.5f}, {-1, 1, 0.5f}};
  p.uvs.assign(1, std::vector<scene::Vec2>(4));
  for (size_t v = 0; v < 4; ++v) {
    const double x = (p.positions[v][0] + 1) / 2 * kSize, y = (p.positions[v][1] + 1) / 2 * kSize;
    p.uvs[0][v] = {float((kDsDx * x + kDsDy * y) / kTexels),
                   float((kDtDx * x + kDtDy * y) / kTexels)};
  }
  p.indices = {0, 1, 2, 0, 2, 3};
  return p;
}

// Bilinear between the rows' codes at texel row position t (repeat wrap).
double rows_at(double t) {
  const double y = t - 0.5, y0 = std::floor(y), f = y - y0;
  auto code = [](double r) {
    return double(row_code(int(((int64_t(r) % kTexels) + kTexels) % kTexels)));
  };
  return code(y0) + f * (code(y0 + 1) - code(y0));
}

// Measured: the footprint's axes taken as the derivatives' lengths (16.0 and 16.1 texels) read
// 2 taps at LOD 4, which averaged the 16-texel rows away: worst pixel 94.7 codes off, RMS 67.7.
// With the ellipse's axes (16 taps at LOD 0.5): worst 2.7, RMS 2.0.
TEST(Footprint, ShearedMappingKeepsItsNarrowAxisSharp) {
  if (!vulkan()) GTEST_SKIP() << "no Vulkan device";
  const auto dir = test::process_temp_dir("vt_footprint");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string png = write_rows_png(dir.string());
  ASSERT_FALSE(png.empty());
  scene::Material m;
  m.name = "m";
  m.base_color_texture.image = 0;
  m.metallic_factor = 0;
  const scene::Scene sc = one_primitive_scene(sheared_quad(), m, png);
  auto draws = reference_scene_draws(sc);
  ASSERT_TRUE(draws.ok()) << draws.status().message();
  RenderOptions o;
  o.width = o.height = kSize;
  auto renderer = Renderer::create(*vulkan(), o);
  ASSERT_TRUE(renderer.ok()) << renderer.status().message();
  ASSERT_TRUE((*renderer)->set_meshes(draws->meshes).ok());
  ASSERT_TRUE((*renderer)->set_reference_textures(draws->textures).ok());
  auto f = (*renderer)->render_reference(Camera{});
  ASSERT_TRUE(f.ok()) << f.status().message();
  double worst = 0, sum2 = 0, contrast = 0;
  int n = 0;
  for (uint32_t py = 0; py < kSize; ++py)
    for (uint32_t px = 0; px < kSize; ++px) {
      const size_t i = size_t(py) * kSize + px;
      ASSERT_EQ(f->covered[i] & 1u, 1u);
      // The pixel's mean: point samples over its square (the rows vary along t alone).
      constexpr int kGrid = 32;
      double mean = 0;
      for (int a = 0; a < kGrid; ++a)
        for (int b = 0; b < kGrid; ++b) {
          const double x = px + (a + 0.5) / kGrid, y = py + (b + 0.5) / kGrid;
          mean += rows_at(kDtDx * x + kDtDy * y);
        }
      mean /= kGrid * kGrid;
      const double e = std::abs(f->color.texels[i * 4] - mean);
      worst = std::max(worst, e), sum2 += e * e, ++n;
      contrast = std::max(contrast, std::abs(mean - 128));
    }
  const double rms = std::sqrt(sum2 / n);
  std::printf("sheared footprint: worst %.1f codes, RMS %.2f, contrast %.1f\n", worst, rms,
              contrast);
  EXPECT_GT(contrast, 80);  // the pixels' means keep the rows' contrast
  EXPECT_LT(worst, 8);
  EXPECT_LT(rms, 4);
}

}  // namespace
}  // namespace vt::render
