// The sRGB transfer curve (IEC 61966-2-1): a linear segment near black, a 2.4 power above,
// offset so that the two meet. The one definition: the baker's OpenColorIO config is built
// from these constants, and the float functions are that curve for code converting one
// value at a time.
#pragma once

#include <cmath>

namespace vt {

inline constexpr double kSrgbGamma = 2.4;
inline constexpr double kSrgbOffset = 0.055;  // encoded = (1 + offset) * linear^(1/gamma) - offset
inline constexpr double kSrgbSlope = 12.92;   // of the linear segment
inline constexpr float kSrgbEncodedKnee = 0.04045f;   // encoded values up to it: linear segment
inline constexpr float kSrgbLinearKnee = 0.0031308f;  // linear values up to it: linear segment

// Encoded to linear; nothing is clamped.
inline float srgb_to_linear(float v) {
  return v <= kSrgbEncodedKnee
             ? v / float(kSrgbSlope)
             : std::pow((v + float(kSrgbOffset)) / float(1 + kSrgbOffset), float(kSrgbGamma));
}

// Linear to encoded; nothing is clamped.
inline float linear_to_srgb(float v) {
  return v <= kSrgbLinearKnee
             ? v * float(kSrgbSlope)
             : float(1 + kSrgbOffset) * std::pow(v, 1.0f / float(kSrgbGamma)) - float(kSrgbOffset);
}

// The float constants are the literals the curve was written with (pinned outputs use them).
static_assert(float(kSrgbGamma) == 2.4f && float(kSrgbOffset) == 0.055f &&
              float(kSrgbSlope) == 12.92f && float(1 + kSrgbOffset) == 1.055f);

}  // namespace vt
