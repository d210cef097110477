// BC6H: the decoder against blocks built here bit by bit from the specification's layouts (modes
// 1, 11 and 14, unsigned and signed, delta wrap-around, reserved modes), robustness on arbitrary
// bytes, and the encoders' measured error on synthetic HDR content at every level: constant
// blocks exact, gradients over 1e-3..6e4, signed data, NaN and infinity inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <set>
#include <vector>

#include "codec/bc.h"
#include "codec/bc6h.h"
#include "codec/hdr_metrics.h"
#include "common/half.h"
#include "tests/codec/test_bc_images.h"

namespace vt {
namespace {

using test::Rng;

constexpr BcQuality kLevels[] = {BcQuality::kRealtime, BcQuality::kNormal, BcQuality::kHigh};
constexpr int kWeights3[8] = {0, 9, 18, 27, 37, 46, 55, 64};
constexpr int kWeights4[16] = {0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64};

// Writes a block from its lowest bit.
struct Bits {
  uint8_t data[16] = {};
  int pos = 0;
  void put(int v, int n) {
    for (int i = 0; i < n; ++i, ++pos) data[pos >> 3] |= uint8_t(((v >> i) & 1) << (pos & 7));
  }
  void bit(int v, int b) { put((v >> b) & 1, 1); }                  // "v[b]"
  void range(int v, int hi, int lo) { put(v >> lo, hi - lo + 1); }  // "v[hi:lo]"
  void reversed(int v, int lo, int hi) {                            // "v[lo:hi]"
    for (int b = hi; b >= lo; --b) bit(v, b);
  }
};

// The specification's unquantize and finish steps for unsigned endpoints of < 15 bits.
int unq_u(int q, int bits) {
  if (q == 0) return 0;
  if (q == (1 << bits) - 1) return 0xffff;
  return ((q << 16) + 0x8000) >> bits;
}
int interp(int a, int b, int w) {
  return ((64 - w) * a + w * b + 32) >> 6;
}

TEST(Bc6hDecode, Mode11UnsignedHandBuilt) {
  Bits b;
  b.put(0x03, 5);                                             // mode 11
  b.range(0, 9, 0), b.range(512, 9, 0), b.range(1023, 9, 0);  // rw gw bw
  b.range(1023, 9, 0), b.range(512, 9, 0), b.range(0, 9, 0);  // rx gx bx
  b.put(0, 3);                                                // texel 0: anchor, 3 bits
  for (int i = 1; i < 16; ++i) b.put(i, 4);
  ASSERT_EQ(b.pos, 128);
  EXPECT_EQ(bc6h_block_mode(b.data), 11);
  EXPECT_EQ(bc6h_block_partition(b.data), -1);
  uint16_t rgb[48];
  bc6h_decode_block(b.data, false, rgb);
  // Endpoints unquantized: R 0 -> 65535, G 32800 both, B 65535 -> 0.
  EXPECT_EQ(unq_u(512, 10), 32800);
  for (int i = 0; i < 16; ++i) {
    const int w = kWeights4[i];
    EXPECT_EQ(rgb[3 * i + 0], (interp(0, 0xffff, w) * 31) >> 6) << i;
    EXPECT_EQ(rgb[3 * i + 1], (32800 * 31) >> 6) << i;
    EXPECT_EQ(rgb[3 * i + 2], (interp(0xffff, 0, w) * 31) >> 6) << i;
  }
  EXPECT_EQ(rgb[0], 0);
  EXPECT_EQ(rgb[3 * 15], 0x7bff);                   // 65504, the largest half
  EXPECT_EQ(half_to_float(rgb[1]), 1.5146484375f);  // 0x3e0f
  EXPECT_EQ(rgb[2], 0x7bff);
}

TEST(Bc6hDecode, Mode11SignedHandBuilt) {
  Bits b;
  b.put(0x03, 5);
  // rw = -512 (10-bit two's complement 512), gw = 0, bw = 511; rx = 511, gx = -1, bx = -511.
  b.range(512, 9, 0), b.range(0, 9, 0), b.range(511, 9, 0);
  b.range(511, 9, 0), b.range(1023, 9, 0), b.range(513, 9, 0);
  b.put(0, 3);
  for (int i = 1; i < 16; ++i) b.put(15, 4);  // every other texel at the second endpoint
  uint16_t rgb[48];
  bc6h_decode_block(b.data, true, rgb);
  // Signed unquantize at 10 bits: |q| >= 511 -> 0x7fff; 1 -> ((1 << 15) + 0x4000) >> 9 = 96.
  // Finish: magnitude * 31 >> 5, sign kept: 0x7fff -> 0x7bff.
  EXPECT_EQ(rgb[0], 0x8000 | 0x7bff);  // -65504
  EXPECT_EQ(rgb[1], 0);
  EXPECT_EQ(rgb[2], 0x7bff);
  EXPECT_EQ(rgb[3 * 5 + 0], 0x7bff);
  EXPECT_EQ(rgb[3 * 5 + 1], 0x8000 | ((96 * 31) >> 5));  // -93 as half bits
  EXPECT_EQ(rgb[3 * 5 + 2], 0x8000 | 0x7bff);
  // Unsigned, the same bits read as magnitudes: rw 512 -> 32800.
  bc6h_decode_block(b.data, false, rgb);
  EXPECT_EQ(rgb[0], (32800 * 31) >> 6);
}

TEST(Bc6hDecode, Mode14ConstantWithReversedHighBits) {
  // Mode 14: a 16-bit base whose bits 10..15 are stored highest first, 4-bit deltas. Base u such
  // that u * 31 >> 6 is 1.0 (0x3c00): u = ceil(15360 * 64 / 31) = 31711.
  const int base[3] = {31711, 0, 65535};
  Bits b;
  b.put(0x0f, 5);
  for (int c = 0; c < 3; ++c) b.range(base[c], 9, 0);
  for (int c = 0; c < 3; ++c) {
    b.put(0, 4);  // delta 0
    b.reversed(base[c], 10, 15);
  }
  b.put(0, 3);
  for (int i = 1; i < 16; ++i) b.put(i, 4);
  ASSERT_EQ(b.pos, 128);
  EXPECT_EQ(bc6h_block_mode(b.data), 14);
  uint16_t rgb[48];
  bc6h_decode_block(b.data, false, rgb);
  for (int i = 0; i < 16; ++i) {
    EXPECT_EQ(rgb[3 * i + 0], 0x3c00) << i;
    EXPECT_EQ(rgb[3 * i + 1], 0) << i;
    EXPECT_EQ(rgb[3 * i + 2], 0x7bff) << i;
  }
  // A delta of -1 on red (4-bit 0xf) moves the second endpoint one step down.
  Bits d;
  d.put(0x0f, 5);
  for (int c = 0; c < 3; ++c) d.range(base[c], 9, 0);
  for (int c = 0; c < 3; ++c) {
    d.put(c == 0 ? 0xf : 0, 4);
    d.reversed(base[c], 10, 15);
  }
  d.put(0, 3);
  for (int i = 1; i < 16; ++i) d.put(15, 4);
  bc6h_decode_block(d.data, false, rgb);
  EXPECT_EQ(rgb[0], 0x3c00);
  EXPECT_EQ(rgb[3], (31710 * 31) >> 6);  // 15359
}

TEST(Bc6hDecode, Mode1TwoRegionsDeltasAndWrap) {
  // Mode 1: 10-bit base w, 5-bit signed deltas x, y, z; partition 13 (texels 8-15 in region 1,
  // anchor texel 15).
  const int w[3] = {2, 200, 300};
  const int dx[3] = {-5, -3, 0}, dy[3] = {-16, 15, 1}, dz[3] = {7, -1, -16};
  auto m5 = [](int v) { return v & 31; };
  const int rx = m5(dx[0]), gx = m5(dx[1]), bx = m5(dx[2]);
  const int ry = m5(dy[0]), gy = m5(dy[1]), by = m5(dy[2]);
  const int rz = m5(dz[0]), gz = m5(dz[1]), bz = m5(dz[2]);
  Bits b;
  b.put(0, 2);
  b.bit(gy, 4), b.bit(by, 4), b.bit(bz, 4);
  b.range(w[0], 9, 0), b.range(w[1], 9, 0), b.range(w[2], 9, 0);
  b.range(rx, 4, 0), b.bit(gz, 4), b.range(gy, 3, 0), b.range(gx, 4, 0), b.bit(bz, 0);
  b.range(gz, 3, 0), b.range(bx, 4, 0), b.bit(bz, 1), b.range(by, 3, 0), b.range(ry, 4, 0);
  b.bit(bz, 2), b.range(rz, 4, 0), b.bit(bz, 3), b.range(13, 4, 0);
  ASSERT_EQ(b.pos, 82);
  int idx[16];
  for (int i = 0; i < 16; ++i) {
    idx[i] = (i * 3) % 8;
    if (i == 0 || i == 15) idx[i] &= 3;  // anchors: 2 bits
    b.put(idx[i], (i == 0 || i == 15) ? 2 : 3);
  }
  ASSERT_EQ(b.pos, 128);
  EXPECT_EQ(bc6h_block_mode(b.data), 1);
  EXPECT_EQ(bc6h_block_partition(b.data), 13);
  uint16_t rgb[48];
  bc6h_decode_block(b.data, false, rgb);
  // Red of x wraps: (2 - 5) & 1023 = 1021.
  int e[4][3];
  for (int c = 0; c < 3; ++c) {
    e[0][c] = w[c];
    e[1][c] = (w[c] + dx[c]) & 1023;
    e[2][c] = (w[c] + dy[c]) & 1023;
    e[3][c] = (w[c] + dz[c]) & 1023;
  }
  EXPECT_EQ(e[1][0], 1021);
  for (int i = 0; i < 16; ++i) {
    const int r = i >= 8 ? 1 : 0;
    for (int c = 0; c < 3; ++c) {
      const int v = interp(unq_u(e[2 * r][c], 10), unq_u(e[2 * r + 1][c], 10), kWeights3[idx[i]]);
      EXPECT_EQ(rgb[3 * i + c], (v * 31) >> 6) << i << " " << c;
    }
  }
  // Signed: the same sums sign-extended from 10 bits (x red is -3, not 1021), unquantized as
  // signed magnitudes, finished with * 31 >> 5.
  auto unq_s = [](int q) {
    const int a = std::abs(q);
    const int u = a == 0 ? 0 : a >= 511 ? 0x7fff : ((a << 15) + 0x4000) >> 9;
    return q < 0 ? -u : u;
  };
  auto sext10 = [](int v) { return (v & 512) ? v - 1024 : v; };
  bc6h_decode_block(b.data, true, rgb);
  for (int i = 0; i < 16; ++i) {
    const int r = i >= 8 ? 1 : 0;
    for (int c = 0; c < 3; ++c) {
      const int v =
          interp(unq_s(sext10(e[2 * r][c])), unq_s(sext10(e[2 * r + 1][c])), kWeights3[idx[i]]);
      const int fin = v < 0 ? -((-v * 31) >> 5) : (v * 31) >> 5;
      EXPECT_EQ(rgb[3 * i + c], fin < 0 ? 0x8000 | -fin : fin) << i << " " << c;
    }
  }
  EXPECT_EQ(sext10(e[1][0]), -3);
}

TEST(Bc6hDecode, ReservedModesDecodeToZero) {
  for (const int m : {0x13, 0x17, 0x1b, 0x1f}) {
    uint8_t block[16];
    std::memset(block, 0xa5, 16);
    block[0] = uint8_t((block[0] & ~0x1f) | m);
    EXPECT_EQ(bc6h_block_mode(block), 0);
    uint16_t rgb[48];
    bc6h_decode_block(block, false, rgb);
    for (const uint16_t v : rgb) EXPECT_EQ(v, 0);
  }
}

TEST(Bc6hDecode, ArbitraryBytesNeverGiveNaNOrInfinity) {
  Rng rng(7);
  std::set<int> modes;
  for (int n = 0; n < 20000; ++n) {
    uint8_t block[16];
    for (auto& v : block) v = uint8_t(rng.next());
    modes.insert(bc6h_block_mode(block));
    uint16_t rgb[48];
    bc6h_decode_block(block, false, rgb);
    for (const uint16_t v : rgb) ASSERT_LE(v, 0x7bff);  // finite, non-negative
    bc6h_decode_block(block, true, rgb);
    for (const uint16_t v : rgb) ASSERT_LE(v & 0x7fff, 0x7c00);  // never NaN
  }
  EXPECT_EQ(modes.size(), 15u);  // 14 modes and the reserved values
}

// A block of 16 RGB halves from floats.
std::vector<uint16_t> halves(const std::vector<float>& f) {
  std::vector<uint16_t> h(f.size());
  for (size_t i = 0; i < f.size(); ++i) h[i] = float_to_half(f[i]);
  return h;
}

TEST(Bc6hEncode, ConstantBlocksAreExact) {
  Rng rng(3);
  for (const bool is_signed : {false, true}) {
    for (int n = 0; n < 300; ++n) {
      uint16_t rgb[48], back[48];
      uint16_t v[3];
      for (auto& c : v) {
        c = uint16_t(rng.next() % 0x7c00);  // every finite magnitude
        if (is_signed && (rng.next() & 1)) c |= 0x8000;
      }
      for (int i = 0; i < 16; ++i) std::memcpy(rgb + 3 * i, v, sizeof v);
      for (const BcQuality q : kLevels) {
        uint8_t block[16];
        bc6h_encode_block(rgb, is_signed, q, block);
        bc6h_decode_block(block, is_signed, back);
        for (int i = 0; i < 48; ++i)
          ASSERT_EQ(back[i], v[i % 3] == 0x8000 ? 0 : v[i % 3])
              << "signed " << is_signed << " level " << int(q) << " value " << v[i % 3];
      }
    }
  }
}

// An HDR test image: a horizontal exponential ramp over 1e-3..6e4 (log2 -10..16), channels
// scaled differently, with sine modulation down the rows, noise and some hard-edged squares.
std::vector<float> hdr_image(int w, int h, bool negative, uint32_t seed) {
  std::vector<float> img(size_t(w) * h * 3);
  Rng rng(seed);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double l = -10.0 + 25.8 * x / (w - 1);
      for (int c = 0; c < 3; ++c) {
        double v = std::exp2(l) * (0.55 + 0.45 * std::sin(0.09 * y + 1.7 * c)) *
                   (1.0 + 0.02 * (rng.below(101) - 50) / 50.0);
        if (((x / 12) + (y / 12)) % 5 == 0) v *= 0.125;
        if (negative && ((x / 8 + y / 8 + c) & 1)) v = -v;
        img[(size_t(y) * w + x) * 3 + c] = float(std::clamp(v, -60000.0, 60000.0));
      }
    }
  }
  return img;
}

struct Measured {
  HdrError err;
  std::vector<int> modes = std::vector<int>(15, 0);
};

Measured round_trip(const std::vector<uint16_t>& src, int w, int h, bool is_signed, BcQuality q) {
  const BcFormat f = is_signed ? BcFormat::kBc6hSf16 : BcFormat::kBc6hUf16;
  std::vector<uint8_t> blocks(bc_image_bytes(f, w, h));
  EXPECT_TRUE(
      bc_encode_image(f, q, reinterpret_cast<const uint8_t*>(src.data()), w, h, 3, blocks.data())
          .ok());
  std::vector<uint16_t> back(src.size());
  EXPECT_TRUE(
      bc_decode_image(f, blocks.data(), w, h, 3, reinterpret_cast<uint8_t*>(back.data())).ok());
  Measured m;
  add_hdr_error(src.data(), back.data(), size_t(w) * h, 3, 3, m.err);
  for (size_t b = 0; b < blocks.size(); b += 16) ++m.modes[size_t(bc6h_block_mode(&blocks[b]))];
  for (const uint16_t v : back) EXPECT_LE(v & 0x7fff, 0x7bff);
  return m;
}

TEST(Bc6hEncode, HdrGradientErrorBounds) {
  const int w = 64, h = 64;
  const std::vector<uint16_t> src = halves(hdr_image(w, h, false, 11));
  // A hard case: 1.6 stops across each block plus noise and edges. Measured (tone-mapped PSNR
  // dB, mean log error): realtime 42.73 / 0.0499, normal 46.86 / 0.0337, high 47.04 / 0.0332.
  const double min_psnr[3] = {42.2, 46.3, 46.5};
  const double max_log_mean[3] = {0.052, 0.035, 0.035};
  double last = 0;
  for (int qi = 0; qi < 3; ++qi) {
    const Measured m = round_trip(src, w, h, false, kLevels[qi]);
    EXPECT_GE(m.err.tonemapped_psnr_db(), min_psnr[qi]) << qi;
    EXPECT_LE(m.err.log_abs_mean(), max_log_mean[qi]) << qi;
    EXPECT_LT(m.err.log_abs_max, 0.5) << qi;
    EXPECT_GE(m.err.tonemapped_psnr_db(), last - 0.05) << "levels must not get worse " << qi;
    last = m.err.tonemapped_psnr_db();
    if (kLevels[qi] != BcQuality::kRealtime) {
      int two_region = 0;
      for (int mode = 1; mode <= 10; ++mode) two_region += m.modes[size_t(mode)];
      EXPECT_GT(two_region, 0) << "two-region modes used at level " << qi;
    } else {
      for (int mode = 1; mode <= 10; ++mode) EXPECT_EQ(m.modes[size_t(mode)], 0);
    }
  }
}

TEST(Bc6hEncode, SmoothBlocksKeepRelativePrecision) {
  // A smooth ramp inside one exposure range fits the transformed one-region modes, whose 12- to
  // 16-bit bases keep the relative error to a few half ulps.
  const int w = 32, h = 32;
  std::vector<float> f(size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        f[(size_t(y) * w + x) * 3 + c] = float(100.0 * (1.0 + 0.002 * (x + y) + 0.1 * c));
  const std::vector<uint16_t> src = halves(f);
  for (const BcQuality q : kLevels) {
    const Measured m = round_trip(src, w, h, false, q);
    EXPECT_LT(m.err.relative_max, 0.004) << int(q);  // measured 0.0020 (realtime)
    EXPECT_GT(m.modes[12] + m.modes[13] + m.modes[14], 0) << int(q);
  }
}

TEST(Bc6hEncode, SignedContentKeepsItsSign) {
  const int w = 64, h = 64;
  const std::vector<uint16_t> src = halves(hdr_image(w, h, true, 5));
  // Signs alternate in 8x8 squares per channel. Measured (tone-mapped PSNR dB): realtime 42.76,
  // normal 46.86, high 47.01.
  const double min_psnr[3] = {42.2, 46.3, 46.5};
  for (int qi = 0; qi < 3; ++qi) {
    const Measured m = round_trip(src, w, h, true, kLevels[qi]);
    EXPECT_GE(m.err.tonemapped_psnr_db(), min_psnr[qi]) << qi;
  }
  // The same content as unsigned reads its negatives as 0.
  const BcFormat f = BcFormat::kBc6hUf16;
  std::vector<uint8_t> blocks(bc_image_bytes(f, w, h));
  ASSERT_TRUE(bc_encode_image(f, BcQuality::kRealtime, reinterpret_cast<const uint8_t*>(src.data()),
                              w, h, 3, blocks.data())
                  .ok());
  std::vector<uint16_t> back(src.size());
  ASSERT_TRUE(
      bc_decode_image(f, blocks.data(), w, h, 3, reinterpret_cast<uint8_t*>(back.data())).ok());
  for (const uint16_t v : back) EXPECT_EQ(v & 0x8000, 0);
}

TEST(Bc6hEncode, NanAndInfinityInputsAreClamped) {
  const uint16_t kNaN = 0x7e00, kInf = 0x7c00, kNegInf = 0xfc00;
  // Blocks of one value: NaN codes 0, infinities the largest finite half, exactly.
  const uint16_t kConst[][3] = {{kNaN, kNaN, kNaN}, {kInf, kInf, kInf}, {kNegInf, kInf, kNaN}};
  for (const bool is_signed : {false, true}) {
    for (const auto& v : kConst) {
      uint16_t rgb[48], back[48];
      for (int i = 0; i < 16; ++i) std::memcpy(rgb + 3 * i, v, 6);
      for (const BcQuality q : kLevels) {
        uint8_t block[16];
        bc6h_encode_block(rgb, is_signed, q, block);
        bc6h_decode_block(block, is_signed, back);
        for (int i = 0; i < 48; ++i) {
          const int want = bc6h_half_to_int(v[i % 3], is_signed);
          EXPECT_EQ(back[i], want < 0 ? 0x8000 | -want : want) << i;
        }
      }
    }
  }
  // Mixed with ordinary values on one line (equal channels, half bits i * 2047): NaN, +inf
  // and -inf read as 0, 65504 and 0 (unsigned) or -65504 (signed), also on that line; the output
  // is finite and each texel within half a palette step (range / 15 / 2) of the clamped input.
  uint16_t rgb[48];
  for (int i = 0; i < 16; ++i) {
    const uint16_t v = i == 0 ? kNaN : i == 15 ? kInf : i == 7 ? kNegInf : uint16_t(i * 2047);
    rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = v;
  }
  for (const bool is_signed : {false, true}) {
    const int range = is_signed ? 2 * 0x7bff : 0x7bff;
    for (const BcQuality q : kLevels) {
      uint8_t block[16];
      uint16_t back[48];
      bc6h_encode_block(rgb, is_signed, q, block);
      bc6h_decode_block(block, is_signed, back);
      for (int i = 0; i < 48; ++i) {
        ASSERT_LT(back[i] & 0x7fff, 0x7c00) << "finite " << i;
        const int got = bc6h_half_to_int(back[i], true);
        const int want = bc6h_half_to_int(rgb[i], is_signed);
        EXPECT_LE(std::abs(got - want), range / 30 + 64)
            << "signed " << is_signed << " level " << int(q) << " texel " << i / 3;
      }
    }
  }
  EXPECT_EQ(bc6h_half_to_int(kNaN, false), 0);
  EXPECT_EQ(bc6h_half_to_int(kInf, false), 0x7bff);
  EXPECT_EQ(bc6h_half_to_int(kNegInf, false), 0);
  EXPECT_EQ(bc6h_half_to_int(kNegInf, true), -0x7bff);
  EXPECT_EQ(bc6h_half_to_int(0x8001, false), 0);
}

TEST(Bc6hImage, ChannelsAndAlpha) {
  // Four channels in: the fourth is ignored on encode and decodes as 1.0; one channel in: green
  // and blue read 0.
  const int w = 8, h = 8;
  std::vector<uint16_t> rgba(size_t(w) * h * 4), r1(size_t(w) * h);
  for (int i = 0; i < w * h; ++i) {
    for (int c = 0; c < 4; ++c) rgba[size_t(i) * 4 + c] = float_to_half(0.25f * float(c + 1));
    r1[size_t(i)] = float_to_half(3.0f);
  }
  std::vector<uint8_t> blocks(bc_image_bytes(BcFormat::kBc6hUf16, w, h));
  ASSERT_TRUE(bc_encode_image(BcFormat::kBc6hUf16, BcQuality::kRealtime,
                              reinterpret_cast<const uint8_t*>(rgba.data()), w, h, 4, blocks.data())
                  .ok());
  std::vector<uint16_t> back(rgba.size());
  ASSERT_TRUE(bc_decode_image(BcFormat::kBc6hUf16, blocks.data(), w, h, 4,
                              reinterpret_cast<uint8_t*>(back.data()))
                  .ok());
  for (int i = 0; i < w * h; ++i) {
    for (int c = 0; c < 3; ++c) EXPECT_EQ(back[size_t(i) * 4 + c], rgba[size_t(i) * 4 + c]);
    EXPECT_EQ(back[size_t(i) * 4 + 3], 0x3c00);
  }
  ASSERT_TRUE(bc_encode_image(BcFormat::kBc6hUf16, BcQuality::kNormal,
                              reinterpret_cast<const uint8_t*>(r1.data()), w, h, 1, blocks.data())
                  .ok());
  std::vector<uint16_t> back3(size_t(w) * h * 3);
  ASSERT_TRUE(bc_decode_image(BcFormat::kBc6hUf16, blocks.data(), w, h, 3,
                              reinterpret_cast<uint8_t*>(back3.data()))
                  .ok());
  for (int i = 0; i < w * h; ++i) {
    EXPECT_EQ(back3[size_t(i) * 3], r1[size_t(i)]);
    EXPECT_EQ(back3[size_t(i) * 3 + 1], 0);
    EXPECT_EQ(back3[size_t(i) * 3 + 2], 0);
  }
  EXPECT_EQ(bc_format_channels(BcFormat::kBc6hSf16), 3);
  EXPECT_EQ(bc_block_bytes(BcFormat::kBc6hUf16), 16u);
  EXPECT_EQ(bc_channel_bytes(BcFormat::kBc6hUf16), 2);
  EXPECT_FALSE(bc_encode_image(BcFormat::kBc6hUf16, BcQuality::kRealtime,
                               reinterpret_cast<const uint8_t*>(r1.data()), 6, 8, 1, blocks.data())
                   .ok());
}

TEST(Bc6hEncode, Deterministic) {
  const int w = 16, h = 16;
  const std::vector<uint16_t> src = halves(hdr_image(w, h, false, 9));
  for (const BcQuality q : kLevels) {
    std::vector<uint8_t> a(bc_image_bytes(BcFormat::kBc6hUf16, w, h)), b(a.size());
    ASSERT_TRUE(bc_encode_image(BcFormat::kBc6hUf16, q,
                                reinterpret_cast<const uint8_t*>(src.data()), w, h, 3, a.data())
                    .ok());
    ASSERT_TRUE(bc_encode_image(BcFormat::kBc6hUf16, q,
                                reinterpret_cast<const uint8_t*>(src.data()), w, h, 3, b.data())
                    .ok());
    EXPECT_EQ(a, b);
  }
}

// A 132x132 HDR page (33 blocks a row: partial batches of the real-time kernel) with every kind
// of block: exponential gradients over 2^-14..2^15, noise over six stops, hard edges between
// black and 3e4, flat blocks, and scattered NaN, infinities and negatives (signed: negatives
// everywhere).
std::vector<uint16_t> pinned_hdr_page(int size, int channels, bool is_signed, uint32_t seed) {
  std::vector<uint16_t> img(size_t(size) * size * size_t(channels));
  Rng rng(seed);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const int region = ((y / 12) * 7 + (x / 12) * 3) % 5;
      for (int c = 0; c < channels; ++c) {
        float v = 0;
        if (region == 0) v = std::exp2(-14.0f + 29.0f * float(x + y * (c + 1)) / float(3 * size));
        if (region == 1) v = std::exp2(float(rng.below(600)) / 100.0f - 2.0f) * (1.0f + 0.3f * c);
        if (region == 2) v = ((x ^ y) & 2) ? 0.0f : 30000.0f / float(1 + c);
        if (region == 3) v = 0.25f + float(c);
        if (region == 4) v = float(x % 4) * 0.5f + float(c) * float(y % 4) * 64.0f;
        if (is_signed && ((x + 2 * y + c) % 3 == 0)) v = -v;
        uint16_t h = float_to_half(v);
        const int r = rng.below(200);
        if (r == 0) h = 0x7e00;                 // NaN
        if (r == 1) h = 0x7c00;                 // +infinity
        if (r == 2) h = 0xfc00;                 // -infinity
        if (r == 3) h = float_to_half(-0.75f);  // negative (0 when unsigned)
        img[(size_t(y) * size + size_t(x)) * size_t(channels) + size_t(c)] = h;
      }
    }
  }
  return img;
}

uint64_t fnv1a(const void* data, size_t bytes) {
  uint64_t h = 1469598103934665603ull;
  for (size_t i = 0; i < bytes; ++i)
    h = (h ^ static_cast<const uint8_t*>(data)[i]) * 1099511628211ull;
  return h;
}

// The real-time encoder's blocks and their decoded texels, pinned (digests from the scalar
// encoder before the 16-block kernel): the runtime transcode of HDR layers must give these exact
// bytes on every machine (AVX-512, AVX2 and baseline builds of the kernel), and the decoder must
// read them back to the same texels.
TEST(Bc6hEncode, RealtimeOutputIsPinned) {
  struct Case {
    BcFormat format;
    int channels;
    uint64_t blocks, texels;
  };
  const Case cases[] = {
      {BcFormat::kBc6hUf16, 3, 0x2634cc8f0e730f11ull, 0xdcc24f854150380cull},
      {BcFormat::kBc6hUf16, 4, 0xe8d5f407114b709cull, 0x7b1d7f7e2f7366a3ull},
      {BcFormat::kBc6hUf16, 1, 0x5389090e84e919fdull, 0xcda750cbaf4bc779ull},
      {BcFormat::kBc6hSf16, 3, 0x37182fd5db623ba0ull, 0x644b368fd30f1a5full},
  };
  const int size = 132;
  for (const Case& c : cases) {
    const bool is_signed = c.format == BcFormat::kBc6hSf16;
    const std::vector<uint16_t> page = pinned_hdr_page(size, c.channels, is_signed, 2026);
    std::vector<uint8_t> blocks(bc_image_bytes(c.format, size, size));
    ASSERT_TRUE(bc_encode_image(c.format, BcQuality::kRealtime,
                                reinterpret_cast<const uint8_t*>(page.data()), size, size,
                                c.channels, blocks.data())
                    .ok());
    std::vector<uint16_t> back(page.size());
    ASSERT_TRUE(bc_decode_image(c.format, blocks.data(), size, size, c.channels,
                                reinterpret_cast<uint8_t*>(back.data()))
                    .ok());
    const uint64_t hb = fnv1a(blocks.data(), blocks.size());
    const uint64_t ht = fnv1a(back.data(), back.size() * 2);
    EXPECT_EQ(hb, c.blocks) << "format " << int(c.format) << ", " << c.channels
                            << " channels: blocks 0x" << std::hex << hb;
    EXPECT_EQ(ht, c.texels) << "format " << int(c.format) << ", " << c.channels
                            << " channels: texels 0x" << std::hex << ht;
  }
}

// One block through bc6h_encode_block (the kernel with one lane used) gives the same bytes as
// the same block inside an image (every lane used).
TEST(Bc6hEncode, RealtimeBlockMatchesImage) {
  for (const bool is_signed : {false, true}) {
    const int size = 132;
    const std::vector<uint16_t> page = pinned_hdr_page(size, 3, is_signed, 7);
    const BcFormat f = is_signed ? BcFormat::kBc6hSf16 : BcFormat::kBc6hUf16;
    std::vector<uint8_t> blocks(bc_image_bytes(f, size, size));
    ASSERT_TRUE(bc_encode_image(f, BcQuality::kRealtime,
                                reinterpret_cast<const uint8_t*>(page.data()), size, size, 3,
                                blocks.data())
                    .ok());
    for (int by = 0; by < size / 4; by += 5) {
      for (int bx = 0; bx < size / 4; ++bx) {
        uint16_t rgb[48];
        for (int t = 0; t < 16; ++t)
          for (int ch = 0; ch < 3; ++ch)
            rgb[3 * t + ch] =
                page[((size_t(by) * 4 + size_t(t / 4)) * size + size_t(bx) * 4 + size_t(t % 4)) *
                         3 +
                     size_t(ch)];
        uint8_t one[16];
        bc6h_encode_block(rgb, is_signed, BcQuality::kRealtime, one);
        EXPECT_EQ(0, std::memcmp(one, &blocks[(size_t(by) * (size / 4) + size_t(bx)) * 16], 16))
            << "block " << bx << "," << by << (is_signed ? " signed" : "");
      }
    }
  }
}

TEST(HdrMetrics, LogAndToneMappedErrors) {
  // L(1) = 1, L(3) = 2, L(-3) = -2; T(1) = srgb(0.5).
  EXPECT_DOUBLE_EQ(hdr_log_value(1.0f), 1.0);
  EXPECT_DOUBLE_EQ(hdr_log_value(3.0f), 2.0);
  EXPECT_DOUBLE_EQ(hdr_log_value(-3.0f), -2.0);
  EXPECT_NEAR(hdr_tonemap(1.0f), 0.7354, 1e-4);
  EXPECT_NEAR(hdr_tonemap(-1.0f), -0.7354, 1e-4);
  const uint16_t a[4] = {float_to_half(1.0f), float_to_half(3.0f), 0x7e00, 0x7c00};
  const uint16_t b[4] = {float_to_half(3.0f), float_to_half(3.0f), 0x0000, 0x7bff};
  HdrError e;
  add_hdr_error(a, b, 2, 2, 2, e);  // NaN reads 0 and infinity 65504: the last texel matches
  EXPECT_EQ(e.samples, 4u);
  EXPECT_DOUBLE_EQ(e.log_abs_sum, 1.0);
  EXPECT_DOUBLE_EQ(e.log_abs_max, 1.0);
  EXPECT_DOUBLE_EQ(e.log_abs_mean(), 0.25);
  EXPECT_DOUBLE_EQ(e.relative_max, 2.0);
  const double dt = hdr_tonemap(1.0f) - hdr_tonemap(3.0f);
  EXPECT_NEAR(e.tonemapped_psnr_db(), 10 * std::log10(4 / (dt * dt)), 1e-9);
  HdrError same;
  add_hdr_error(a, a, 2, 2, 2, same);
  EXPECT_TRUE(std::isinf(same.tonemapped_psnr_db()));
  e.add(same);
  EXPECT_EQ(e.samples, 8u);
}

}  // namespace
}  // namespace vt
