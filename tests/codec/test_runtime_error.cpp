// The error after the runtime BC format: exact where BC is exact, the stored BC blocks used as
// they are, angles for normal maps, and sums over pages.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "codec/runtime_error.h"

namespace vt {
namespace {

constexpr int kSize = 16;

TEST(RuntimeError, BlackAndWhiteBlocksAreExactInBc1) {
  std::vector<uint8_t> page(size_t(kSize) * kSize * 3);
  for (size_t i = 0; i < page.size(); ++i) page[i] = (i / 3 / 4) % 2 ? 255 : 0;
  RuntimeError e;
  ASSERT_TRUE(
      measure_runtime_error(BcFormat::kBc1, false, page.data(), page.data(), nullptr, kSize, 3, e)
          .ok());
  EXPECT_EQ(e.samples, uint64_t(kSize) * kSize * 3);
  EXPECT_EQ(e.squared_error, 0);
  EXPECT_TRUE(std::isinf(e.psnr_db()));
}

TEST(RuntimeError, MeasuresAgainstTheSourceNotTheStoredTexels) {
  std::vector<uint8_t> source(size_t(kSize) * kSize * 3, 0), stored = source;
  stored[0] = 255;  // the stored codec's error, which BC keeps or smears
  RuntimeError e;
  ASSERT_TRUE(measure_runtime_error(BcFormat::kBc1, false, source.data(), stored.data(), nullptr,
                                    kSize, 3, e)
                  .ok());
  EXPECT_GT(e.squared_error, 0);
  EXPECT_GT(e.max_error, 0u);
}

TEST(RuntimeError, AnUnclippedReferenceCountsWhatClippingLost) {
  // White stored (exact in BC1) where the source was brighter: code 400 before clipping.
  std::vector<uint8_t> page(size_t(kSize) * kSize * 3, 255);
  std::vector<float> reference(page.size(), 255.0f);
  reference[0] = 400.0f;
  RuntimeError e;
  ASSERT_TRUE(measure_runtime_error(BcFormat::kBc1, false, page.data(), page.data(), nullptr, kSize,
                                    3, e, reference.data())
                  .ok());
  EXPECT_EQ(e.squared_error, 145.0 * 145.0);
  EXPECT_EQ(e.max_error, 145u);
  EXPECT_EQ(e.samples, uint64_t(kSize) * kSize * 3);
}

TEST(RuntimeError, StoredBlocksAreUsedAsTheyAre) {
  std::vector<uint8_t> page(size_t(kSize) * kSize * 3, 0);
  // Blocks that decode to white everywhere: c0 = c1 = 0xFFFF, indices 0.
  std::vector<uint8_t> blocks(bc_image_bytes(BcFormat::kBc1, kSize, kSize), 0);
  for (size_t b = 0; b < blocks.size(); b += 8)
    blocks[b] = blocks[b + 1] = blocks[b + 2] = blocks[b + 3] = 0xFF;
  RuntimeError e;
  ASSERT_TRUE(measure_runtime_error(BcFormat::kBc1, false, page.data(), page.data(), blocks.data(),
                                    kSize, 3, e)
                  .ok());
  EXPECT_EQ(e.max_error, 255u);
  EXPECT_NEAR(e.psnr_db(), 0.0, 1e-9);
}

TEST(RuntimeError, NormalAnglesAndSums) {
  std::vector<uint8_t> flat(size_t(kSize) * kSize * 2, 128), tilted = flat;
  RuntimeError a;
  ASSERT_TRUE(
      measure_runtime_error(BcFormat::kBc5, true, flat.data(), flat.data(), nullptr, kSize, 2, a)
          .ok());
  EXPECT_EQ(a.normals, uint64_t(kSize) * kSize);
  EXPECT_LT(a.angle_max_deg, 0.5);
  // Landed normals tilted by the stored codec: x = 0.5 is 30 degrees off the flat source.
  for (size_t i = 0; i < tilted.size(); i += 2) tilted[i] = 191;
  RuntimeError b;
  ASSERT_TRUE(
      measure_runtime_error(BcFormat::kBc5, true, flat.data(), tilted.data(), nullptr, kSize, 2, b)
          .ok());
  EXPECT_NEAR(b.angle_mean_deg(), 30.0, 0.5);
  EXPECT_NEAR(b.angle_p99_deg(), 30.0, 0.5);
  RuntimeError sum = a;
  sum.add(b);
  EXPECT_EQ(sum.normals, 2 * uint64_t(kSize) * kSize);
  EXPECT_NEAR(sum.angle_mean_deg(), (a.angle_mean_deg() + b.angle_mean_deg()) / 2, 1e-9);
  EXPECT_DOUBLE_EQ(sum.angle_max_deg, b.angle_max_deg);
  EXPECT_NEAR(sum.angle_p99_deg(), 30.0, 0.5);
}

}  // namespace
}  // namespace vt
