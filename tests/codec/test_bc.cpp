// BC1, BC3, BC4 and BC5: exactness where the format can be exact, measured error bounds on
// procedural content, decoder rounding rules (lavapipe's), determinism and argument errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <vector>

#include "codec/bc.h"
#include "codec/bc1.h"
#include "codec/bc3.h"
#include "codec/bc4.h"
#include "codec/metrics.h"
#include "tests/codec/test_bc_images.h"

namespace vt {
namespace {

using test::Rng;

constexpr BcQuality kLevels[] = {BcQuality::kRealtime, BcQuality::kNormal, BcQuality::kHigh};

std::vector<uint8_t> round_trip(BcFormat f, BcQuality q, const std::vector<uint8_t>& img, int w,
                                int h, int channels) {
  std::vector<uint8_t> blocks(bc_image_bytes(f, w, h));
  EXPECT_TRUE(bc_encode_image(f, q, img.data(), w, h, channels, blocks.data()).ok());
  std::vector<uint8_t> out(img.size());
  EXPECT_TRUE(bc_decode_image(f, blocks.data(), w, h, channels, out.data()).ok());
  return out;
}

int expand5(int v) {
  return (v << 3) | (v >> 2);
}
int expand6(int v) {
  return (v << 2) | (v >> 4);
}

// ---- decoder rounding rules ----

// The RGBA texels of a BC1 block with endpoints c0, c1 (RGB565) and index byte `indices` for
// texels 0-3 (the other texels index 0).
std::array<uint8_t, 64> bc1_decode_indices(uint16_t c0, uint16_t c1, uint8_t indices) {
  const uint8_t block[8] = {
      uint8_t(c0), uint8_t(c0 >> 8), uint8_t(c1), uint8_t(c1 >> 8), indices, 0, 0, 0};
  std::array<uint8_t, 64> rgba;
  bc1_decode_block(block, rgba.data());
  return rgba;
}

TEST(Bc1Decode, FourColourPaletteTruncates) {
  // c0 = (31, 0, 1), c1 = (0, 0, 0): red 255 and 0, blue 8 and 0.
  const uint16_t c0 = (31 << 11) | 1, c1 = 0;
  const auto rgba = bc1_decode_indices(c0, c1, 0xE4);  // indices 0,1,2,3 in texels 0-3
  EXPECT_EQ(rgba[0], 255);
  EXPECT_EQ(rgba[4], 0);
  EXPECT_EQ(rgba[8], 170);  // (2*255 + 0) / 3 = 170
  EXPECT_EQ(rgba[12], 85);  // (255 + 0) / 3 = 85
  EXPECT_EQ(rgba[2], 8);    // blue 1 -> 8
  EXPECT_EQ(rgba[10], 5);   // (2*8 + 0) / 3 = 5.33 -> 5 (truncated, not rounded)
  EXPECT_EQ(rgba[14], 2);   // (8 + 0) / 3 = 2.67 -> 2 (a rounding decoder gives 3)
  EXPECT_EQ(rgba[3], 255);
}

TEST(Bc1Decode, ThreeColourMidpointRoundsUpAndIndexThreeIsBlack) {
  // c0 = (r0, g1, b0) <= c1 = (r1, g2, b0): red 0 and 8, green 4 and 8.
  const uint16_t c0 = 1 << 5, c1 = (1 << 11) | (2 << 5);
  const auto rgba = bc1_decode_indices(c0, c1, 0xE4);
  EXPECT_EQ(rgba[0], 0);
  EXPECT_EQ(rgba[1], 4);
  EXPECT_EQ(rgba[4], 8);
  EXPECT_EQ(rgba[5], 8);
  EXPECT_EQ(rgba[8], 4);  // (0 + 8 + 1) / 2
  EXPECT_EQ(rgba[9], 6);  // (4 + 8 + 1) / 2
  // Index 3 is black (RGB format: alpha stays 255).
  EXPECT_EQ(rgba[12], 0);
  EXPECT_EQ(rgba[13], 0);
  EXPECT_EQ(rgba[14], 0);
  EXPECT_EQ(rgba[15], 255);
}

TEST(Bc1Decode, ThreeColourOddSumRoundsUp) {
  // An odd sum: green 0 -> 0 and 16 -> 65 give (0 + 65 + 1) / 2 = 33 (32.5 rounds up).
  const uint16_t c0 = 0, c1 = 16 << 5;
  const auto rgba = bc1_decode_indices(c0, c1, 0x02);  // texel 0 -> index 2
  EXPECT_EQ(expand6(16), 65);
  EXPECT_EQ(rgba[1], 33);
}

TEST(Bc3Decode, ColourHalfIsAlwaysFourColour) {
  // c0 < c1 would be 3-colour in BC1, but BC3 interpolates 4 colours.
  const uint16_t c0 = 0, c1 = 31 << 11;
  uint8_t block[16] = {
      255,  255, 0, 0, 0, 0, 0, 0, uint8_t(c0), uint8_t(c0 >> 8), uint8_t(c1), uint8_t(c1 >> 8),
      0xE4, 0,   0, 0};
  uint8_t rgba[64];
  bc3_decode_block(block, rgba);
  EXPECT_EQ(rgba[0], 0);
  EXPECT_EQ(rgba[4], 255);
  EXPECT_EQ(rgba[8], 85);    // (2*0 + 255) / 3
  EXPECT_EQ(rgba[12], 170);  // (0 + 2*255) / 3, not black
  EXPECT_EQ(rgba[3], 255);
}

// The 16 texels of a BC4 block with endpoints e0, e1 and index i in texel i for i < 8 (index 0
// in texels 8-15), so texels 0-7 show the whole palette.
std::array<uint8_t, 16> bc4_decode_palette_block(uint8_t e0, uint8_t e1) {
  uint64_t bits = 0;
  for (int i = 0; i < 8; ++i) bits |= uint64_t(i) << (3 * i);
  uint8_t block[8] = {e0, e1};
  for (int i = 0; i < 6; ++i) block[2 + i] = uint8_t(bits >> (8 * i));
  std::array<uint8_t, 16> v;
  bc4_decode_block(block, v.data(), 1);
  return v;
}

TEST(Bc4Decode, EightValueModeTruncates) {
  const auto v = bc4_decode_palette_block(200, 10);  // e0 > e1
  EXPECT_EQ(v[0], 200);
  EXPECT_EQ(v[1], 10);
  for (int k = 2; k < 8; ++k) EXPECT_EQ(v[k], ((8 - k) * 200 + (k - 1) * 10) / 7) << k;
  EXPECT_EQ(v[2], 172);  // 1210 / 7 = 172.86: truncated
}

TEST(Bc4Decode, SixValueModeHasZeroAnd255) {
  const auto v = bc4_decode_palette_block(10, 200);  // e0 <= e1
  EXPECT_EQ(v[0], 10);
  EXPECT_EQ(v[1], 200);
  EXPECT_EQ(v[2], (4 * 10 + 1 * 200) / 5);
  EXPECT_EQ(v[3], (3 * 10 + 2 * 200) / 5);
  EXPECT_EQ(v[4], (2 * 10 + 3 * 200) / 5);
  EXPECT_EQ(v[5], (1 * 10 + 4 * 200) / 5);
  EXPECT_EQ(v[6], 0);
  EXPECT_EQ(v[7], 255);
}

// ---- exactness ----

TEST(Bc1, RepresentableConstantAndTwoColourBlocksAreExact) {
  Rng rng(7);
  for (BcQuality q : kLevels) {
    for (int trial = 0; trial < 200; ++trial) {
      int c[2][3];
      for (auto& col : c) {
        col[0] = expand5(rng.below(32));
        col[1] = expand6(rng.below(64));
        col[2] = expand5(rng.below(32));
      }
      const bool two = trial % 2 == 1;
      uint8_t rgba[64], out[64], block[8];
      for (int i = 0; i < 16; ++i) {
        const int* col = c[two ? rng.below(2) : 0];
        rgba[4 * i] = uint8_t(col[0]), rgba[4 * i + 1] = uint8_t(col[1]);
        rgba[4 * i + 2] = uint8_t(col[2]), rgba[4 * i + 3] = 255;
      }
      bc1_encode_block(rgba, q, block);
      bc1_decode_block(block, out);
      ASSERT_EQ(0, std::memcmp(rgba, out, 64)) << "level " << int(q) << " trial " << trial;
    }
  }
}

TEST(Bc1, AnyConstantColourIsWithinOneOfExact) {
  // Through the single-colour tables every 8-bit value is reachable within 1 (measured: the
  // truncating 2/3 blend of two 565 levels covers every value to +-1).
  for (int v = 0; v < 256; ++v) {
    uint8_t rgba[64], out[64], block[8];
    for (int i = 0; i < 16; ++i) {
      rgba[4 * i] = uint8_t(v), rgba[4 * i + 1] = uint8_t(255 - v),
               rgba[4 * i + 2] = uint8_t(v / 2);
      rgba[4 * i + 3] = 255;
    }
    bc1_encode_block(rgba, BcQuality::kRealtime, block);
    bc1_decode_block(block, out);
    for (int i = 0; i < 64; ++i) ASSERT_LE(std::abs(out[i] - rgba[i]), 1) << v;
    for (int i = 4; i < 64; ++i) ASSERT_EQ(out[i], out[i % 4]);  // one colour out
  }
}

// The batch encoder runs 16 blocks side by side: every block must come out as if encoded alone
// (lane independence, the partial last batch, the output stride), and every non-constant
// block's indices must name a nearest entry of the palette the decoder builds.
TEST(Bc1, RealtimeBatchMatchesSingleBlocksAndPicksNearestEntries) {
  Rng rng(77);
  constexpr int kBlocks = 41;  // two full batches and a partial one
  std::vector<uint8_t> rgba(kBlocks * 64);
  for (int blk = 0; blk < kBlocks; ++blk) {
    uint8_t* px = &rgba[size_t(blk) * 64];
    const int kind = blk % 4;
    const int base[3] = {rng.below(256), rng.below(256), rng.below(256)};
    for (int i = 0; i < 16; ++i) {
      for (int c = 0; c < 3; ++c) {
        int v = base[c];
        if (kind == 1) v = rng.below(256);                                   // noise
        if (kind == 2) v = (base[c] * (15 - i) + (255 - base[c]) * i) / 15;  // gradient
        if (kind == 3) v = (i & 5) ? base[c] : 255 - base[c];                // two colours
        px[4 * i + c] = uint8_t(v);
      }
      px[4 * i + 3] = 255;
    }
  }
  std::vector<uint8_t> batch8(kBlocks * 8), batch16(kBlocks * 16, 0xAB);
  for (size_t count : {size_t(1), size_t(15), size_t(16), size_t(17), size_t(kBlocks)}) {
    bc1_encode_blocks_realtime(rgba.data(), count, batch8.data(), 8);
    bc1_encode_blocks_realtime(rgba.data(), count, batch16.data() + 8, 16);
    for (size_t blk = 0; blk < count; ++blk) {
      uint8_t single[8];
      bc1_encode_block(&rgba[blk * 64], BcQuality::kRealtime, single);
      ASSERT_EQ(std::memcmp(single, &batch8[blk * 8], 8), 0) << count << " " << blk;
      ASSERT_EQ(std::memcmp(single, &batch16[blk * 16 + 8], 8), 0) << count << " " << blk;
      for (int i = 0; i < 8; ++i) ASSERT_EQ(batch16[blk * 16 + size_t(i)], 0xAB);
    }
  }
  for (int blk = 0; blk < kBlocks; ++blk) {
    if (blk % 4 == 0) continue;  // constant blocks go through the single-colour tables
    const uint8_t* px = &rgba[size_t(blk) * 64];
    const uint8_t* b = &batch8[size_t(blk) * 8];
    uint8_t out[64], pal_block[8], pal[64];
    bc1_decode_block(b, out);
    // The four palette entries: the same endpoints with indices 0, 1, 2, 3.
    std::memcpy(pal_block, b, 4);
    pal_block[4] = 0xE4, pal_block[5] = pal_block[6] = pal_block[7] = 0;
    bc1_decode_block(pal_block, pal);
    for (int i = 0; i < 16; ++i) {
      int best = 1 << 30, got = 0;
      // c0 <= c1 only when the endpoints collapsed: 3-colour decode, black is not a choice.
      const int entries = (b[0] | (b[1] << 8)) > (b[2] | (b[3] << 8)) ? 4 : 3;
      for (int k = 0; k < entries; ++k) {
        int d = 0;
        for (int c = 0; c < 3; ++c) {
          const int e = pal[4 * k + c] - px[4 * i + c];
          d += e * e;
        }
        best = std::min(best, d);
      }
      for (int c = 0; c < 3; ++c) {
        const int e = out[4 * i + c] - px[4 * i + c];
        got += e * e;
      }
      ASSERT_EQ(got, best) << "block " << blk << " texel " << i;
    }
  }
}

TEST(Bc1, PureBlackAndWhite) {
  for (BcQuality q : kLevels) {
    uint8_t rgba[64], out[64], block[8];
    for (int i = 0; i < 16; ++i) {
      const uint8_t v = (i * 7) % 3 == 0 ? 255 : 0;
      rgba[4 * i] = rgba[4 * i + 1] = rgba[4 * i + 2] = v;
      rgba[4 * i + 3] = 255;
    }
    bc1_encode_block(rgba, q, block);
    bc1_decode_block(block, out);
    EXPECT_EQ(0, std::memcmp(rgba, out, 64));
  }
}

TEST(Bc4, TwoValuesAndConstantsAreExact) {
  Rng rng(11);
  for (BcQuality q : kLevels) {
    for (int trial = 0; trial < 300; ++trial) {
      const int a = rng.below(256), b = trial % 3 == 0 ? a : rng.below(256);
      uint8_t v[16], out[16], block[8];
      for (int i = 0; i < 16; ++i) v[i] = uint8_t(rng.below(2) ? a : b);
      bc4_encode_block(v, 1, q, block);
      bc4_decode_block(block, out, 1);
      ASSERT_EQ(0, std::memcmp(v, out, 16)) << a << " " << b;
    }
  }
}

TEST(Bc3, AlphaOnlyZeroOr255IsExact) {
  auto img = test::smooth_image(32, 32, 4, 3);
  Rng rng(5);
  for (size_t i = 3; i < img.size(); i += 4) img[i] = rng.below(2) ? 255 : 0;
  for (BcQuality q : kLevels) {
    auto out = round_trip(BcFormat::kBc3, q, img, 32, 32, 4);
    for (size_t i = 3; i < img.size(); i += 4) ASSERT_EQ(img[i], out[i]);
    EXPECT_GT(test::psnr(img, out, 4, 3), 33.0);
  }
}

// ---- measured error bounds (procedural content; bounds set a little under the measured
// figures so a regression fails) ----

struct Bound {
  BcFormat format;
  int channels;
  double psnr_smooth[3];  // per level
  double psnr_noise;      // realtime
};

TEST(Bc, RoundTripErrorBounds) {
  const Bound bounds[] = {
      {BcFormat::kBc1, 3, {36.0, 36.2, 36.5}, 11.5},
      {BcFormat::kBc3, 4, {37.0, 37.3, 37.5}, 11.5},
      {BcFormat::kBc4, 1, {42.0, 42.5, 42.6}, 16.0},
      {BcFormat::kBc5, 2, {42.0, 42.5, 42.6}, 16.0},
  };
  const int w = 64, h = 64;
  for (const Bound& b : bounds) {
    auto img = test::smooth_image(w, h, b.channels, 21);
    double previous = 0;
    for (int level = 0; level < 3; ++level) {
      auto out = round_trip(b.format, kLevels[level], img, w, h, b.channels);
      const double p = test::psnr(img, out, b.channels, b.channels);
      EXPECT_GT(p, b.psnr_smooth[level]) << "format " << int(b.format) << " level " << level;
      EXPECT_GE(p, previous - 0.05) << "a higher level must not be worse";
      previous = p;
    }
    auto noise = test::noise_image(w, h, b.channels, 4);
    auto out = round_trip(b.format, BcQuality::kRealtime, noise, w, h, b.channels);
    EXPECT_GT(test::psnr(noise, out, b.channels, b.channels), b.psnr_noise) << int(b.format);
  }
}

TEST(Bc, GradientsAreSmooth) {
  const int w = 64, h = 64;
  auto img = test::gradient_image(w, h, 4);
  for (BcQuality q : kLevels) {
    auto out1 = round_trip(BcFormat::kBc1, q, img, w, h, 4);
    // Three channels ramping in three directions are not on one line: measured 9-10.
    EXPECT_LE(test::max_abs(img, out1, 4, 3), 11) << int(q);
    auto out4 = round_trip(BcFormat::kBc4, q, img, w, h, 4);
    EXPECT_LE(test::max_abs(img, out4, 4, 1), 2) << int(q);
  }
}

TEST(Bc5, NormalMapAngularError) {
  const int w = 64, h = 64;
  std::vector<uint8_t> img(size_t(w) * h * 2);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      // A bumpy surface: slopes from a sum of sines, normalised.
      const double dx = 0.6 * std::cos(0.2 * x) * std::sin(0.1 * y);
      const double dy = 0.5 * std::sin(0.15 * x + 0.05 * y);
      const double len = std::sqrt(dx * dx + dy * dy + 1);
      img[(size_t(y) * w + x) * 2] = uint8_t(std::lround((-dx / len * 0.5 + 0.5) * 255));
      img[(size_t(y) * w + x) * 2 + 1] = uint8_t(std::lround((-dy / len * 0.5 + 0.5) * 255));
    }
  }
  for (BcQuality q : kLevels) {
    auto out = round_trip(BcFormat::kBc5, q, img, w, h, 2);
    auto e = normal_angular_error(img.data(), out.data(), w, h, 2);
    ASSERT_TRUE(e.ok());
    // Measured 0.51 / 0.49 / 0.45 mean and 1.73 / 1.62 / <1.7 max: one 8-bit step is ~0.45.
    EXPECT_LT(e->mean_deg, 0.55) << int(q);
    EXPECT_LT(e->max_deg, 1.9) << int(q);
  }
}

// ---- determinism and API ----

TEST(Bc, EncodingIsDeterministicAndBlockwise) {
  const int w = 32, h = 32;
  auto img = test::smooth_image(w, h, 4, 99);
  for (BcFormat f : {BcFormat::kBc1, BcFormat::kBc3, BcFormat::kBc4, BcFormat::kBc5}) {
    for (BcQuality q : kLevels) {
      std::vector<uint8_t> a(bc_image_bytes(f, w, h)), b(a.size());
      ASSERT_TRUE(bc_encode_image(f, q, img.data(), w, h, 4, a.data()).ok());
      ASSERT_TRUE(bc_encode_image(f, q, img.data(), w, h, 4, b.data()).ok());
      EXPECT_EQ(a, b);
    }
  }
  // The image call is the block call on each gathered block.
  std::vector<uint8_t> image_blocks(bc_image_bytes(BcFormat::kBc1, w, h));
  ASSERT_TRUE(
      bc_encode_image(BcFormat::kBc1, BcQuality::kNormal, img.data(), w, h, 4, image_blocks.data())
          .ok());
  uint8_t rgba[64], block[8];
  for (int y = 0; y < 4; ++y)
    std::memcpy(rgba + 16 * y, img.data() + (size_t(4 + y) * w + 8) * 4, 16);
  bc1_encode_block(rgba, BcQuality::kNormal, block);
  EXPECT_EQ(0, std::memcmp(block, image_blocks.data() + (1 * (w / 4) + 2) * 8, 8));
}

TEST(Bc, MissingChannelsReadAsZeroColourAndOpaqueAlpha) {
  const int w = 8, h = 8;
  std::vector<uint8_t> grey(w * h, 200);
  std::vector<uint8_t> blocks(bc_image_bytes(BcFormat::kBc3, w, h)), out(w * h * 4);
  ASSERT_TRUE(
      bc_encode_image(BcFormat::kBc3, BcQuality::kNormal, grey.data(), w, h, 1, blocks.data())
          .ok());
  ASSERT_TRUE(bc_decode_image(BcFormat::kBc3, blocks.data(), w, h, 4, out.data()).ok());
  for (int i = 0; i < w * h; ++i) {
    EXPECT_NEAR(out[4 * i], 200, 1);
    EXPECT_EQ(out[4 * i + 1], 0);
    EXPECT_EQ(out[4 * i + 2], 0);
    EXPECT_EQ(out[4 * i + 3], 255);
  }
}

TEST(Bc, BadArgumentsAreErrors) {
  uint8_t texels[16 * 16 * 4] = {}, blocks[256] = {};
  EXPECT_EQ(bc_encode_image(BcFormat::kBc1, BcQuality::kRealtime, texels, 6, 8, 4, blocks).code(),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(bc_encode_image(BcFormat::kBc1, BcQuality::kRealtime, texels, 0, 8, 4, blocks).code(),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(bc_encode_image(BcFormat::kBc1, BcQuality::kRealtime, texels, 8, 8, 5, blocks).code(),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(bc_encode_image(BcFormat::kBc1, BcQuality::kRealtime, nullptr, 8, 8, 4, blocks).code(),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(bc_decode_image(BcFormat(9), blocks, 8, 8, 4, texels).code(),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(bc_format_channels(BcFormat::kBc5), 2);
  EXPECT_EQ(bc_image_bytes(BcFormat::kBc7, 128, 128), size_t(16384));
}

// ---- pinned real-time output ----

// A page of integer-only content (no libm: the same texels on every platform): smooth
// gradients, noise, hard edges and flat patches by 16x16 region, as pages mix them.
std::vector<uint8_t> pinned_page(int size, int channels, uint32_t seed) {
  std::vector<uint8_t> img(size_t(size) * size * channels);
  Rng rng(seed);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const int region = ((y / 16) * 7 + (x / 16) * 3) % 4;
      for (int c = 0; c < channels; ++c) {
        int v = 0;
        if (region == 0) v = (x * (2 + c) + y * (3 - c / 2)) & 255;       // gradient
        if (region == 1) v = 96 + 32 * c + rng.below(64) - 32;            // noise
        if (region == 2) v = ((x ^ y) & 4) ? 40 + 50 * c : 220 - 30 * c;  // edges
        if (region == 3) v = 17 + 61 * c;                                 // flat
        img[(size_t(y) * size + x) * channels + c] = uint8_t(std::clamp(v, 0, 255));
      }
    }
  }
  return img;
}

uint64_t fnv1a(const std::vector<uint8_t>& bytes) {
  uint64_t h = 1469598103934665603ull;
  for (uint8_t b : bytes) h = (h ^ b) * 1099511628211ull;
  return h;
}

// The real-time encoders' bytes, pinned: the runtime transcode (bc1.cpp's SIMD kernel in its
// AVX-512, AVX2 and baseline builds, whichever this machine runs) must give these exact blocks,
// so a speed change that moves one byte shows here. Digests from the encoders before issue 22's
// work; BC7's from its batched mode-6 kernel (bc7_realtime.cpp, 2026-12-04), which replaced the
// per-block search on purpose.
TEST(Bc, RealtimeOutputIsPinned) {
  struct Case {
    BcFormat format;
    int channels;
    uint64_t digest;
  };
  const Case cases[] = {
      {BcFormat::kBc1, 3, 0x2589bfc49b54a1a6ull}, {BcFormat::kBc1, 4, 0x6d589166b84d63d6ull},
      {BcFormat::kBc3, 4, 0x5a72a59de87aacbaull}, {BcFormat::kBc4, 1, 0xd6d1fcc9d72b9c2eull},
      {BcFormat::kBc5, 2, 0x8b90291667ba48b6ull}, {BcFormat::kBc7, 4, 0x3fd1a665b1d2ab14ull}};
  for (const Case& c : cases) {
    const std::vector<uint8_t> page = pinned_page(128, c.channels, 2026);
    std::vector<uint8_t> blocks(bc_image_bytes(c.format, 128, 128));
    ASSERT_TRUE(bc_encode_image(c.format, BcQuality::kRealtime, page.data(), 128, 128, c.channels,
                                blocks.data())
                    .ok());
    EXPECT_EQ(fnv1a(blocks), c.digest) << "format " << int(c.format) << ", " << c.channels
                                       << " channels: 0x" << std::hex << fnv1a(blocks);
  }
}

// The real-time BC1 path gathers blocks straight from 1-4 channel rows (bc1_encode_rows_realtime):
// the same bytes as the RGBA blocks through bc1_encode_blocks_realtime, at every row length
// (partial batches of 16, a row's last texel read without running past the image).
TEST(Bc1, RealtimeRowsMatchRgbaBlocks) {
  for (int w : {4, 8, 20, 64, 68, 132}) {
    const int h = 8;
    for (int channels = 1; channels <= 4; ++channels) {
      const std::vector<uint8_t> img = pinned_page(std::max(w, h), channels, uint32_t(w));
      // The top-left w x h of the page, rows packed, in a buffer of exactly that size.
      const size_t stride = size_t(std::max(w, h)) * channels;
      std::vector<uint8_t> sub(size_t(w) * h * channels);
      for (int y = 0; y < h; ++y)
        std::memcpy(&sub[size_t(y) * w * channels], &img[y * stride], size_t(w) * channels);
      std::vector<uint8_t> got(bc_image_bytes(BcFormat::kBc1, w, h));
      ASSERT_TRUE(bc_encode_image(BcFormat::kBc1, BcQuality::kRealtime, sub.data(), w, h, channels,
                                  got.data())
                      .ok());
      std::vector<uint8_t> rgba(size_t(w / 4) * 64), want(got.size());
      for (int by = 0; by < h / 4; ++by) {
        for (int bx = 0; bx < w / 4; ++bx) {
          for (int i = 0; i < 16; ++i) {
            const uint8_t* t = &sub[((size_t(by) * 4 + i / 4) * w + bx * 4 + i % 4) * channels];
            for (int c = 0; c < 4; ++c)
              rgba[size_t(bx) * 64 + 4 * i + c] = c < channels ? t[c] : (c == 3 ? 255 : 0);
          }
        }
        bc1_encode_blocks_realtime(rgba.data(), size_t(w / 4), &want[size_t(by) * (w / 4) * 8], 8);
      }
      ASSERT_EQ(got, want) << w << " wide, " << channels << " channels";
    }
  }
}

// Real-time BC1 on 3-channel rows of content that drives the kernel's choices both ways
// (noise, noisy gradients, four-level palettes, near-flat blocks; 17 blocks a row: a full batch
// of 16 and a partial one), pinned to the bytes of the kernel before its 2026-12-04 rewrite on
// lane vectors (the same digest from its AVX-512, AVX2 and baseline builds).
TEST(Bc1, RealtimeRowsArePinnedOnMixedContent) {
  const int w = 68, h = 64;
  std::vector<uint8_t> px(size_t(w) * h * 3);
  uint32_t s = 22;
  auto next = [&s] { return (s = s * 1664525u + 1013904223u) >> 8; };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) {
        const int kind = (x / 4 + y / 4) % 4;
        const uint32_t v = kind == 0   ? next() & 255u
                           : kind == 1 ? (uint32_t(x * 7 + y * 3 + c * 40) + next() % 9) & 255u
                           : kind == 2 ? (next() % 4) * 80
                                       : uint32_t(c * 60) + next() % 3;
        px[(size_t(y) * w + x) * 3 + c] = uint8_t(v);
      }
    }
  }
  std::vector<uint8_t> blocks(bc_image_bytes(BcFormat::kBc1, w, h));
  ASSERT_TRUE(
      bc_encode_image(BcFormat::kBc1, BcQuality::kRealtime, px.data(), w, h, 3, blocks.data())
          .ok());
  EXPECT_EQ(fnv1a(blocks), 0x737a91ce3cf6a9beull) << "0x" << std::hex << fnv1a(blocks);
}

}  // namespace
}  // namespace vt
