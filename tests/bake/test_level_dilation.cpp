// Banded pull-push (level_dilation.h) against pull_push on the whole level: the same bytes at
// any band height, memory budget (pull levels in memory or scratch files) and level shape.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <vector>

#include "bake/build.h"
#include "bake/level_dilation.h"
#include "bake/level_store.h"
#include "bake/pyramid.h"
#include "tests/transfer/scratch_dir.h"

namespace vt {
namespace {

struct Level {
  uint32_t w, h, ch;
  std::vector<float> texels;
  std::vector<uint8_t> coverage;
};

// Random texels; covered texels in a few rectangles (charts) over an otherwise empty level, so
// that some uncovered texels reach their first covered ancestor only many levels up.
Level random_level(uint32_t w, uint32_t h, uint32_t ch, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(-2.0f, 3.0f);
  Level l{w, h, ch, std::vector<float>(size_t(w) * h * ch), std::vector<uint8_t>(size_t(w) * h)};
  for (float& v : l.texels) v = value(rng);
  for (int r = 0; r < 3; ++r) {
    const uint32_t x0 = uint32_t(rng() % w), y0 = uint32_t(rng() % h);
    const uint32_t x1 = std::min<uint32_t>(w, x0 + 1 + uint32_t(rng() % 5));
    const uint32_t y1 = std::min<uint32_t>(h, y0 + 1 + uint32_t(rng() % 7));
    for (uint32_t y = y0; y < y1; ++y)
      for (uint32_t x = x0; x < x1; ++x) l.coverage[size_t(y) * w + x] = 1;
  }
  return l;
}

std::vector<float> whole(const Level& l) {
  std::vector<float> t = l.texels;
  pull_push(t.data(), l.coverage.data(), l.w, l.h, l.ch);
  return t;
}

std::vector<float> banded(const Level& l, bool in_memory, uint32_t band_rows, uint64_t budget,
                          const std::string& dir, bool compressed = false) {
  auto store = LevelStore::create(l.w, l.h, l.ch, in_memory, dir, compressed);
  EXPECT_TRUE(store.ok());
  EXPECT_TRUE((*store)->write_rows(0, l.h, l.texels.data()).ok());
  BandedDilationOptions o;
  o.memory_budget = budget;
  o.scratch_dir = dir;
  o.band_rows = band_rows;
  auto filled =
      pull_push_banded(**store, *CoverageMask::from_bytes(l.w, l.h, l.coverage.data()), o);
  EXPECT_TRUE(filled.ok()) << filled.status().message();
  std::vector<float> out(l.texels.size());
  EXPECT_TRUE((*store)->read(0, l.h, out.data()).ok());
  return out;
}

TEST(BandedDilation, SameBytesAsWholeLevelPullPush) {
  test::ScratchDir dir;
  const uint32_t shapes[][3] = {{37, 23, 3}, {64, 1, 1},  {1, 45, 4},  {130, 70, 2},
                                {2, 2, 3},   {200, 9, 4}, {33, 129, 3}};
  uint32_t seed = 1;
  for (const auto& s : shapes) {
    const Level l = random_level(s[0], s[1], s[2], seed++);
    const std::vector<float> want = whole(l);
    for (uint32_t rows : {1u, 2u, 7u, 0u}) {
      for (bool in_memory : {true, false}) {
        for (uint64_t budget : {uint64_t(0), uint64_t(1) << 30}) {
          const std::vector<float> got = banded(l, in_memory, rows, budget, dir.file(""));
          ASSERT_EQ(got.size(), want.size());
          EXPECT_EQ(std::memcmp(got.data(), want.data(), want.size() * sizeof(float)), 0)
              << s[0] << "x" << s[1] << "x" << s[2] << " rows " << rows << " memory " << in_memory
              << " budget " << budget;
        }
      }
    }
  }
}

// Pull levels of rows wide enough that scratch pull levels move a few rows per batch (1 row of
// 2.2 MB at level 1, 3 at level 2, ...; a last batch of fewer), raw and compressed.
TEST(BandedDilation, WideScratchPullLevelsInBatchesGiveTheSameBytes) {
  test::ScratchDir dir;
  const Level l = random_level(140000, 26, 3, 3);  // level 2: 7 rows, batches of 3
  const std::vector<float> want = whole(l);
  for (bool compressed : {false, true}) {
    const std::vector<float> got = banded(l, false, 5, 0, dir.file(""), compressed);
    ASSERT_EQ(got.size(), want.size());
    EXPECT_EQ(std::memcmp(got.data(), want.data(), want.size() * sizeof(float)), 0)
        << "compressed " << compressed;
  }
}

TEST(BandedDilation, AllOrNothingCoveredLeavesTheLevel) {
  test::ScratchDir dir;
  for (uint8_t c : {uint8_t(0), uint8_t(1)}) {
    Level l = random_level(19, 11, 3, 7);
    std::fill(l.coverage.begin(), l.coverage.end(), c);
    const std::vector<float> got = banded(l, false, 3, 0, dir.file(""));
    EXPECT_EQ(got, l.texels);
  }
}

TEST(BandedDilation, ScratchLevelStoreDilatesLikeAnInMemoryOne) {
  test::ScratchDir dir;
  const Level l = random_level(41, 27, 3, 11);
  for (bool compressed : {false, true}) {  // (compressed: its pull levels too)
    auto store = LevelStore::create(l.w, l.h, l.ch, false, dir.file(""), compressed);
    ASSERT_TRUE(store.ok());
    ASSERT_TRUE((*store)->write_rows(0, l.h, l.texels.data()).ok());
    ASSERT_TRUE((*store)->set_coverage_and_dilate(l.coverage, 0, dir.file("")).ok());
    std::vector<float> out(l.texels.size());
    ASSERT_TRUE((*store)->read(0, l.h, out.data()).ok());
    EXPECT_EQ(out, whole(l)) << "compressed " << compressed;
    ASSERT_NE((*store)->coverage(), nullptr);
  }
}

// A build of a layer with coverage at a memory limit that puts level 0, every level and the
// coverage masks in scratch files (dilated in bands) writes the bytes of the build that holds
// them in memory, raw or compressed.
TEST(BandedDilation, OutOfCoreCoverageBuildWritesTheSameBytes) {
  test::ScratchDir dir;
  const uint32_t w = 300, h = 250;
  Level l = random_level(w, h, 3, 5);
  for (float& v : l.texels) v = std::fabs(v) / 3.0f;
  for (uint32_t y = 40; y < 200; ++y)
    for (uint32_t x = 10; x < 290; x += 1 + (y % 3)) l.coverage[size_t(y) * w + x] = 1;
  std::vector<char> first;
  // 64 KiB: the masks of levels 0 and 1 in scratch files too (1/64 of the limit is 1 KiB).
  for (int run = 0; run < 5; ++run) {
    const uint64_t limit =
        std::array{uint64_t(2) << 30, uint64_t(1) << 20, uint64_t(64) << 10}[std::min(run, 2)];
    auto coverage = CoverageMask::create(w, h, limit > (1 << 20), dir.file(""));
    ASSERT_TRUE(coverage.ok());
    ASSERT_TRUE((*coverage)->write_rows(0, h, l.coverage.data()).ok());
    BuildOptions o;
    LayerInput in;
    in.source =
        std::make_shared<MemoryImageSource>(ImageInfo{w, h, 3, false, -1, "linear"}, l.texels);
    in.coverage = *coverage;
    o.scratch_dir = dir.file("");
    o.layers.push_back(in);
    o.payload = 56;
    o.memory_limit = limit;
    o.compress_scratch = run >= 3;
    o.output = dir.file("out" + std::to_string(run) + ".vtpf");
    auto built = build_page_file(o);
    ASSERT_TRUE(built.ok()) << built.status().message();
    if (limit < (uint64_t(1) << 30)) {
      EXPECT_TRUE(built->levels[1].scratch);
      EXPECT_LT(built->level_memory_bytes, uint64_t(1) << 20);
    }
    std::ifstream f(o.output, std::ios::binary);
    std::vector<char> bytes{std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
    if (first.empty())
      first = bytes;
    else
      EXPECT_TRUE(bytes == first);
  }
}

}  // namespace
}  // namespace vt
