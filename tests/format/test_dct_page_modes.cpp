// The per-page DCT mode decision: hard content takes lossless or full chroma and never costs more
// than its lossless form, photographs keep the default mode, the error floor holds, and the
// layer codec decodes every mode.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "codec/dct.h"
#include "common/hash.h"
#include "format/dct_page_modes.h"
#include "format/zstd_frame.h"

namespace vt {
namespace {

constexpr int kSize = 128;

DctTablesPtr tables(int quality, DctPlaneLayout layout = DctPlaneLayout::kYCoCg420) {
  auto t = dct_make_tables({quality, 3, layout}, kSize, kSize);
  EXPECT_TRUE(t.ok()) << t.status().message();
  return std::move(t).value();
}

std::vector<uint8_t> checker() {
  std::vector<uint8_t> p(size_t(kSize) * kSize * 3);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      uint8_t* t = &p[(size_t(y) * kSize + x) * 3];
      const bool red = (x / 8 + y / 8) % 2 == 0;
      t[0] = red ? 255 : 0;
      t[2] = red ? 0 : 255;
    }
  return p;
}

// Smooth colour with fine noise, as photographs are.
std::vector<uint8_t> photo_like() {
  Lcg64 rng{3};
  std::vector<uint8_t> p(size_t(kSize) * kSize * 3);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      for (int c = 0; c < 3; ++c) {
        const double v =
            128 + 60 * std::sin(0.05 * x + c) * std::cos(0.04 * y) + int(rng.next() >> 27) - 16;
        p[(size_t(y) * kSize + x) * 3 + c] = uint8_t(std::clamp(v, 0.0, 255.0));
      }
  return p;
}

double psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
  return s == 0 ? INFINITY : 10 * std::log10(255.0 * 255.0 * double(a.size()) / s);
}

size_t lossless_bytes(const std::vector<uint8_t>& page) {
  std::vector<uint8_t> z;
  EXPECT_TRUE(zstd_compress(page, 3, z).ok());
  return z.size() + 1;
}

struct Coded {
  uint8_t mode = 0;
  std::vector<uint8_t> bytes, decoded;
};

Coded code(const DctTables& t, const std::vector<uint8_t>& page, DctModeSettings s = {}) {
  Coded c;
  c.decoded.resize(page.size());
  auto mode = dct_encode_page_modes(t, page.data(), kSize, 3, s, c.bytes, c.decoded.data());
  EXPECT_TRUE(mode.ok()) << mode.status().message();
  c.mode = mode.ok() ? *mode : 255;
  // What the reader gets is what the encoder reported.
  std::vector<uint8_t> back(page.size());
  EXPECT_TRUE(dct_decode_page_modes(t, c.bytes, kSize, back).ok());
  EXPECT_EQ(back, c.decoded);
  return c;
}

TEST(DctPageModes, SaturatedCheckerIsNeverLargerThanLossless) {
  const auto page = checker();
  for (int q : {25, 50, 75, 90, 100}) {
    const auto t = tables(q);
    const Coded c = code(*t, page);
    EXPECT_LE(c.bytes.size(), lossless_bytes(page)) << "q" << q;
    EXPECT_GT(psnr(page, c.decoded), 40.0) << "q" << q;  // the default mode gave ~17 dB
  }
  const Coded top = code(*tables(100), page);
  EXPECT_EQ(top.mode, kDctModeLossless);
  EXPECT_EQ(top.decoded, page);
}

TEST(DctPageModes, PhotographsKeepTheDefaultMode) {
  const auto page = photo_like();
  const auto t = tables(75);
  const Coded c = code(*t, page);
  EXPECT_EQ(c.mode, 0);
  std::vector<uint8_t> plain;
  ASSERT_TRUE(dct_encode_page(*t, page.data(), kSize, kSize, plain).ok());
  EXPECT_EQ(c.bytes, plain);
}

// An image's edge page or coarse level: smooth colour in one corner, the rest its edge texels
// repeated. The page's own error is small (most of it is padding), and a lambda taken from it
// alone stored such pages lossless at q90-q95, 6x their default form (whole Kodak pyramids: +1.5%
// bytes at equal PSNR). The layer's slope bounds lambda now.
TEST(DctPageModes, MostlyPaddingPagesKeepTheDefaultMode) {
  for (int w : {48, 96}) {
    std::vector<uint8_t> page(size_t(kSize) * kSize * 3);
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x)
        for (int c = 0; c < 3; ++c) {
          const int u = std::min(x, w - 1), v = std::min(y, 63);
          page[(size_t(y) * kSize + x) * 3 + c] =
              uint8_t(std::lround(128 + 20 * std::sin(0.15 * u + c) * std::cos(0.12 * v)));
        }
    for (int q : {50, 75, 90, 95}) {
      const Coded c = code(*tables(q), page);
      EXPECT_EQ(c.mode, 0) << w << " texels wide, q" << q << ": " << dct_mode_name(c.mode);
    }
  }
}

TEST(DctPageModes, ErrorFloorHolds) {
  const auto page = photo_like();
  const auto t = tables(30);
  const double plain = psnr(page, code(*t, page, {true, 0, 3}).decoded);
  for (double floor : {plain + 1, plain + 4, 50.0}) {
    const Coded c = code(*t, page, {true, floor, 3});
    EXPECT_GE(psnr(page, c.decoded), floor) << floor;
    EXPECT_NE(c.mode, 0) << floor;
  }
}

TEST(DctPageModes, DisabledGivesTheDefaultMode) {
  const auto page = checker();
  const Coded c = code(*tables(75), page, {false, 0, 3});
  EXPECT_EQ(c.mode, 0);
  EXPECT_EQ(c.bytes[0], 0);
}

TEST(DctPageModes, DamagedLosslessPagesAreCorrupt) {
  const auto page = checker();
  const auto t = tables(100);
  Coded c = code(*t, page);
  ASSERT_EQ(c.mode, kDctModeLossless);
  std::vector<uint8_t> back(page.size());
  for (size_t n : {size_t(1), size_t(2), c.bytes.size() - 1}) {
    const std::span<const uint8_t> cut(c.bytes.data(), n);
    EXPECT_EQ(dct_decode_page_modes(*t, cut, kSize, back).code(), ErrorCode::kCorrupt) << n;
  }
  std::vector<uint8_t> wrong(page.size() - 1);
  EXPECT_EQ(dct_decode_page_modes(*t, c.bytes, kSize, wrong).code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace vt
