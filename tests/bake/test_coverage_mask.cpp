// The 1-bit coverage mask (bake/coverage_mask.h), in memory and in scratch files, against the
// whole-level byte functions it replaced in the build: the same rows, the same half-size levels,
// the same present pages and the same plan-hash part.
#include <gtest/gtest.h>
#include <xxhash.h>

#include <random>
#include <vector>

#include "bake/coverage_mask.h"
#include "bake/paging.h"
#include "bake/pyramid.h"
#include "tests/transfer/scratch_dir.h"

namespace vt {
namespace {

// Charts as rectangles of covered texels (some crossing every band and word edge) plus specks.
std::vector<uint8_t> random_coverage(uint32_t w, uint32_t h, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<uint8_t> c(size_t(w) * h, 0);
  for (int r = 0; r < 4; ++r) {
    const uint32_t x0 = uint32_t(rng() % w), y0 = uint32_t(rng() % h);
    const uint32_t x1 = std::min(w, x0 + 1 + uint32_t(rng() % 40));
    const uint32_t y1 = std::min(h, y0 + 1 + uint32_t(rng() % 40));
    for (uint32_t y = y0; y < y1; ++y)
      for (uint32_t x = x0; x < x1; ++x) c[size_t(y) * w + x] = 1;
  }
  for (int k = 0; k < 30; ++k) c[rng() % c.size()] = uint8_t(1 + rng() % 255);  // any non-zero
  return c;
}

std::vector<uint8_t> as_01(std::vector<uint8_t> c) {
  for (uint8_t& v : c) v = v ? 1 : 0;
  return c;
}

const uint32_t kShapes[][2] = {{1, 1}, {31, 3}, {32, 32}, {33, 17}, {77, 53}, {130, 1}, {1, 90}};

TEST(CoverageMask, RowsRoundTripInMemoryAndInScratchFiles) {
  test::ScratchDir dir;
  uint32_t seed = 1;
  for (const auto& s : kShapes) {
    const std::vector<uint8_t> bytes = random_coverage(s[0], s[1], seed++);
    for (bool in_memory : {true, false}) {
      auto mask = CoverageMask::create(s[0], s[1], in_memory, dir.file(""));
      ASSERT_TRUE(mask.ok()) << mask.status().message();
      EXPECT_EQ((*mask)->in_memory(), in_memory);
      EXPECT_EQ(*(*mask)->to_bytes(), std::vector<uint8_t>(bytes.size(), 0));  // created empty
      // Written in uneven bands, read back in others.
      for (uint32_t y = 0; y < s[1]; y += 3)
        ASSERT_TRUE(
            (*mask)->write_rows(y, std::min(3u, s[1] - y), bytes.data() + size_t(y) * s[0]).ok());
      EXPECT_EQ(*(*mask)->to_bytes(), as_01(bytes)) << s[0] << "x" << s[1];
      std::vector<uint8_t> rows;
      ASSERT_TRUE((*mask)->read_rows(s[1] / 2, s[1], rows).ok());
      EXPECT_TRUE(
          std::equal(rows.begin(), rows.end(), as_01(bytes).begin() + size_t(s[1] / 2) * s[0]));
    }
  }
}

TEST(CoverageMask, HalfLevelsAreDownsampleCoverageDownToOneTexel) {
  test::ScratchDir dir;
  uint32_t seed = 10;
  for (const auto& s : kShapes) {
    std::vector<uint8_t> want = as_01(random_coverage(s[0], s[1], seed++));
    for (bool in_memory : {true, false}) {
      std::shared_ptr<const CoverageMask> mask = CoverageMask::from_bytes(s[0], s[1], want.data());
      std::vector<uint8_t> level = want;
      uint32_t w = s[0], h = s[1];
      while (w > 1 || h > 1) {
        level = downsample_coverage(level.data(), w, h);
        w = (w + 1) / 2, h = (h + 1) / 2;
        auto half = mask->downsample(in_memory, dir.file(""));
        ASSERT_TRUE(half.ok()) << half.status().message();
        ASSERT_EQ((*half)->width(), w);
        ASSERT_EQ((*half)->height(), h);
        EXPECT_EQ(*(*half)->to_bytes(), level) << s[0] << "x" << s[1] << " at " << w << "x" << h;
        mask = *half;
      }
    }
  }
}

TEST(CoverageMask, PresentPagesAndHashAreThoseOfTheBytes) {
  test::ScratchDir dir;
  PageGeometry g;
  g.payload = 8, g.border = 4, g.width = 77, g.height = 53;
  const std::vector<uint8_t> bytes = random_coverage(g.width, g.height, 99);
  auto mask = CoverageMask::create(g.width, g.height, false, dir.file(""));
  ASSERT_TRUE(mask.ok());
  ASSERT_TRUE((*mask)->write_rows(0, g.height, bytes.data()).ok());
  uint32_t present = 0;
  for (uint32_t y = 0; y < g.pages_y(0); ++y) {
    auto row = pages_with_coverage(g, 0, y, **mask);
    ASSERT_TRUE(row.ok());
    ASSERT_EQ(row->size(), g.pages_x(0));
    for (uint32_t x = 0; x < g.pages_x(0); ++x) {
      EXPECT_EQ((*row)[x] != 0, page_has_coverage(g, PageId{0, x, y}, bytes.data()))
          << x << "," << y;
      present += (*row)[x];
    }
  }
  EXPECT_GT(present, 0u);
  EXPECT_LT(present, g.pages_x(0) * g.pages_y(0));
  std::vector<uint8_t> b01 = as_01(bytes);
  EXPECT_EQ(*(*mask)->content_hash(), XXH3_64bits(b01.data(), b01.size()));
  // The hash is kept between writes, not past one.
  b01[size_t(g.height / 2) * g.width + 5] ^= 1;
  ASSERT_TRUE((*mask)->write_rows(g.height / 2, 1, &b01[size_t(g.height / 2) * g.width]).ok());
  EXPECT_EQ(*(*mask)->content_hash(), XXH3_64bits(b01.data(), b01.size()));
}

TEST(CoverageMask, OneBitPerTexelAndAShareOfTheLimitInMemory) {
  EXPECT_EQ(CoverageMask::packed_bytes(65536, 65536), uint64_t(512) << 20);
  EXPECT_EQ(CoverageMask::packed_bytes(33, 2), 16u);  // rows of whole 32-bit words
  const uint64_t limit = uint64_t(2) << 30;
  EXPECT_TRUE(CoverageMask::fits_memory(16384, 16384, limit));
  EXPECT_FALSE(CoverageMask::fits_memory(16385, 16384, limit));
  // At 65,536^2 only levels of 16,384^2 and below stay in memory: 32 MiB and a third more.
  EXPECT_EQ(CoverageMask::pyramid_memory_bytes(65536, 65536, limit),
            CoverageMask::pyramid_memory_bytes(16384, 16384, limit));
  EXPECT_LE(CoverageMask::pyramid_memory_bytes(65536, 65536, limit), limit / 48 + 4096);
}

}  // namespace
}  // namespace vt
