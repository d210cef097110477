// common/srgb.h: the float sRGB curve is IEC 61966-2-1, its two directions invert each other
// on every 8-bit code, and it is the same curve as the OpenColorIO config's sRGB space.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "bake/color.h"
#include "common/srgb.h"

namespace vt {
namespace {

// The standard's formulas in double, written from the standard rather than from srgb.h.
double reference_to_linear(double v) {
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}
double reference_to_srgb(double v) {
  return v <= 0.0031308 ? v * 12.92 : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
}

TEST(Srgb, FloatCurveIsTheStandardOne) {
  for (int k = 0; k <= 1000; ++k) {
    const float v = k / 1000.0f;
    EXPECT_NEAR(srgb_to_linear(v), reference_to_linear(v), 1e-6 + 1e-6 * v) << v;
    EXPECT_NEAR(linear_to_srgb(v), reference_to_srgb(v), 1e-6 + 1e-6 * v) << v;
  }
  // The linear segments are plain divisions and products: exact.
  EXPECT_EQ(srgb_to_linear(0.04045f), 0.04045f / 12.92f);
  EXPECT_EQ(linear_to_srgb(0.002f), 0.002f * 12.92f);
  EXPECT_EQ(srgb_to_linear(0.0f), 0.0f);
  // The segments meet at the knees (the curve has no step there).
  EXPECT_NEAR(srgb_to_linear(std::nextafter(kSrgbEncodedKnee, 1.0f)),
              srgb_to_linear(kSrgbEncodedKnee), 1e-7);
  EXPECT_NEAR(linear_to_srgb(std::nextafter(kSrgbLinearKnee, 1.0f)),
              linear_to_srgb(kSrgbLinearKnee), 1e-6);
}

TEST(Srgb, EveryCodeSurvivesARoundTrip) {
  for (int k = 0; k < 256; ++k) {
    const float back = linear_to_srgb(srgb_to_linear(k / 255.0f));
    EXPECT_EQ(std::lround(back * 255.0f), k);
  }
}

// OpenColorIO derives the linear segment from gamma and offset (slope 12.9232, where the
// standard rounds to 12.92), so near black the two differ by up to 0.03% of the value.
TEST(Srgb, SameCurveAsTheOpenColorIoConfig) {
  auto to_lin = ColorConverter::create("sRGB", "linear");
  auto to_srgb = ColorConverter::create("linear", "sRGB");
  ASSERT_TRUE(to_lin.ok() && to_srgb.ok());
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 2000; ++i) {
    const float v = i < 256 ? i / 255.0f : u(rng);
    float a[3] = {v, v, v}, b[3] = {v, v, v};
    (*to_lin)->apply(a, 1, 3);
    (*to_srgb)->apply(b, 1, 3);
    ASSERT_NEAR(a[0], srgb_to_linear(v), 2e-6) << v;
    ASSERT_NEAR(b[0], linear_to_srgb(v), 2e-6 + 3e-4 * b[0]) << v;
  }
}

}  // namespace
}  // namespace vt
