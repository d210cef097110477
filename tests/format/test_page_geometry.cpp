// Page geometry: level sizes and grids against a direct computation, validation bounds, Morton.
#include <gtest/gtest.h>

#include <random>

#include "format/page_geometry.h"

namespace vt {
namespace {

uint64_t ceil_div(uint64_t a, uint64_t b) {
  return (a + b - 1) / b;
}

TEST(PageGeometry, DefaultLevelsAndGrids) {
  PageGeometry g{1000, 500, 120, 4};
  ASSERT_TRUE(g.validate().ok());
  EXPECT_EQ(g.page_size(), 128u);
  // 9x5 -> 5x3 -> 3x2 -> 2x1 -> 1x1
  ASSERT_EQ(g.level_count(), 5u);
  const uint32_t px[] = {9, 5, 3, 2, 1}, py[] = {5, 3, 2, 1, 1};
  const uint32_t w[] = {1000, 500, 250, 125, 63}, h[] = {500, 250, 125, 63, 32};
  uint64_t total = 0;
  for (uint32_t l = 0; l < 5; ++l) {
    EXPECT_EQ(g.pages_x(l), px[l]) << l;
    EXPECT_EQ(g.pages_y(l), py[l]) << l;
    EXPECT_EQ(g.level_width(l), w[l]) << l;
    EXPECT_EQ(g.level_height(l), h[l]) << l;
    total += uint64_t(px[l]) * py[l];
  }
  EXPECT_EQ(g.total_pages(), total);
  EXPECT_TRUE(g.contains({4, 0, 0}));
  EXPECT_FALSE(g.contains({5, 0, 0}));
  EXPECT_FALSE(g.contains({0, 9, 0}));
  EXPECT_FALSE(g.contains({0, 0, 5}));
}

TEST(PageGeometry, GridsMatchLevelSizesForManyShapes) {
  std::mt19937 rng(7);
  for (int i = 0; i < 2000; ++i) {
    PageGeometry g;
    g.width = 1 + rng() % 5000;
    g.height = 1 + rng() % 5000;
    g.border = rng() % 5;
    g.payload = 4 + rng() % 200;
    while ((g.payload + 2 * g.border) % 4) ++g.payload;
    ASSERT_TRUE(g.validate().ok());
    const uint32_t levels = g.level_count();
    for (uint32_t l = 0; l < levels; ++l) {
      // Nested ceilings agree: the level image always fits its page grid exactly.
      EXPECT_EQ(g.level_width(l), std::max<uint64_t>(1, ceil_div(g.width, uint64_t(1) << l)));
      EXPECT_EQ(g.pages_x(l), ceil_div(g.level_width(l), g.payload));
      EXPECT_EQ(g.pages_y(l), ceil_div(g.level_height(l), g.payload));
    }
    EXPECT_EQ(g.pages_in_level(levels - 1), 1u);
    if (levels > 1) {
      EXPECT_GT(g.pages_in_level(levels - 2), 1u);
    }
  }
}

TEST(PageGeometry, SinglePage) {
  PageGeometry g{1, 1, 8, 2};
  ASSERT_TRUE(g.validate().ok());
  EXPECT_EQ(g.level_count(), 1u);
  EXPECT_EQ(g.total_pages(), 1u);
  EXPECT_EQ(g.page_origin_x({0, 0, 0}), -2);
  PageGeometry h{120, 1, 120, 4};
  EXPECT_EQ(h.level_count(), 1u);
  PageGeometry k{121, 1, 120, 4};
  EXPECT_EQ(k.level_count(), 2u);
  EXPECT_EQ(k.page_origin_x({0, 1, 0}), 116);
}

TEST(PageGeometry, ValidateRejects) {
  EXPECT_FALSE((PageGeometry{0, 10, 120, 4}).validate().ok());
  EXPECT_FALSE((PageGeometry{10, 0, 120, 4}).validate().ok());
  EXPECT_FALSE((PageGeometry{10, 10, 0, 2}).validate().ok());
  EXPECT_FALSE((PageGeometry{10, 10, 121, 4}).validate().ok());  // 129 not a multiple of 4
  EXPECT_FALSE((PageGeometry{(1u << 24) + 1, 10, 120, 4}).validate().ok());
  EXPECT_TRUE((PageGeometry{1u << 24, 16, 120, 4}).validate().ok());
  EXPECT_FALSE((PageGeometry{1u << 24, 1u << 24, 120, 4}).validate().ok());  // 1.9e10 pages
  EXPECT_FALSE((PageGeometry{1u << 24, 1u << 24, 2, 1}).validate().ok());    // 2^46 pages
  EXPECT_FALSE((PageGeometry{100, 100, 8000, 4}).validate().ok());
  EXPECT_FALSE((PageGeometry{100, 100, 8, 0xFFFFFFFFu}).validate().ok());
  EXPECT_EQ((PageGeometry{0, 10, 120, 4}).validate().code(), ErrorCode::kInvalidArgument);
}

TEST(PageGeometry, LargestGeometryDoesNotOverflow) {
  PageGeometry g{1u << 24, 1u << 24, 2044, 2};
  ASSERT_TRUE(g.validate().ok());
  EXPECT_EQ(g.pages_x(0), 8209u);
  EXPECT_EQ(g.level_count(), 15u);
  EXPECT_EQ(g.level_width(30), 1u);
  EXPECT_EQ(g.pages_x(40), 1u);
}

TEST(PageGeometry, AddressTexel) {
  EXPECT_EQ(address_texel(-1, 10, AddressMode::kClamp), 0);
  EXPECT_EQ(address_texel(12, 10, AddressMode::kClamp), 9);
  EXPECT_EQ(address_texel(-1, 10, AddressMode::kWrap), 9);
  EXPECT_EQ(address_texel(-11, 10, AddressMode::kWrap), 9);
  EXPECT_EQ(address_texel(12, 10, AddressMode::kWrap), 2);
}

TEST(PageId, KeyAndName) {
  EXPECT_EQ(page_name({2, 3, 1}), "page (2, 3, 1)");
  EXPECT_EQ(page_name({0, 4095, 17}, 3), "page (0, 4095, 17) layer 3");
  // Keys are distinct for every page of the largest grids (x, y < 2^24, levels < 2^16).
  const PageId ids[] = {
      {0, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 0}, {0, (1u << 24) - 1, 0}, {0, 0, (1u << 24) - 1},
      {24, 0, 0}};
  for (const PageId& a : ids)
    for (const PageId& b : ids) EXPECT_EQ(page_key(a) == page_key(b), a == b);
}

TEST(Morton, KnownCodes) {
  EXPECT_EQ(morton_encode(0, 0), 0u);
  EXPECT_EQ(morton_encode(1, 0), 1u);
  EXPECT_EQ(morton_encode(0, 1), 2u);
  EXPECT_EQ(morton_encode(3, 0), 5u);
  EXPECT_EQ(morton_encode(2, 3), 0b1110u);
  EXPECT_EQ(morton_encode(0xFFFFFFFFu, 0), 0x5555555555555555ull);
  EXPECT_EQ(morton_encode(0xFFFFFFFFu, 0xFFFFFFFFu), ~0ull);
}

TEST(Morton, RoundTrip) {
  std::mt19937_64 rng(11);
  for (int i = 0; i < 100000; ++i) {
    uint32_t x = uint32_t(rng()), y = uint32_t(rng() >> 32), dx, dy;
    morton_decode(morton_encode(x, y), &dx, &dy);
    ASSERT_EQ(dx, x);
    ASSERT_EQ(dy, y);
  }
  for (uint64_t c = 0; c < 4096; ++c) {
    uint32_t x, y;
    morton_decode(c, &x, &y);
    ASSERT_EQ(morton_encode(x, y), c);
  }
}

}  // namespace
}  // namespace vt
