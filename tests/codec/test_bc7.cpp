// BC7: the decoder against hand-computed blocks, robustness on arbitrary bytes, and the encoder's
// measured error bounds on opaque and alpha content at every level.
#include <gtest/gtest.h>

#include <cstring>
#include <set>
#include <vector>

#include "codec/bc.h"
#include "codec/bc7.h"
#include "tests/codec/test_bc_images.h"

namespace vt {
namespace {

using test::Rng;

constexpr BcQuality kLevels[] = {BcQuality::kRealtime, BcQuality::kNormal, BcQuality::kHigh};
constexpr int kWeights4[16] = {0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64};

struct Bits {
  uint8_t data[16] = {};
  int pos = 0;
  void put(int v, int n) {
    for (int i = 0; i < n; ++i, ++pos) data[pos >> 3] |= uint8_t(((v >> i) & 1) << (pos & 7));
  }
};

TEST(Bc7Decode, Mode6HandBuiltBlock) {
  Bits b;
  b.put(1 << 6, 7);              // mode 6
  b.put(0, 7), b.put(127, 7);    // R0, R1
  b.put(64, 7), b.put(64, 7);    // G0, G1
  b.put(10, 7), b.put(20, 7);    // B0, B1
  b.put(127, 7), b.put(127, 7);  // A0, A1
  b.put(0, 1), b.put(1, 1);      // p-bits
  b.put(0, 3);                   // texel 0: anchor, 3 bits
  for (int i = 1; i < 16; ++i) b.put(i, 4);
  ASSERT_EQ(b.pos, 128);
  EXPECT_EQ(bc7_block_mode(b.data), 6);
  uint8_t rgba[64];
  bc7_decode_block(b.data, rgba);
  // Endpoints with p-bits: R 0 / 255, G 128 / 129, B 20 / 41, A 254 / 255.
  const int e0[4] = {0, 128, 20, 254}, e1[4] = {255, 129, 41, 255};
  for (int i = 0; i < 16; ++i) {
    const int w = kWeights4[i];
    for (int c = 0; c < 4; ++c) {
      EXPECT_EQ(rgba[4 * i + c], ((64 - w) * e0[c] + w * e1[c] + 32) >> 6) << i << " " << c;
    }
  }
  EXPECT_EQ(rgba[4 * 15], 255);
  EXPECT_EQ(rgba[4 * 7], ((64 - 30) * 0 + 30 * 255 + 32) >> 6);  // 120
}

TEST(Bc7Decode, Mode1TwoSubsetsSharedPbits) {
  // Partition 13 (0xff00): texels 8..15 in subset 1, whose anchor is texel 15.
  Bits b;
  b.put(1 << 1, 2);  // mode 1
  b.put(13, 6);
  const int r[4] = {0, 63, 10, 20}, g[4] = {5, 5, 30, 40}, bl[4] = {63, 0, 0, 63};
  for (int v : r) b.put(v, 6);
  for (int v : g) b.put(v, 6);
  for (int v : bl) b.put(v, 6);
  b.put(1, 1), b.put(0, 1);  // shared p-bit per subset
  for (int i = 0; i < 16; ++i) {
    const bool anchor = i == 0 || i == 15;
    b.put(i % 4, anchor ? 2 : 3);
  }
  ASSERT_EQ(b.pos, 128);
  uint8_t rgba[64];
  bc7_decode_block(b.data, rgba);
  constexpr int kW3[8] = {0, 9, 18, 27, 37, 46, 55, 64};
  auto unq = [](int v, int p) {
    const int x = (v << 1) | p;  // 7 bits
    return (x << 1) | (x >> 6);
  };
  for (int i = 0; i < 16; ++i) {
    const int s = i >= 8 ? 1 : 0, p = s == 0 ? 1 : 0, w = kW3[i % 4];
    const int er0 = unq(r[2 * s], p), er1 = unq(r[2 * s + 1], p);
    const int eg0 = unq(g[2 * s], p), eg1 = unq(g[2 * s + 1], p);
    const int eb0 = unq(bl[2 * s], p), eb1 = unq(bl[2 * s + 1], p);
    EXPECT_EQ(rgba[4 * i], ((64 - w) * er0 + w * er1 + 32) >> 6) << i;
    EXPECT_EQ(rgba[4 * i + 1], ((64 - w) * eg0 + w * eg1 + 32) >> 6) << i;
    EXPECT_EQ(rgba[4 * i + 2], ((64 - w) * eb0 + w * eb1 + 32) >> 6) << i;
    EXPECT_EQ(rgba[4 * i + 3], 255);
  }
}

TEST(Bc7Decode, ReservedModeIsTransparentBlack) {
  uint8_t block[16] = {0,    0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff,
                       0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff};
  uint8_t rgba[64];
  std::memset(rgba, 7, sizeof(rgba));
  bc7_decode_block(block, rgba);
  for (uint8_t v : rgba) EXPECT_EQ(v, 0);
  EXPECT_EQ(bc7_block_mode(block), 8);
}

TEST(Bc7Decode, ArbitraryBytesDecodeDeterministically) {
  Rng rng(123);
  std::set<int> modes;
  for (int trial = 0; trial < 20000; ++trial) {
    uint8_t block[16], a[64], b[64];
    for (uint8_t& v : block) v = uint8_t(rng.next() >> 24);
    bc7_decode_block(block, a);
    bc7_decode_block(block, b);
    ASSERT_EQ(0, std::memcmp(a, b, 64));
    modes.insert(bc7_block_mode(block));
  }
  EXPECT_EQ(modes.size(), 9u);
}

TEST(Bc7, ConstantBlocksWithinOne) {
  Rng rng(3);
  for (BcQuality q : kLevels) {
    for (int trial = 0; trial < 100; ++trial) {
      uint8_t rgba[64], out[64], block[16];
      uint8_t col[4] = {uint8_t(rng.below(256)), uint8_t(rng.below(256)), uint8_t(rng.below(256)),
                        uint8_t(trial % 2 ? 255 : rng.below(256))};
      for (int i = 0; i < 16; ++i) std::memcpy(rgba + 4 * i, col, 4);
      bc7_encode_block(rgba, q, block);
      bc7_decode_block(block, out);
      for (int i = 0; i < 64; ++i) ASSERT_LE(std::abs(out[i] - rgba[i]), 1) << trial;
    }
  }
}

TEST(Bc7, OpaqueErrorBounds) {
  const int w = 64, h = 64;
  auto img = test::smooth_image(w, h, 3, 21);
  const double bounds[3] = {41.0, 43.2, 43.6};  // measured 41.17, 43.43, 43.86
  double previous = 0;
  for (int level = 0; level < 3; ++level) {
    std::vector<uint8_t> blocks(bc_image_bytes(BcFormat::kBc7, w, h)), out(img.size());
    ASSERT_TRUE(
        bc_encode_image(BcFormat::kBc7, kLevels[level], img.data(), w, h, 3, blocks.data()).ok());
    ASSERT_TRUE(bc_decode_image(BcFormat::kBc7, blocks.data(), w, h, 3, out.data()).ok());
    const double p = test::psnr(img, out, 3, 3);
    EXPECT_GT(p, bounds[level]) << level;
    EXPECT_GE(p, previous - 0.05) << level;
    previous = p;
  }
  auto noise = test::noise_image(w, h, 3, 8);
  std::vector<uint8_t> blocks(bc_image_bytes(BcFormat::kBc7, w, h)), out(noise.size());
  ASSERT_TRUE(
      bc_encode_image(BcFormat::kBc7, BcQuality::kRealtime, noise.data(), w, h, 3, blocks.data())
          .ok());
  ASSERT_TRUE(bc_decode_image(BcFormat::kBc7, blocks.data(), w, h, 3, out.data()).ok());
  EXPECT_GT(test::psnr(noise, out, 3, 3), 13.7);  // measured 13.93
}

TEST(Bc7, AlphaContent) {
  const int w = 32, h = 32;
  auto img = test::smooth_image(w, h, 4, 5);
  auto binary = img;
  Rng rng(9);
  for (size_t i = 3; i < binary.size(); i += 4) binary[i] = rng.below(2) ? 255 : 0;
  for (BcQuality q : kLevels) {
    for (const auto* src : {&img, &binary}) {
      std::vector<uint8_t> blocks(bc_image_bytes(BcFormat::kBc7, w, h)), out(src->size());
      ASSERT_TRUE(bc_encode_image(BcFormat::kBc7, q, src->data(), w, h, 4, blocks.data()).ok());
      ASSERT_TRUE(bc_decode_image(BcFormat::kBc7, blocks.data(), w, h, 4, out.data()).ok());
      EXPECT_GT(test::psnr(*src, out, 4, 4), src == &img ? 40.0 : 30.0) << int(q);
      if (src == &binary) {
        // 0/255 alpha survives within a few levels: a cut-out stays a cut-out.
        int worst = 0;
        for (size_t i = 3; i < out.size(); i += 4)
          worst = std::max(worst, std::abs(out[i] - (*src)[i]));
        EXPECT_LE(worst, 16) << int(q);
      }
    }
  }
}

TEST(Bc7, HighLevelUsesPartitionedModes) {
  const int w = 32, h = 32;
  // Three flat-ish regions with hard edges and mild noise: what the two- and three-subset modes
  // are for, and what one line through colour space (mode 6) fits badly.
  std::vector<uint8_t> img(size_t(w) * h * 3);
  Rng rng(17);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      // Within every 4x4 block: left half, top right, bottom right; two colours in each.
      const int region = (x % 4) < 2 ? 0 : (y % 4) < 2 ? 1 : 2;
      const int colours[6][3] = {{220, 30, 40},  {120, 20, 30}, {20, 200, 60},
                                 {200, 220, 40}, {30, 40, 210}, {40, 220, 230}};
      for (int c = 0; c < 3; ++c) {
        img[(size_t(y) * w + x) * 3 + c] =
            uint8_t(colours[2 * region + ((x + y) & 1)][c] + rng.below(7) - 3);
      }
    }
  }
  double psnr[3];
  std::set<int> high_modes;
  for (int level = 0; level < 3; ++level) {
    std::vector<uint8_t> blocks(bc_image_bytes(BcFormat::kBc7, w, h)), out(img.size());
    ASSERT_TRUE(
        bc_encode_image(BcFormat::kBc7, kLevels[level], img.data(), w, h, 3, blocks.data()).ok());
    ASSERT_TRUE(bc_decode_image(BcFormat::kBc7, blocks.data(), w, h, 3, out.data()).ok());
    psnr[level] = test::psnr(img, out, 3, 3);
    if (level == 2) {
      for (size_t b = 0; b < blocks.size(); b += 16) high_modes.insert(bc7_block_mode(&blocks[b]));
    }
  }
  EXPECT_TRUE(high_modes.count(0) || high_modes.count(2));  // three subsets
  // Measured 13.8 dB (one line through six colours), 17.9 (two subsets), 38.4 (three).
  EXPECT_GT(psnr[1], psnr[0] + 2.0);
  EXPECT_GT(psnr[2], psnr[1] + 10.0);
  EXPECT_GT(psnr[2], 37.0);
}

// The real-time level encodes 16 blocks side by side: a block's bytes must not depend on its
// neighbours in the batch, the batch length (short last batches, the 256-block chunks), or whether
// it went through bc7_encode_block alone. Blocks mix opaque, varying-alpha, flat and noisy texels.
TEST(Bc7, RealtimeBatchesMatchSingleBlocks) {
  Rng rng(31);
  const size_t count = 300;
  std::vector<uint8_t> rgba(count * 64);
  const auto smooth = test::smooth_image(64, 64, 4, 12);
  for (size_t b = 0; b < count; ++b) {
    const int kind = int(b % 5);
    for (int i = 0; i < 16; ++i) {
      for (int c = 0; c < 4; ++c) {
        const uint8_t s = smooth[((b % 256) * 16 + size_t(i)) * 4 % smooth.size() + size_t(c)];
        uint8_t v = kind == 0 ? s : kind == 1 ? uint8_t(rng.below(256)) : uint8_t(40 + 50 * c);
        if (c == 3) v = kind == 3 ? uint8_t(rng.below(256)) : kind == 4 ? s : 255;
        rgba[b * 64 + size_t(i) * 4 + size_t(c)] = v;
      }
    }
  }
  for (bool ignore_alpha : {false, true}) {
    std::vector<uint8_t> single(count * 16);
    for (size_t b = 0; b < count; ++b)
      bc7_encode_block(&rgba[b * 64], BcQuality::kRealtime, &single[b * 16], ignore_alpha);
    for (size_t n : {size_t(1), size_t(5), size_t(16), size_t(17), size_t(40), count}) {
      std::vector<uint8_t> batch(n * 16);
      bc7_encode_blocks_realtime(rgba.data(), n, batch.data(), ignore_alpha);
      ASSERT_EQ(0, std::memcmp(batch.data(), single.data(), n * 16))
          << n << " blocks, ignore_alpha " << ignore_alpha;
    }
  }
}

// Opaque blocks decode to alpha 255 exactly (an alpha-tested texture stays opaque), and only with
// the alpha ignored (an RGB layer) may the p-bits leave 254.
TEST(Bc7, RealtimeOpaqueBlocksDecodeOpaque) {
  const auto img = test::smooth_image(32, 32, 4, 44);
  std::vector<uint8_t> opaque = img;
  for (size_t i = 3; i < opaque.size(); i += 4) opaque[i] = 255;
  std::vector<uint8_t> blocks(bc_image_bytes(BcFormat::kBc7, 32, 32)), out(opaque.size());
  ASSERT_TRUE(
      bc_encode_image(BcFormat::kBc7, BcQuality::kRealtime, opaque.data(), 32, 32, 4, blocks.data())
          .ok());
  ASSERT_TRUE(bc_decode_image(BcFormat::kBc7, blocks.data(), 32, 32, 4, out.data()).ok());
  for (size_t i = 3; i < out.size(); i += 4) ASSERT_EQ(out[i], 255) << i;
  ASSERT_TRUE(
      bc_encode_image(BcFormat::kBc7, BcQuality::kRealtime, img.data(), 32, 32, 3, blocks.data())
          .ok());
  ASSERT_TRUE(bc_decode_image(BcFormat::kBc7, blocks.data(), 32, 32, 4, out.data()).ok());
  for (size_t i = 3; i < out.size(); i += 4) ASSERT_GE(out[i], 254) << i;
}

TEST(Bc7, Deterministic) {
  const int w = 16, h = 16;
  auto img = test::smooth_image(w, h, 4, 77);
  for (BcQuality q : kLevels) {
    std::vector<uint8_t> a(bc_image_bytes(BcFormat::kBc7, w, h)), b(a.size());
    ASSERT_TRUE(bc_encode_image(BcFormat::kBc7, q, img.data(), w, h, 4, a.data()).ok());
    ASSERT_TRUE(bc_encode_image(BcFormat::kBc7, q, img.data(), w, h, 4, b.data()).ok());
    EXPECT_EQ(a, b);
  }
}

}  // namespace
}  // namespace vt
