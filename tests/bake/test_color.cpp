// The generated OpenColorIO config: sRGB is the IEC 61966-2-1 curve, the 8-bit table and the
// 8-bit code boundaries give exactly what converting through OpenColorIO gives.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "bake/color.h"

namespace vt {
namespace {

double srgb_to_linear(double v) {
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

TEST(Color, SrgbCurveIsTheStandardOne) {
  auto to_lin = ColorConverter::create("sRGB", "linear");
  ASSERT_TRUE(to_lin.ok()) << to_lin.status().message();
  for (int k = 0; k < 256; ++k) {
    float t[3] = {k / 255.0f, k / 255.0f, k / 255.0f};
    (*to_lin)->apply(t, 1, 3);
    EXPECT_NEAR(t[0], srgb_to_linear(k / 255.0), 2e-6) << k;
  }
  // Off the 8-bit codes (the OpenColorIO path, not the table).
  float t[3] = {0.5004f, 0.02f, 0.9f};
  (*to_lin)->apply(t, 1, 3);
  EXPECT_NEAR(t[0], srgb_to_linear(0.5004), 2e-6);
  EXPECT_NEAR(t[1], srgb_to_linear(0.02), 2e-6);
}

TEST(Color, RoundTripKeepsEveryCode) {
  auto to_lin = ColorConverter::create("srgb_texture", "scene_linear");
  auto to_srgb = ColorConverter::create("linear", "sRGB");
  ASSERT_TRUE(to_lin.ok() && to_srgb.ok());
  for (int k = 0; k < 256; ++k) {
    float t[4] = {k / 255.0f, k / 255.0f, k / 255.0f, k / 255.0f};
    (*to_lin)->apply(t, 1, 4);
    uint8_t out[4];
    (*to_srgb)->apply_to_u8(t, 1, 4, out);
    for (int c = 0; c < 4; ++c) ASSERT_EQ(out[c], k) << "channel " << c;
  }
}

TEST(Color, BoundariesMatchConvertingThenRounding) {
  auto to_srgb = ColorConverter::create("linear", "sRGB");
  ASSERT_TRUE(to_srgb.ok());
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.1f, 1.2f);
  for (int i = 0; i < 20000; ++i) {
    float t[3] = {u(rng), u(rng) * u(rng), std::pow(u(rng), 4.0f)};
    uint8_t fast[3];
    (*to_srgb)->apply_to_u8(t, 1, 3, fast);
    (*to_srgb)->apply(t, 1, 3);
    for (int c = 0; c < 3; ++c) {
      float v = t[c];
      uint8_t slow = !(v > 0) ? 0 : v >= 1 ? 255 : uint8_t(v * 255.0f + 0.5f);
      ASSERT_EQ(fast[c], slow) << "value " << t[c];
    }
  }
}

TEST(Color, UnknownSpaceIsAClearError) {
  auto c = ColorConverter::create("ProPhoto RGB", "linear");
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("ProPhoto RGB"), std::string::npos);
  auto raw = ColorConverter::create("raw", "sRGB");
  ASSERT_TRUE(raw.ok());
  EXPECT_TRUE((*raw)->is_identity());
  EXPECT_FALSE(color_config_yaml().empty());
}

}  // namespace
}  // namespace vt
