// Small deterministic integer hashes and a random stream. Each feeds some output (the DCT
// codec's synthetic training page, the procedural samples, the feedback map's probe order,
// test content), so their arithmetic must never change.
#pragma once

#include <cstddef>
#include <cstdint>

namespace vt {

// The xorshift-multiply finaliser shape: three xorshifts with an odd multiply between each.
template <int kShift0, uint32_t kMul0, int kShift1, uint32_t kMul1, int kShift2>
constexpr uint32_t xorshift_multiply(uint32_t x) {
  x ^= x >> kShift0;
  x *= kMul0;
  x ^= x >> kShift1;
  x *= kMul1;
  x ^= x >> kShift2;
  return x;
}

// One 32-bit word, well mixed (Chris Wellons' "lowbias32").
constexpr uint32_t hash32(uint32_t x) {
  return xorshift_multiply<16, 0x7feb352du, 15, 0x846ca68bu, 16>(x);
}

// A 2-D position and a seed (the procedural sample textures' noise).
constexpr uint32_t hash2d(uint32_t x, uint32_t y, uint32_t seed) {
  return xorshift_multiply<15, 0x2c1b3c6du, 12, 0x297a2d39u, 15>(x * 0x8da6b343u ^ y * 0xd8163841u ^
                                                                 seed * 0xcb1ab31fu);
}

// Knuth's MMIX linear congruential generator, high bits out: a reproducible stream for test
// and benchmark content (not for anything statistical; range and below have modulo bias).
struct Lcg64 {
  uint64_t s;
  uint32_t next() {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return uint32_t(s >> 33);
  }
  // In [lo, hi].
  int range(int lo, int hi) { return lo + int(next() % uint32_t(hi - lo + 1)); }
  // In [0, n); 0 when n is 0.
  size_t below(size_t n) { return n == 0 ? 0 : size_t(next()) % n; }
};

}  // namespace vt
