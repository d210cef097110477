// Page DCT codec: round trips with measured error bounds, monotonicity, constant pages,
// determinism, table serialisation and corrupt input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <vector>

#include "codec/dct.h"
#include "codec/dct_rans.h"
#include "common/hash.h"

namespace vt::dct_test {

enum class Pattern { kGradient, kNoise, kEdges, kText, kMixed };

inline const char* pattern_name(Pattern p) {
  static constexpr const char* kNames[] = {"gradient", "noise", "edges", "text", "mixed"};
  return kNames[int(p)];
}

inline uint8_t pattern_value(Pattern p, int x, int y, int c, int w, int h, Lcg64& rng,
                             const std::vector<uint8_t>& glyphs) {
  switch (p) {
    case Pattern::kGradient: {
      const double t = (x * (1.0 + 0.3 * c) + y * (0.7 + 0.2 * c)) / (w + h);
      return uint8_t(
          std::clamp(20.0 + 215.0 * t + 10.0 * std::sin(0.05 * x * (c + 1)), 0.0, 255.0));
    }
    case Pattern::kNoise:
      return uint8_t(rng.next() >> 24);
    case Pattern::kEdges: {
      const bool bar = ((x / 5) + c) % 2 == 0;
      const bool diag = x * 3 + y * 2 > (w + h) * 2 / 2;
      return uint8_t(bar ? (diag ? 220 - 30 * c : 40 + 20 * c) : (diag ? 90 : 180 - 25 * c));
    }
    case Pattern::kText:
      return glyphs[size_t(y) * w + x] ? uint8_t(25 + 10 * c) : uint8_t(235 - 5 * c);
    case Pattern::kMixed: {
      const Pattern q = x < w / 2 ? (y < h / 2 ? Pattern::kGradient : Pattern::kText)
                                  : (y < h / 2 ? Pattern::kEdges : Pattern::kNoise);
      if (q == Pattern::kNoise) {
        // Noise riding on a gradient, like real texture detail.
        return uint8_t(std::clamp(60 + x / 2 + c * 20 + int(rng.next() >> 27) - 16, 0, 255));
      }
      return pattern_value(q, x, y, c, w, h, rng, glyphs);
    }
  }
  return 0;
}

// A width x height page of `channels` interleaved 8-bit channels.
inline std::vector<uint8_t> make_page(Pattern p, int w, int h, int channels, uint64_t seed = 1) {
  Lcg64 rng{seed};
  // Text-like: short horizontal and vertical strokes on a grid of 6x8 character cells.
  std::vector<uint8_t> glyphs(size_t(w) * h, 0);
  for (int cy = 0; cy + 8 <= h; cy += 9) {
    for (int cx = 0; cx + 6 <= w; cx += 7) {
      for (int s = 0; s < 3; s++) {
        const bool horizontal = rng.below(2) == 0;
        const int x0 = cx + int(rng.below(horizontal ? 2 : 6)),
                  y0 = cy + int(rng.below(horizontal ? 8 : 3));
        for (int i = 0; i < (horizontal ? 4 : 6); i++) {
          const int x = horizontal ? x0 + i : x0, y = horizontal ? y0 : y0 + i;
          if (x < w && y < h) glyphs[size_t(y) * w + x] = 1;
        }
      }
    }
  }
  std::vector<uint8_t> page(size_t(w) * h * channels);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      for (int c = 0; c < channels; c++)
        page[(size_t(y) * w + x) * channels + c] = pattern_value(p, x, y, c, w, h, rng, glyphs);
  return page;
}

// PSNR over all channels; 99 dB when identical.
inline double psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  double se = 0;
  for (size_t i = 0; i < a.size(); i++) {
    const double d = double(a[i]) - double(b[i]);
    se += d * d;
  }
  if (se == 0) return 99.0;
  return 10.0 * std::log10(255.0 * 255.0 * double(a.size()) / se);
}

inline int max_abs_error(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  int m = 0;
  for (size_t i = 0; i < a.size(); i++) m = std::max(m, std::abs(int(a[i]) - int(b[i])));
  return m;
}

}  // namespace vt::dct_test

namespace vt {
namespace {

using dct_test::make_page;
using dct_test::Pattern;

struct Layout {
  int channels;
  DctPlaneLayout layout;
};

const Layout kLayouts[] = {
    {1, DctPlaneLayout::kPlanes},   {2, DctPlaneLayout::kPlanes},   {3, DctPlaneLayout::kPlanes},
    {4, DctPlaneLayout::kPlanes},   {3, DctPlaneLayout::kYCoCg},    {4, DctPlaneLayout::kYCoCg},
    {3, DctPlaneLayout::kYCoCg420}, {4, DctPlaneLayout::kYCoCg420},
};

DctTablesPtr tables_for(int quality, Layout l, int w = 128, int h = 128,
                        std::span<const std::span<const uint8_t>> training = {}) {
  DctSettings s;
  s.quality = quality;
  s.channels = l.channels;
  s.layout = l.layout;
  auto t = dct_make_tables(s, w, h, training);
  EXPECT_TRUE(t.ok()) << t.status().message();
  return std::move(t).value();
}

struct RoundTrip {
  double psnr;
  int max_error;
  size_t bytes;
};

RoundTrip round_trip(const DctTables& t, const std::vector<uint8_t>& page, int w, int h) {
  std::vector<uint8_t> coded;
  EXPECT_TRUE(dct_encode_page(t, page.data(), w, h, coded).ok());
  std::vector<uint8_t> decoded(page.size(), 0xCD);
  const Status s = dct_decode_page(t, coded, w, h, decoded.data());
  EXPECT_TRUE(s.ok()) << s.message();
  return {dct_test::psnr(page, decoded), dct_test::max_abs_error(page, decoded), coded.size()};
}

// Lowest PSNR measured over the full-resolution layouts (kPlanes, kYCoCg; 1-4 channels) and
// over the 4:2:0 layouts, less ~0.5 dB. 4:2:0 cannot carry per-texel colour noise or colour
// edges, which its low figures on those patterns show.
struct Bound {
  Pattern pattern;
  int quality;
  double full_res_db;
  double chroma420_db;
};
const Bound kBounds[] = {
    {Pattern::kGradient, 25, 36.7, 36.8}, {Pattern::kGradient, 75, 48.5, 48.0},
    {Pattern::kGradient, 95, 54.5, 54.0}, {Pattern::kNoise, 25, 19.8, 17.2},
    {Pattern::kNoise, 75, 32.0, 18.5},    {Pattern::kNoise, 95, 45.5, 18.6},
    {Pattern::kEdges, 25, 28.4, 20.3},    {Pattern::kEdges, 75, 40.5, 20.7},
    {Pattern::kEdges, 95, 55.0, 20.7},    {Pattern::kText, 25, 24.9, 24.8},
    {Pattern::kText, 75, 35.4, 32.8},     {Pattern::kText, 95, 47.8, 35.4},
    {Pattern::kMixed, 25, 29.1, 24.5},    {Pattern::kMixed, 75, 37.5, 25.9},
    {Pattern::kMixed, 95, 49.0, 26.1},
};

TEST(Dct, RoundTripMeetsMeasuredPsnrForEveryLayout) {
  for (const Bound& b : kBounds) {
    for (Layout l : kLayouts) {
      auto t = tables_for(b.quality, l);
      const auto page = make_page(b.pattern, 128, 128, l.channels);
      const RoundTrip r = round_trip(*t, page, 128, 128);
      const double bound = l.layout == DctPlaneLayout::kYCoCg420 ? b.chroma420_db : b.full_res_db;
      EXPECT_GE(r.psnr, bound) << dct_test::pattern_name(b.pattern) << " q" << b.quality << " "
                               << l.channels << " channels, layout " << int(l.layout);
      // Stays far from a pathological bit rate (8 bits per texel per channel is raw).
      EXPECT_LT(r.bytes, size_t(128 * 128 * l.channels)) << dct_test::pattern_name(b.pattern);
    }
  }
}

TEST(Dct, SmoothContentHasSmallMaxError) {
  // A gradient at high quality stays within a couple of levels everywhere, in every layout.
  for (Layout l : kLayouts) {
    auto t = tables_for(95, l);
    const auto page = make_page(Pattern::kGradient, 128, 128, l.channels);
    EXPECT_LE(round_trip(*t, page, 128, 128).max_error, 2) << int(l.layout);
  }
}

TEST(Dct, HigherQualityGivesHigherPsnrAndMoreBytes) {
  for (Layout l : {kLayouts[0], kLayouts[4], kLayouts[6]}) {
    const auto page = make_page(Pattern::kMixed, 128, 128, l.channels, 7);
    RoundTrip prev{0, 0, 0};
    for (int q = 10; q <= 100; q += 10) {
      auto t = tables_for(q, l);
      const RoundTrip r = round_trip(*t, page, 128, 128);
      if (q > 10) {
        EXPECT_GT(r.psnr, prev.psnr) << "q" << q << " layout " << int(l.layout);
        EXPECT_GT(r.bytes, prev.bytes) << "q" << q << " layout " << int(l.layout);
      }
      prev = r;
    }
  }
}

TEST(Dct, ConstantPagesDecodeExactlyAndCostAFewBytes) {
  Lcg64 rng{99};
  for (Layout l : kLayouts) {
    for (int q : {1, 50, 100}) {
      auto t = tables_for(q, l);
      for (int trial = 0; trial < 4; trial++) {
        std::vector<uint8_t> texel(size_t(l.channels));
        for (auto& v : texel) v = uint8_t(trial == 0 ? 0 : trial == 1 ? 255 : int(rng.below(256)));
        std::vector<uint8_t> page;
        for (int i = 0; i < 128 * 128; i++) page.insert(page.end(), texel.begin(), texel.end());
        const RoundTrip r = round_trip(*t, page, 128, 128);
        EXPECT_EQ(r.max_error, 0) << "layout " << int(l.layout) << " q" << q;
        EXPECT_LE(r.bytes, size_t(3 + l.channels));  // flag, texel, end marker
      }
    }
  }
}

TEST(Dct, NearlyFlatPagesStaySmallAndAccurate) {
  // One texel differs: not a constant page, but almost all blocks are DC-only.
  for (Layout l : kLayouts) {
    auto t = tables_for(75, l);
    std::vector<uint8_t> page(size_t(128) * 128 * l.channels, 140);
    page[size_t(64 * 128 + 64) * l.channels] = 150;
    const RoundTrip r = round_trip(*t, page, 128, 128);
    EXPECT_LE(r.max_error, 10);
    EXPECT_GE(r.psnr, 50.0);
    EXPECT_LT(r.bytes, size_t(64 * l.channels));
  }
}

TEST(Dct, OtherPageSizes) {
  // Sizes whose half-resolution chroma is not a whole number of blocks exercise the padding.
  const int sizes[][2] = {{8, 8}, {24, 40}, {136, 8}, {256, 72}};
  for (const auto& wh : sizes) {
    for (Layout l : kLayouts) {
      auto t = tables_for(90, l, wh[0], wh[1]);
      const auto page = make_page(Pattern::kGradient, wh[0], wh[1], l.channels);
      const RoundTrip r = round_trip(*t, page, wh[0], wh[1]);
      EXPECT_GE(r.psnr, 40.0) << wh[0] << "x" << wh[1] << " layout " << int(l.layout);
    }
  }
}

TEST(Dct, EncodeAndDecodeAreDeterministic) {
  for (Layout l : kLayouts) {
    auto t = tables_for(60, l);
    const auto page = make_page(Pattern::kMixed, 128, 128, l.channels, 3);
    std::vector<uint8_t> a, b;
    ASSERT_TRUE(dct_encode_page(*t, page.data(), 128, 128, a).ok());
    ASSERT_TRUE(dct_encode_page(*t, page.data(), 128, 128, b).ok());
    EXPECT_EQ(a, b);
    // Tables that went through bytes code and decode identically.
    auto parsed = dct_parse_tables(dct_serialize_tables(*t));
    ASSERT_TRUE(parsed.ok()) << parsed.status().message();
    std::vector<uint8_t> c;
    ASSERT_TRUE(dct_encode_page(**parsed, page.data(), 128, 128, c).ok());
    EXPECT_EQ(a, c);
    std::vector<uint8_t> d1(page.size(), 0), d2(page.size(), 0xFF);
    ASSERT_TRUE(dct_decode_page(*t, a, 128, 128, d1.data()).ok());
    ASSERT_TRUE(dct_decode_page(**parsed, a, 128, 128, d2.data()).ok());
    EXPECT_EQ(d1, d2);
  }
}

TEST(Dct, HighestFrequencyAndLargestCoefficientsRoundTrip) {
  // A one-texel checkerboard puts nearly all energy in the last zigzag position (the first
  // half of the last coefficient pair, whose second half is past the block) at the largest
  // magnitudes (escape tokens); quality 100 keeps them, step 1. Rows and columns of mid grey
  // between the tiles give every block other coefficients too.
  const int size = 128;
  std::vector<uint8_t> page(size_t(size) * size);
  for (int y = 0; y < size; y++) {
    for (int x = 0; x < size; x++) {
      page[size_t(y) * size + x] = (x / 8 + y / 8) % 3 == 0 ? uint8_t(128 + (x + y) % 7)
                                   : (x + y) % 2            ? uint8_t(255)
                                                            : uint8_t(0);
    }
  }
  for (int q : {100, 90}) {
    auto t = tables_for(q, {1, DctPlaneLayout::kPlanes});
    const RoundTrip r = round_trip(*t, page, size, size);
    // Measured: 61.9 dB, max error 1 at q100; 48.3 dB, 3 at q90.
    EXPECT_GE(r.psnr, q == 100 ? 61.0 : 47.5) << "q" << q;
    EXPECT_LE(r.max_error, q == 100 ? 1 : 4) << "q" << q;
  }
}

TEST(Dct, DecodedTexelsArePinned) {
  // Integer decoding is part of the format: fixed tables and bytes must always give the same
  // texels. A change here (entropy decoding, IDCT, rounding, upsampling, colour
  // transform) is a format change and needs a new tables version.
  auto t = tables_for(50, {4, DctPlaneLayout::kYCoCg420});
  auto bytes = dct_serialize_tables(*t);
  // Untrained tables: a 13-byte header, then plane 0's 64 quantiser steps, made uneven here.
  for (int i = 0; i < 64; i++) bytes[13 + size_t(i)] = uint8_t(3 + (i * 5) % 11);
  auto pinned = dct_parse_tables(bytes);
  ASSERT_TRUE(pinned.ok()) << pinned.status().message();
  // A busy page, so most coefficient paths and every plane carry data.
  const auto page = make_page(Pattern::kMixed, 64, 64, 4, 2024);
  std::vector<uint8_t> data;
  ASSERT_TRUE(dct_encode_page(**pinned, page.data(), 64, 64, data).ok());
  std::vector<uint8_t> decoded(size_t(64) * 64 * 4);
  ASSERT_TRUE(dct_decode_page(**pinned, data, 64, 64, decoded.data()).ok());
  // The encoder (floating point, free to improve) is pinned too; when it changes on purpose,
  // check the decoded PSNR is sane and update both numbers.
  uint64_t hc = 1469598103934665603ull;
  for (uint8_t v : data) hc = (hc ^ v) * 1099511628211ull;
  EXPECT_EQ(hc, 15488033857020092065ull);
  EXPECT_GT(dct_test::psnr(page, decoded), 25.0);  // 4:2:0 on colour noise: ~27.3 dB
  uint64_t h = 1469598103934665603ull;
  for (uint8_t v : decoded) h = (h ^ v) * 1099511628211ull;
  EXPECT_EQ(h, 17576140493363672463ull);
  // The pinned output must exercise real arithmetic, not only clamping.
  std::vector<int> histogram(256, 0);
  for (uint8_t v : decoded) histogram[v]++;
  EXPECT_GT(std::count_if(histogram.begin(), histogram.end(), [](int c) { return c > 0; }), 100);
}

// The encoder chooses each block's levels by rate and distortion: a lone small coefficient at the
// end of a block costs a pair token for every pair up to it, more than its error is worth, and is
// dropped although the deadzone quantiser alone would keep it.
TEST(Dct, RateDistortionLevelsDropALoneCostlyCoefficient) {
  auto t = tables_for(50, {1, DctPlaneLayout::kPlanes}, 64, 64);
  // The step of the (7, 7) coefficient, the last in zigzag order, from the serialised tables:
  // plane 0's steps (natural order) follow the 13-byte header.
  const int step = dct_serialize_tables(*t)[13 + 63];
  // A flat page with, in one block, the (7, 7) basis function at 0.75 steps: the deadzone
  // rounding (+0.36) makes it a level of 1.
  std::vector<uint8_t> page(64 * 64, 128);
  for (int y = 0; y < 8; y++) {
    for (int x = 0; x < 8; x++) {
      const double b = 0.25 * std::cos((2 * x + 1) * 7 * std::numbers::pi / 16) *
                       std::cos((2 * y + 1) * 7 * std::numbers::pi / 16);
      page[size_t(16 + y) * 64 + 24 + x] = uint8_t(std::lround(128 + 0.75 * step * b));
    }
  }
  std::vector<uint8_t> coded, decoded(page.size());
  ASSERT_TRUE(dct_encode_page(*t, page.data(), 64, 64, coded).ok());
  ASSERT_TRUE(dct_decode_page(*t, coded, 64, 64, decoded.data()).ok());
  EXPECT_NE(page, std::vector<uint8_t>(page.size(), 128));
  EXPECT_EQ(decoded, std::vector<uint8_t>(page.size(), 128)) << "the lone level is dropped";
}

TEST(Dct, TrainedTablesCodeSimilarPagesSmaller) {
  const Layout l{3, DctPlaneLayout::kYCoCg420};
  std::vector<std::vector<uint8_t>> training;
  for (uint64_t seed = 1; seed <= 4; seed++) {
    training.push_back(make_page(Pattern::kMixed, 128, 128, 3, seed));
  }
  std::vector<std::span<const uint8_t>> spans(training.begin(), training.end());
  auto trained = tables_for(75, l, 128, 128, spans);
  auto plain = tables_for(75, l);
  const auto page = make_page(Pattern::kMixed, 128, 128, 3, 42);  // not in the training set
  const RoundTrip a = round_trip(*trained, page, 128, 128);
  const RoundTrip b = round_trip(*plain, page, 128, 128);
  EXPECT_LT(a.bytes, b.bytes);
  // Training changes the entropy coding, and the levels only through the rate estimates the
  // encoder's rate-distortion pass takes from the models.
  EXPECT_NEAR(a.psnr, b.psnr, 0.05);
}

TEST(Dct, AdaptiveModelsOnTrainedTablesChangeOnlyTheBytes) {
  std::vector<std::vector<uint8_t>> training;
  for (uint64_t seed = 1; seed <= 4; seed++) {
    training.push_back(make_page(Pattern::kMixed, 128, 128, 3, seed));
  }
  std::vector<std::span<const uint8_t>> spans(training.begin(), training.end());
  DctSettings s;
  auto fixed = dct_make_tables(s, 128, 128, spans);
  s.adaptive = true;
  auto adaptive = dct_make_tables(s, 128, 128, spans);
  ASSERT_TRUE(fixed.ok() && adaptive.ok());
  const auto fixed_bytes = dct_serialize_tables(**fixed);
  const auto adaptive_bytes = dct_serialize_tables(**adaptive);
  EXPECT_EQ(fixed_bytes[12], 0);  // the mode byte
  EXPECT_EQ(adaptive_bytes[12], 1);
  auto parsed = dct_parse_tables(adaptive_bytes);
  ASSERT_TRUE(parsed.ok());
  const auto page = make_page(Pattern::kText, 128, 128, 3, 9);
  std::vector<uint8_t> a, b, c;
  ASSERT_TRUE(dct_encode_page(**fixed, page.data(), 128, 128, a).ok());
  ASSERT_TRUE(dct_encode_page(**adaptive, page.data(), 128, 128, b).ok());
  ASSERT_TRUE(dct_encode_page(**parsed, page.data(), 128, 128, c).ok());
  EXPECT_NE(a, b);
  EXPECT_EQ(b, c);
  std::vector<uint8_t> da(page.size()), db(page.size());
  ASSERT_TRUE(dct_decode_page(**fixed, a, 128, 128, da.data()).ok());
  ASSERT_TRUE(dct_decode_page(**parsed, b, 128, 128, db.data()).ok());
  EXPECT_EQ(da, db);
  EXPECT_FALSE(dct_decode_page(**fixed, b, 128, 128, da.data()).ok());  // modes do not mix
}

TEST(DctTables, SerialiseParseRoundTrip) {
  const auto page = make_page(Pattern::kMixed, 128, 128, 4, 5);
  const std::span<const uint8_t> one[] = {page};
  for (Layout l : kLayouts) {
    for (bool train : {false, true}) {
      const auto training =
          train && l.channels == 4 ? std::span(one) : std::span<const std::span<const uint8_t>>();
      auto t = tables_for(80, l, 128, 128, training);
      const auto bytes = dct_serialize_tables(*t);
      auto parsed = dct_parse_tables(bytes);
      ASSERT_TRUE(parsed.ok()) << parsed.status().message();
      EXPECT_EQ(dct_serialize_tables(**parsed), bytes);
    }
  }
}

TEST(DctTables, MalformedBytesAreRejected) {
  const auto page = make_page(Pattern::kMixed, 128, 128, 3, 5);
  const std::span<const uint8_t> one[] = {page};
  auto t = tables_for(80, {3, DctPlaneLayout::kYCoCg420}, 128, 128, one);
  const auto bytes = dct_serialize_tables(*t);
  // Every truncation.
  for (size_t n = 0; n < bytes.size(); n++) {
    auto r = dct_parse_tables(std::span(bytes.data(), n));
    ASSERT_FALSE(r.ok()) << n;
    EXPECT_EQ(r.status().code(), ErrorCode::kCorrupt) << n;
  }
  auto with = [&](size_t at, uint8_t v) {
    auto b = bytes;
    b[at] = v;
    return dct_parse_tables(b);
  };
  EXPECT_EQ(with(0, 'X').status().code(), ErrorCode::kCorrupt);    // magic
  EXPECT_EQ(with(4, 1).status().code(), ErrorCode::kUnsupported);  // version 1 (range coder)
  EXPECT_EQ(with(5, 0).status().code(), ErrorCode::kCorrupt);      // quality 0
  EXPECT_EQ(with(6, 5).status().code(), ErrorCode::kCorrupt);      // 5 channels
  EXPECT_EQ(with(7, 9).status().code(), ErrorCode::kCorrupt);      // layout
  EXPECT_EQ(with(8, 7).status().code(), ErrorCode::kCorrupt);      // width 135
  EXPECT_EQ(with(12, 2).status().code(), ErrorCode::kCorrupt);     // model mode
  EXPECT_EQ(with(13, 0).status().code(), ErrorCode::kCorrupt);     // zero quantiser step
  // The first model: its observation count, then 16 frequencies that must sum to the total.
  EXPECT_EQ(with(13 + 64, 200).status().code(), ErrorCode::kCorrupt);  // count beyond the cap
  EXPECT_EQ(with(13 + 65, uint8_t(bytes[13 + 65] ^ 1)).status().code(), ErrorCode::kCorrupt);
  auto longer = bytes;
  longer.push_back(0);
  EXPECT_EQ(dct_parse_tables(longer).status().code(), ErrorCode::kCorrupt);
  EXPECT_NE(dct_parse_tables(longer).status().message().find("trailing"), std::string::npos);
}

TEST(Dct, InvalidArgumentsAreRejected) {
  DctSettings s;
  s.quality = 0;
  EXPECT_EQ(dct_make_tables(s, 128, 128).status().code(), ErrorCode::kInvalidArgument);
  s.quality = 101;
  EXPECT_EQ(dct_make_tables(s, 128, 128).status().code(), ErrorCode::kInvalidArgument);
  s.quality = 75;
  s.channels = 2;  // YCoCg needs RGB
  EXPECT_EQ(dct_make_tables(s, 128, 128).status().code(), ErrorCode::kInvalidArgument);
  s.channels = 3;
  EXPECT_EQ(dct_make_tables(s, 100, 128).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(dct_make_tables(s, 0, 128).status().code(), ErrorCode::kInvalidArgument);
  const std::vector<uint8_t> small(10);
  const std::span<const uint8_t> bad[] = {small};
  EXPECT_EQ(dct_make_tables(s, 128, 128, bad).status().code(), ErrorCode::kInvalidArgument);
  auto t = tables_for(75, {3, DctPlaneLayout::kYCoCg420});
  std::vector<uint8_t> page(128 * 128 * 3), out;
  EXPECT_EQ(dct_encode_page(*t, page.data(), 130, 128, out).code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(dct_decode_page(*t, out, 128, 12, page.data()).code(), ErrorCode::kInvalidArgument);
}

// The plane decoder's two builds (baseline and AVX2 + BMI2, codec/dct.cpp) decode every page
// alike, valid or damaged: same status, same texels. Only the AVX2 build runs on an AVX2 host
// otherwise, so without this the baseline one would go untested there.
TEST(Dct, BaselineAndAvx2PlaneDecodersAgree) {
  if (!dct_detail::plane_decoder_uses_avx2()) GTEST_SKIP() << "one plane decoder build here";
  struct Baseline {
    Baseline() { dct_detail::force_baseline_plane_decoder(true); }
    ~Baseline() { dct_detail::force_baseline_plane_decoder(false); }
  };
  std::vector<std::vector<uint8_t>> training;
  for (uint64_t seed = 1; seed <= 2; seed++)
    training.push_back(make_page(Pattern::kMixed, 128, 128, 3, seed));
  std::vector<std::span<const uint8_t>> spans(training.begin(), training.end());
  // Static (trained) and adaptive (untrained) models; 4:2:0, full chroma and planes.
  std::vector<DctTablesPtr> tables;
  tables.push_back(tables_for(50, {3, DctPlaneLayout::kYCoCg420}, 128, 128, spans));
  tables.push_back(tables_for(90, {3, DctPlaneLayout::kYCoCg420}, 128, 128, spans));
  tables.push_back(tables_for(75, {4, DctPlaneLayout::kYCoCg}));
  tables.push_back(tables_for(30, {2, DctPlaneLayout::kPlanes}));
  Lcg64 rng{5};
  int compared = 0, damaged_ok = 0;
  for (const auto& t : tables) {
    const int ch = dct_tables_shape(*t).channels;
    for (Pattern p : {Pattern::kMixed, Pattern::kNoise, Pattern::kText}) {
      const auto page = make_page(p, 128, 128, ch, 77);
      std::vector<uint8_t> coded;
      ASSERT_TRUE(dct_encode_page(*t, page.data(), 128, 128, coded).ok());
      ASSERT_EQ(coded[0], 0) << "a coded page";  // not stored raw
      for (int i = 0; i < 40; i++) {
        auto bytes = coded;
        if (i > 0) bytes[1 + rng.below(bytes.size() - 1)] ^= uint8_t(1u << rng.below(8));
        std::vector<uint8_t> a(page.size(), 1), b(page.size(), 1);
        const Status sa = dct_decode_page(*t, bytes, 128, 128, a.data());
        Status sb;
        {
          Baseline baseline;
          EXPECT_FALSE(dct_detail::plane_decoder_uses_avx2());
          sb = dct_decode_page(*t, bytes, 128, 128, b.data());
        }
        ASSERT_EQ(sa.code(), sb.code()) << sa.message() << " / " << sb.message();
        if (i == 0) {
          ASSERT_TRUE(sa.ok()) << sa.message();
        }
        if (sa.ok()) {
          EXPECT_EQ(a, b);
        }
        damaged_ok += i > 0 && sa.ok();
        compared++;
      }
    }
  }
  EXPECT_EQ(compared, 4 * 3 * 40);
  EXPECT_GT(damaged_ok, 0);  // some flipped bits still decode: texels compared on damaged data
}

TEST(Dct, TruncatedAndCorruptPagesGiveErrorsNotCrashes) {
  for (Layout l : {kLayouts[0], kLayouts[3], kLayouts[6]}) {
    auto t = tables_for(75, l);
    const auto page = make_page(Pattern::kMixed, 128, 128, l.channels, 9);
    std::vector<uint8_t> coded;
    ASSERT_TRUE(dct_encode_page(*t, page.data(), 128, 128, coded).ok());
    std::vector<uint8_t> out(page.size());
    EXPECT_EQ(dct_decode_page(*t, {}, 128, 128, out.data()).code(), ErrorCode::kCorrupt);
    // Cut anywhere before the last 16 bytes: the decoder runs out of data and says so.
    int corrupt = 0, total = 0;
    for (size_t n = 0; n + 16 < coded.size(); n += 7) {
      const Status s = dct_decode_page(*t, std::span(coded.data(), n), 128, 128, out.data());
      EXPECT_TRUE(s.ok() || s.code() == ErrorCode::kCorrupt);
      corrupt += s.code() == ErrorCode::kCorrupt;
      total++;
    }
    EXPECT_EQ(corrupt, total) << "layout " << int(l.layout);
    // Flipped bits decode to something or fail cleanly; the sanitizers check the rest.
    Lcg64 rng{17};
    for (int i = 0; i < 50; i++) {
      auto bad = coded;
      bad[rng.below(bad.size())] ^= uint8_t(1u << rng.below(8));
      const Status s = dct_decode_page(*t, bad, 128, 128, out.data());
      EXPECT_TRUE(s.ok() || s.code() == ErrorCode::kCorrupt);
    }
  }
}

}  // namespace
}  // namespace vt
