// The JPEG anchor: abbreviated page streams share one tables-only stream, decode back close to
// the page, and a bad stream is an error, not a crash. vtbake-bench runs a kind end to end.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "bench/jpeg_anchor.h"
#include "samples/sample_scene.h"

namespace vt::bench {
namespace {

constexpr int kSize = 64;

std::vector<uint8_t> smooth_page(int seed) {
  std::vector<uint8_t> rgb(size_t(kSize) * kSize * 3);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      for (int c = 0; c < 3; ++c)
        rgb[(size_t(y) * kSize + x) * 3 + c] =
            uint8_t(128 + 100 * std::sin(0.1 * (x + seed) + 0.07 * y * (c + 1)));
  return rgb;
}

double psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  double se = 0;
  for (size_t i = 0; i < a.size(); ++i) se += (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
  return 10 * std::log10(255.0 * 255.0 * double(a.size()) / std::max(se, 1e-9));
}

bool has_marker(const std::vector<uint8_t>& s, uint8_t marker) {
  for (size_t i = 0; i + 1 < s.size(); ++i)
    if (s[i] == 0xFF && s[i + 1] == marker) return true;
  return false;
}

TEST(JpegAnchor, PagesShareTheTablesAndDecodeBack) {
  auto encoder = JpegPageEncoder::create({.page_size = kSize, .quality = 90});
  ASSERT_TRUE(encoder.ok()) << encoder.status().message();
  EXPECT_TRUE(has_marker(encoder->tables(), 0xDB));  // quantisation tables (DQT)
  auto decoder = JpegPageDecoder::create(kSize, encoder->tables());
  ASSERT_TRUE(decoder.ok()) << decoder.status().message();
  for (int seed : {0, 17}) {
    const std::vector<uint8_t> page = smooth_page(seed);
    std::vector<uint8_t> coded, back(page.size());
    ASSERT_TRUE(encoder->encode(page.data(), coded).ok());
    EXPECT_FALSE(has_marker(coded, 0xDB)) << "an abbreviated page carries no tables";
    EXPECT_LT(coded.size(), page.size() / 4);
    ASSERT_TRUE(decoder->decode(coded, back.data()).ok());
    EXPECT_GT(psnr(page, back), 35.0) << seed;
  }
}

TEST(JpegAnchor, SubsamplingCostsChromaDetail) {
  std::vector<uint8_t> page(size_t(kSize) * kSize * 3);
  for (size_t i = 0; i < page.size() / 3; ++i) page[i * 3 + (i % 2 ? 0 : 2)] = 255;  // red/blue
  double quality[2];
  for (int sub = 0; sub < 2; ++sub) {
    auto encoder =
        JpegPageEncoder::create({.page_size = kSize, .quality = 95, .subsample = sub == 1});
    ASSERT_TRUE(encoder.ok());
    auto decoder = JpegPageDecoder::create(kSize, encoder->tables());
    ASSERT_TRUE(decoder.ok());
    std::vector<uint8_t> coded, back(page.size());
    ASSERT_TRUE(encoder->encode(page.data(), coded).ok());
    ASSERT_TRUE(decoder->decode(coded, back.data()).ok());
    quality[sub] = psnr(page, back);
  }
  EXPECT_GT(quality[0], quality[1] + 3.0);  // 4:4:4 keeps the per-texel colour alternation
}

TEST(JpegAnchor, BadStreamsAreErrors) {
  auto encoder = JpegPageEncoder::create({.page_size = kSize});
  ASSERT_TRUE(encoder.ok());
  const std::vector<uint8_t> junk = {1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_FALSE(JpegPageDecoder::create(kSize, junk).ok());
  auto decoder = JpegPageDecoder::create(kSize, encoder->tables());
  ASSERT_TRUE(decoder.ok());
  std::vector<uint8_t> back(size_t(kSize) * kSize * 3);
  const Status bad = decoder->decode(junk, back.data());
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("libjpeg"), std::string::npos) << bad.message();
  // The decoder is still usable after an error.
  const std::vector<uint8_t> page = smooth_page(3);
  std::vector<uint8_t> coded;
  ASSERT_TRUE(encoder->encode(page.data(), coded).ok());
  EXPECT_TRUE(decoder->decode(coded, back.data()).ok());
}

TEST(VtbakeBench, CodecKindReportsJpegAgainstDct) {
  const std::string dir = ::testing::TempDir() + "vt_bench_cli/";
  std::filesystem::create_directories(dir);
  ASSERT_TRUE(write_texture(dir + "colour.png", 256, 128, 3, [](double u, double v, float* t) {
                t[0] = float(u), t[1] = float(v), t[2] = float(0.5 + 0.5 * std::sin(40 * u * v));
              }).ok());
  const std::string out = dir + "report.json";
  const std::string cmd = std::string(VTBAKE_BENCH_BINARY) +
                          " --quiet --json codec --repeats 1 --slow-pages 1 --dct-qualities 75"
                          " --jpeg-qualities 50,90 " +
                          dir + "colour.png > " + out;
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream in(out);
  const auto report = nlohmann::json::parse(in);
  EXPECT_EQ(report["colour_pages"], 2);
  int jpeg_rows = 0;
  for (const auto& row : report["rows"])
    if (row["name"].get<std::string>().starts_with("JPEG q")) ++jpeg_rows;
  EXPECT_EQ(jpeg_rows, 4);  // two qualities, each alone and + BC1
  EXPECT_EQ(
      std::system(
          (std::string(VTBAKE_BENCH_BINARY) + " codec --repeats 0 x.png 2>/dev/null").c_str()) >>
          8,
      2);
}

TEST(VtbakeBench, Bc6hKindReportsEveryLevel) {
  const std::string dir = ::testing::TempDir() + "vt_bench_bc6h/";
  std::filesystem::create_directories(dir);
  const std::string out = dir + "report.json";
  // The synthetic HDR set, small pages: three rows, the levels in order of quality.
  const std::string cmd =
      std::string(VTBAKE_BENCH_BINARY) + " --quiet --json bc6h --repeats 1 --page-size 16 > " + out;
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream in(out);
  const auto report = nlohmann::json::parse(in);
  ASSERT_EQ(report.size(), 3u);
  EXPECT_EQ(report[0]["level"], "realtime");
  EXPECT_EQ(report[2]["level"], "high");
  EXPECT_GT(report[0]["encode_mtexel_s"].get<double>(), 0.0);
  EXPECT_GT(report[0]["tonemapped_psnr_db"].get<double>(), 35.0);
  EXPECT_GE(report[2]["tonemapped_psnr_db"].get<double>(),
            report[0]["tonemapped_psnr_db"].get<double>());
  EXPECT_LT(report[1]["bc6h_zstd_bits_per_texel"].get<double>(),
            report[1]["half_zstd_bits_per_texel"].get<double>());
  EXPECT_EQ(
      std::system((std::string(VTBAKE_BENCH_BINARY) + " bc6h --page-size 6 2>/dev/null").c_str()) >>
          8,
      2);
}

}  // namespace
}  // namespace vt::bench
