// DCT page modes (tables version 4): every mode round-trips, finer modes lose less, mode {}
// keeps the version-3 bytes, and the decoder refuses bad mode bytes and version-3 tables' use of
// the new page kinds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "codec/dct.h"
#include "common/hash.h"

namespace vt {
namespace {

constexpr int kSize = 64;

std::vector<uint8_t> busy_page(int channels) {
  Lcg64 rng{7};
  std::vector<uint8_t> p(size_t(kSize) * kSize * channels);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      for (int c = 0; c < channels; ++c)
        p[(size_t(y) * kSize + x) * channels + c] =
            uint8_t(((x / 4 + y / 4 + c) % 2 ? 200 : 40) + int(rng.next() >> 28));
  return p;
}

DctTablesPtr tables(int quality, int channels, DctPlaneLayout layout) {
  auto t = dct_make_tables({quality, channels, layout}, kSize, kSize);
  EXPECT_TRUE(t.ok()) << t.status().message();
  return std::move(t).value();
}

double sse(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
  return s;
}

TEST(DctModes, EveryModeRoundTripsAndFinerLosesLess) {
  const auto t = tables(50, 3, DctPlaneLayout::kYCoCg420);
  const auto page = busy_page(3);
  double previous = INFINITY;
  for (int finer = 0; finer <= kDctMaxFiner; ++finer) {
    double best_of_finer = INFINITY;
    for (bool full : {false, true}) {
      const DctPageMode mode{full, uint8_t(finer)};
      ASSERT_TRUE(dct_mode_applies(*t, mode));
      std::vector<uint8_t> data, back(page.size());
      ASSERT_TRUE(dct_encode_page(*t, page.data(), kSize, kSize, data, mode).ok());
      const uint8_t byte = uint8_t((full ? 1 : 0) | finer << 1);
      if (byte == 0) {
        EXPECT_EQ(data[0], 0);  // kind 0: the version-3 bytes
      } else {
        ASSERT_GE(data.size(), 2u);
        EXPECT_EQ(data[0], 3);
        EXPECT_EQ(data[1], byte);
      }
      ASSERT_TRUE(dct_decode_page(*t, data, kSize, kSize, back.data()).ok());
      best_of_finer = std::min(best_of_finer, sse(page, back));
    }
    EXPECT_LT(best_of_finer, previous) << "finer " << finer;
    previous = best_of_finer;
  }
}

TEST(DctModes, DefaultModeBytesAreTheOldOnes) {
  const auto t = tables(75, 4, DctPlaneLayout::kYCoCg420);
  const auto page = busy_page(4);
  std::vector<uint8_t> a, b;
  ASSERT_TRUE(dct_encode_page(*t, page.data(), kSize, kSize, a).ok());
  ASSERT_TRUE(dct_encode_page(*t, page.data(), kSize, kSize, b, DctPageMode{}).ok());
  EXPECT_EQ(a, b);
  EXPECT_EQ(a[0], 0);
}

TEST(DctModes, FullChromaNeedsSubsampledTables) {
  const auto t = tables(75, 3, DctPlaneLayout::kPlanes);
  EXPECT_FALSE(dct_mode_applies(*t, {true, 0}));
  EXPECT_TRUE(dct_mode_applies(*t, {false, 2}));
  EXPECT_FALSE(dct_mode_applies(*t, {false, kDctMaxFiner + 1}));
  const auto page = busy_page(3);
  std::vector<uint8_t> data;
  EXPECT_EQ(dct_encode_page(*t, page.data(), kSize, kSize, data, {true, 0}).code(),
            ErrorCode::kInvalidArgument);
}

TEST(DctModes, BadModeBytesAndLosslessKindAreRefused) {
  const auto planes = tables(75, 3, DctPlaneLayout::kPlanes);
  const auto page = busy_page(3);
  std::vector<uint8_t> data, back(page.size());
  ASSERT_TRUE(dct_encode_page(*planes, page.data(), kSize, kSize, data, {false, 1}).ok());
  for (uint8_t bad : {uint8_t(0), uint8_t(1), uint8_t(8), uint8_t(255)}) {
    auto d = data;
    d[1] = bad;  // 1: full chroma, which plane tables do not have
    EXPECT_EQ(dct_decode_page(*planes, d, kSize, kSize, back.data()).code(), ErrorCode::kCorrupt)
        << int(bad);
  }
  EXPECT_EQ(dct_decode_page(*planes, std::vector<uint8_t>{3}, kSize, kSize, back.data()).code(),
            ErrorCode::kCorrupt);
  // Lossless pages (zstd) belong to the layer codec.
  EXPECT_EQ(
      dct_decode_page(*planes, std::vector<uint8_t>{4, 1, 2}, kSize, kSize, back.data()).code(),
      ErrorCode::kCorrupt);
}

TEST(DctModes, VersionThreeTablesReadAndRefuseNewPageKinds) {
  const auto t = tables(75, 3, DctPlaneLayout::kYCoCg420);
  auto bytes = dct_serialize_tables(*t);
  EXPECT_EQ(bytes[4], 4);
  bytes[4] = 3;
  auto old = dct_parse_tables(bytes);
  ASSERT_TRUE(old.ok()) << old.status().message();
  EXPECT_EQ(dct_tables_version(**old), 3);
  EXPECT_EQ(dct_serialize_tables(**old), bytes);  // re-written as read
  EXPECT_FALSE(dct_mode_applies(**old, {false, 1}));
  const auto page = busy_page(3);
  std::vector<uint8_t> v3, v4, back(page.size());
  ASSERT_TRUE(dct_encode_page(**old, page.data(), kSize, kSize, v3).ok());
  ASSERT_TRUE(dct_encode_page(*t, page.data(), kSize, kSize, v4).ok());
  EXPECT_EQ(v3, v4);
  ASSERT_TRUE(dct_decode_page(**old, v3, kSize, kSize, back.data()).ok());
  ASSERT_TRUE(dct_encode_page(*t, page.data(), kSize, kSize, v4, {false, 1}).ok());
  const Status s = dct_decode_page(**old, v4, kSize, kSize, back.data());
  EXPECT_EQ(s.code(), ErrorCode::kCorrupt);
  EXPECT_NE(s.message().find("unknown page kind"), std::string::npos) << s.message();
  bytes[4] = 5;
  const auto newer = dct_parse_tables(bytes);
  EXPECT_EQ(newer.status().code(), ErrorCode::kUnsupported);
  EXPECT_NE(newer.status().message().find("newer vtbake"), std::string::npos);
}

}  // namespace
}  // namespace vt
