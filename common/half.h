// IEEE 754 binary16 ("half") conversions for half-float layers (TexelType::kF16): the baker
// stores HDR texels with float_to_half, tests and tools read them back with half_to_float.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

namespace vt {

inline constexpr float kHalfMax = 65504.0f;  // the largest finite half

// Rounds to the nearest half, ties to even. Finite values beyond +-kHalfMax become +-kHalfMax
// (not infinity: a texel filter must not meet an infinity); infinities and NaN are kept.
inline uint16_t float_to_half(float f) {
  uint32_t x;
  std::memcpy(&x, &f, 4);
  const uint16_t sign = uint16_t((x >> 16) & 0x8000u);
  const uint32_t ax = x & 0x7fffffffu;
  if (ax > 0x7f800000u) return uint16_t(sign | 0x7e00u);  // NaN
  if (ax == 0x7f800000u) return uint16_t(sign | 0x7c00u);
  if (ax >= 0x477fe000u) return uint16_t(sign | 0x7bffu);  // >= 65504
  if (ax >= 0x38800000u) {                                 // normal: >= 2^-14
    const uint32_t rounded = ax + 0x0fffu + ((ax >> 13) & 1u);
    return uint16_t(sign | ((rounded - 0x38000000u) >> 13));
  }
  // Subnormal (or zero): a multiple of 2^-24; scaling by 2^24 is exact, rint rounds to even.
  float v;
  std::memcpy(&v, &ax, 4);
  return uint16_t(sign | uint16_t(std::nearbyint(v * 16777216.0f)));
}

inline float half_to_float(uint16_t h) {
  const uint32_t sign = uint32_t(h & 0x8000u) << 16;
  const uint32_t e = (h >> 10) & 0x1fu, m = h & 0x3ffu;
  uint32_t x;
  if (e == 0) {
    const float v = float(m) * (1.0f / 16777216.0f);
    return sign ? -v : v;
  }
  if (e == 31) {
    x = sign | 0x7f800000u | (m << 13);
  } else {
    x = sign | ((e + 112u) << 23) | (m << 13);
  }
  float f;
  std::memcpy(&f, &x, 4);
  return f;
}

}  // namespace vt
