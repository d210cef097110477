// Metrics against values computed by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "codec/metrics.h"

namespace vt {
namespace {

TEST(Metrics, PsnrOfKnownErrors) {
  // 2x2 RGB; channel 0 off by 1 everywhere, channel 1 off by 2 in one texel, channel 2 exact.
  std::vector<uint8_t> a = {10, 20, 30, 10, 20, 30, 10, 20, 30, 10, 20, 30};
  std::vector<uint8_t> b = {11, 20, 30, 11, 22, 30, 11, 20, 30, 11, 20, 30};
  auto e = compare_images(a.data(), b.data(), 2, 2, 3);
  ASSERT_TRUE(e.ok());
  EXPECT_DOUBLE_EQ(e->mse[0], 1.0);
  EXPECT_DOUBLE_EQ(e->mse[1], 1.0);  // 4 / 4
  EXPECT_DOUBLE_EQ(e->mse[2], 0.0);
  EXPECT_NEAR(e->psnr[0], 48.1308, 1e-4);  // 10 log10(65025)
  EXPECT_DOUBLE_EQ(e->psnr[2], kPsnrIdentical);
  EXPECT_DOUBLE_EQ(e->mse_rgb, 8.0 / 12.0);
  EXPECT_NEAR(e->psnr_rgb, 10 * std::log10(65025.0 * 12 / 8), 1e-9);
  EXPECT_EQ(e->max_abs[0], 1);
  EXPECT_EQ(e->max_abs[1], 2);
  EXPECT_EQ(e->max_abs_rgb, 2);
}

TEST(Metrics, AlphaIsOutsideTheRgbFigure) {
  std::vector<uint8_t> a = {0, 0, 0, 0}, b = {0, 0, 0, 200};
  auto e = compare_images(a.data(), b.data(), 1, 1, 4);
  ASSERT_TRUE(e.ok());
  EXPECT_DOUBLE_EQ(e->psnr_rgb, kPsnrIdentical);
  EXPECT_EQ(e->max_abs_all, 200);
  EXPECT_EQ(e->max_abs_rgb, 0);
}

TEST(Metrics, SsimIdenticalAndConstantImages) {
  std::vector<uint8_t> a(16 * 16), b(16 * 16);
  for (int i = 0; i < 256; ++i) a[i] = uint8_t(i * 7 % 256);
  auto same = ssim(a.data(), a.data(), 16, 16, 1);
  ASSERT_TRUE(same.ok());
  EXPECT_DOUBLE_EQ(*same, 1.0);
  // Two constant images A = 100, B = 110: every window has zero variance, so
  // SSIM = (2AB + C1) / (A^2 + B^2 + C1) with C1 = (0.01 * 255)^2 = 6.5025.
  std::fill(a.begin(), a.end(), 100);
  std::fill(b.begin(), b.end(), 110);
  auto s = ssim(a.data(), b.data(), 16, 16, 1);
  ASSERT_TRUE(s.ok());
  EXPECT_NEAR(*s, (2 * 100 * 110 + 6.5025) / (100 * 100 + 110 * 110 + 6.5025), 1e-12);
  // Inverted structure scores below zero.
  for (int i = 0; i < 256; ++i)
    a[i] = uint8_t((i & 1) ? 200 : 50), b[i] = uint8_t((i & 1) ? 50 : 200);
  auto inv = ssim(a.data(), b.data(), 16, 16, 1);
  ASSERT_TRUE(inv.ok());
  EXPECT_LT(*inv, -0.9);
  EXPECT_FALSE(ssim(a.data(), b.data(), 4, 4, 1).ok());
}

TEST(Metrics, AngularErrorOfKnownNormals) {
  // X = 255 (x = 1, z = 0) against Y = 255 (y = 1, z = 0), with the other component 128
  // (1/255 * 2 - ... = 0.00392): a right angle, less the small tilt both share.
  const uint8_t ref[2] = {255, 128}, test[2] = {128, 255};
  auto e = normal_angular_error(ref, test, 1, 1, 2);
  ASSERT_TRUE(e.ok());
  const double s = 128 / 127.5 - 1;  // 0.0039216
  const double expected = std::acos(2 * s / (1 + s * s)) * 180 / M_PI;
  EXPECT_NEAR(e->mean_deg, expected, 1e-6);
  EXPECT_NEAR(e->max_deg, expected, 1e-6);
  EXPECT_NEAR(expected, 89.55, 0.01);
  // Identical normals: zero, not NaN, even for XY outside the unit disc.
  const uint8_t outside[4] = {255, 255, 0, 0};
  auto z = normal_angular_error(outside, outside, 2, 1, 2);
  ASSERT_TRUE(z.ok());
  EXPECT_EQ(z->max_deg, 0.0);
  EXPECT_FALSE(normal_angular_error(ref, test, 1, 1, 1).ok());
}

TEST(Metrics, AngularErrorPercentile) {
  // 100 texels: 99 exact and one tilted by a known angle; p99 is the 99th value, still 0.
  std::vector<uint8_t> ref(200, 128), test(200, 128);
  test[0] = 200;
  auto e = normal_angular_error(ref.data(), test.data(), 100, 1, 2);
  ASSERT_TRUE(e.ok());
  EXPECT_EQ(e->p99_deg, 0.0);
  EXPECT_GT(e->max_deg, 30.0);
  EXPECT_NEAR(e->mean_deg, e->max_deg / 100, 1e-9);
}

TEST(Metrics, PsnrFromMse) {
  EXPECT_DOUBLE_EQ(psnr_from_mse(0), kPsnrIdentical);
  EXPECT_NEAR(psnr_from_mse(65025), 0.0, 1e-12);
  EXPECT_NEAR(psnr_from_mse(6502.5), 10.0, 1e-12);
}

}  // namespace
}  // namespace vt
