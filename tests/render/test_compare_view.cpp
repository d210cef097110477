// compare_view on frames the test paints itself (no Vulkan): which pixels enter the tiles.
#include <gtest/gtest.h>

#include "render/validate.h"

namespace vt::render {
namespace {

constexpr uint32_t kW = 64, kH = 48;

// A grey square [16, 48) x [8, 40) drawn by both renders over an undrawn background.
struct Frames {
  ReferenceFrame reference;
  VirtualFrame virt;
  Frames() {
    for (Rgba8Image* im : {&reference.color, &virt.color}) {
      im->width = kW, im->height = kH;
      im->texels.assign(size_t(kW) * kH * 4, 0);
    }
    reference.covered.assign(size_t(kW) * kH, 0);
    virt.status.assign(size_t(kW) * kH, 0);
    for (uint32_t y = 8; y < 40; ++y)
      for (uint32_t x = 16; x < 48; ++x) {
        set(reference.color, x, y, 128);
        set(virt.color, x, y, 128);
        reference.covered[y * kW + x] = 1;
        virt.status[y * kW + x] = 0x80000000u;
      }
  }
  static void set(Rgba8Image& im, uint32_t x, uint32_t y, uint8_t v) {
    uint8_t* p = &im.texels[(size_t(y) * kW + x) * 4];
    p[0] = p[1] = p[2] = v, p[3] = 255;
  }
};

TEST(CompareView, OutlineIsCappedInTheTilesNotInTheView) {
  Frames f;
  // Every outline pixel of the square 100 steps off, as taps that ran off the surface read.
  for (uint32_t y = 8; y < 40; ++y)
    for (uint32_t x = 16; x < 48; ++x)
      if (x == 16 || x == 47 || y == 8 || y == 39) Frames::set(f.virt.color, x, y, 28);
  auto m = compare_view(f.reference, f.virt);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->pixels, 32u * 32u);
  EXPECT_EQ(m->outline_pixels, 32u * 32u - 28u * 28u);  // the two-pixel ring
  // In the tiles the outline counts 24 steps off, so no tile of it alone falls below 20.5 dB
  // (10 log10(255^2 / 24^2)); the interior is identical.
  EXPECT_GT(m->worst_tile_psnr, 20.5);
  EXPECT_LT(m->worst_tile_psnr, 30.0);
  EXPECT_LT(m->psnr_rgb, 20.0);  // the whole view sees the outline as it is

  // A 4 x 4 patch inside, two pixels from the outline, sinks its tile.
  Frames g;
  for (uint32_t y = 20; y < 24; ++y)
    for (uint32_t x = 18; x < 22; ++x) Frames::set(g.virt.color, x, y, 28);
  m = compare_view(g.reference, g.virt);
  ASSERT_TRUE(m.ok());
  EXPECT_LT(m->worst_tile_psnr, 30.0);
  EXPECT_EQ(m->worst_tile_x, 16u);
  EXPECT_EQ(m->worst_tile_y, 16u);
}

// A pixel whose taps read page border texels counts fully even on the outline (a zeroed
// border shows there first on a small object); a hole only one render drew is no background.
TEST(CompareView, BorderReadsAndOneRenderHolesAreNoOutline) {
  Frames f;
  f.reference.covered[20 * kW + 30] = 0;  // a hole in the reference only
  for (uint32_t y = 10; y < 38; ++y) f.virt.status[y * kW + 16] |= 0x20000000u;
  for (uint32_t x = 18; x < 22; ++x) f.virt.status[8 * kW + x] |= 0x20000000u;
  auto m = compare_view(f.reference, f.virt);
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m->outline_pixels, 32u * 32u - 28u * 28u - 32u);
}

// A silhouette in front of another surface (both renders drew every pixel): a step in the
// reference's depth makes an outline as background does; a shallow one and the interior do not.
TEST(CompareView, DepthStepIsOutlineAShallowOneIsNot) {
  auto frames = [](float square_depth) {
    Frames f;
    f.reference.depth.assign(size_t(kW) * kH, 10.0f);
    for (uint32_t y = 0; y < kH; ++y)
      for (uint32_t x = 0; x < kW; ++x) {
        const size_t i = size_t(y) * kW + x;
        const bool square = x >= 16 && x < 48 && y >= 8 && y < 40;
        if (!square)
          Frames::set(f.reference.color, x, y, 128), Frames::set(f.virt.color, x, y, 128);
        f.reference.covered[i] = 1;
        f.virt.status[i] = 0x80000000u;
        if (square) f.reference.depth[i] = square_depth;
      }
    // The square's edge ring 100 steps off, as taps that ran off the silhouette read.
    for (uint32_t y = 8; y < 40; ++y)
      for (uint32_t x = 16; x < 48; ++x)
        if (x == 16 || x == 47 || y == 8 || y == 39) Frames::set(f.virt.color, x, y, 28);
    return f;
  };
  Frames step = frames(5.0f);  // twice as near as the surface behind
  auto m = compare_view(step.reference, step.virt);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->pixels, size_t(kW) * kH);
  EXPECT_GE(m->outline_pixels, 32u * 32u - 26u * 26u);  // three rings inside, more outside
  EXPECT_GT(m->worst_tile_psnr, 20.5);
  EXPECT_LT(m->psnr_rgb, 25.0);

  Frames shallow = frames(9.8f);  // 2 % nearer: one surface's relief, no silhouette
  m = compare_view(shallow.reference, shallow.virt);
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m->outline_pixels, 0u);
  EXPECT_LT(m->worst_tile_psnr, 20.0);

  // Away from the step, an error counts fully.
  Frames inner = frames(5.0f);
  for (uint32_t y = 8; y < 40; ++y)
    for (uint32_t x = 16; x < 48; ++x) Frames::set(inner.virt.color, x, y, 128);
  for (uint32_t y = 20; y < 24; ++y)
    for (uint32_t x = 20; x < 24; ++x) Frames::set(inner.virt.color, x, y, 28);
  m = compare_view(inner.reference, inner.virt);
  ASSERT_TRUE(m.ok());
  EXPECT_LT(m->worst_tile_psnr, 20.5);  // 20.2 dB; capped, it would read 32.6
  EXPECT_EQ(m->worst_tile_x, 16u);
  EXPECT_EQ(m->worst_tile_y, 16u);
}

}  // namespace
}  // namespace vt::render
