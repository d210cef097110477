// The DCT decoder's pixel back end: inverse DCT of 8x8 blocks and the conversion of decoded
// planes to interleaved 8-bit texels. Internal to codec/ (called by dct.cpp).
//
// Every function is part of the file format: the same inputs give the same bytes on every
// machine and every SIMD target (SSE2, AVX2, scalar), for all inputs in the stated ranges. The
// arithmetic is that of the original scalar decoder with two changes that let 16-bit SIMD lanes
// hold every intermediate (docs/FORMAT.md):
//   1. IDCT pass 1 (vertical, rows v -> y) saturates to int16:
//        tmp[y][u] = clamp((sum_v B[y][v] * F[v][u] + 256) >> 9, -32768, 32767)
//      pass 2 (horizontal) is unchanged:
//        out[y][x] = clamp((sum_u B[x][u] * tmp[y][u] + 2048) >> 12, -4095, 4095)
//      with B = kIdctBasis (12-bit orthonormal basis, below) and >> arithmetic.
//      Pass 1 can only saturate when a column holds several coefficients near +-2047 with
//      matching signs; blocks of 8-bit content (|F| <= 1024 plus half a quantiser step) never do.
//   2. 4:2:0 chroma samples (Co, Cg) are clamped to [-2047, 2047] before the 9-3-3-1 filter
//      (valid content stays within about +-1020), so 9a + 3b + 3c + d + 8 fits int16.
// Everything else is as before: 9-3-3-1 filter = vertical 3a + b, then (3v + v' + 8) >> 4 with
// edges clamped; Y' = Y + 1024, t = Y' - Cg, R = t + Co, G = Y' + Cg, B = t - Co; each channel
// to 8 bits as clamp((v + 4) >> 3, 0, 255). The 4:4:4 path clamps nothing.
//
// Samples are in 1/8 texel units centred on 0 (Y + 1024 is the 0..2040 range). Inputs to the
// colour functions are idct_block outputs, i.e. within [-4095, 4095]; the 4:2:0 chroma may be
// any int16. For ch == 4 the colour functions leave channel 3 untouched (they read and rewrite
// those bytes unchanged), so alpha may be written before or after.
// width and height are multiples of 8, at most 4096; 4:2:0 chroma planes are width/2 x height/2.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>

namespace vt::dct_detail {

// Orthonormal 8-point DCT basis B[x][u] = c(u) cos((2x + 1) u pi / 16) in 1/4096, rounded once
// (c(0) = sqrt(1/8), else 1/2). Part of the format: the decoder's integer IDCT is defined on it.
inline constexpr int16_t kIdctBasis[8][8] = {
    {1448, 2009, 1892, 1703, 1448, 1138, 784, 400},
    {1448, 1703, 784, -400, -1448, -2009, -1892, -1138},
    {1448, 1138, -784, -2009, -1448, 400, 1892, 1703},
    {1448, 400, -1892, -1138, 1448, 1703, -784, -2009},
    {1448, -400, -1892, 1138, 1448, -1703, -784, 2009},
    {1448, -1138, -784, 2009, -1448, -400, 1892, -1703},
    {1448, -1703, 784, 400, -1448, 2009, -1892, 1138},
    {1448, -2009, 1892, -1703, 1448, -1138, 784, -400},
};

// f: dequantised coefficients in natural (row-major v*8+u) order, each in [-2047, 2047], zero
// outside rows < nv and columns < nu (1..8); nv, nu only pick a fast path, the result is that
// of the full transform. out: 8x8 samples in 1/8 texel units, rows `stride` apart.
void idct_block(const int16_t* f, int nv, int nu, int16_t* out, int stride);

// DC-only block: fills 8x8 with the value idct_block gives for f[0] = dc (|dc| <= 2047), rest 0:
// pass 1 then pass 2 on the DC basis entry. Inline, since most blocks of smooth pages are
// DC-only and a call per block through the ISA dispatch cost more than the fill.
inline void idct_dc_block(int dc, int16_t* out, int stride) {
  const int t = std::clamp((kIdctBasis[0][0] * dc + 256) >> 9, -32768, 32767);
  const int16_t v = int16_t(std::clamp((t * kIdctBasis[0][0] + 2048) >> 12, -4095, 4095));
  for (int y = 0; y < 8; y++)
    for (int x = 0; x < 8; x++) out[y * stride + x] = v;
}

// YCoCg planes to interleaved texels with `ch` channels (3 or 4; channel 3 untouched).
// 4:2:0: co, cg are width/2 x height/2, `cstride` apart, upsampled with the 9-3-3-1 filter.
void ycocg420_to_rgb(const int16_t* y, int ystride, const int16_t* co, const int16_t* cg,
                     int cstride, int width, int height, int ch, uint8_t* texels);
// 4:4:4: co, cg at full resolution.
void ycocg_to_rgb(const int16_t* y, int ystride, const int16_t* co, const int16_t* cg, int cstride,
                  int width, int height, int ch, uint8_t* texels);

// One plane (1/8 units, centred on 0; any int16) into channel c of interleaved texels with ch
// (1..4) channels as clamp((v + 1028) >> 3, 0, 255); the other channels are untouched.
void plane_to_channel(const int16_t* src, int stride, int width, int height, int ch, int c,
                      uint8_t* texels);

// Plain scalar reference implementations: the definition of the arithmetic, used on hosts
// without SIMD and by the tests.
void idct_block_scalar(const int16_t* f, int nv, int nu, int16_t* out, int stride);
void ycocg420_to_rgb_scalar(const int16_t* y, int ystride, const int16_t* co, const int16_t* cg,
                            int cstride, int width, int height, int ch, uint8_t* texels);
void ycocg_to_rgb_scalar(const int16_t* y, int ystride, const int16_t* co, const int16_t* cg,
                         int cstride, int width, int height, int ch, uint8_t* texels);
void plane_to_channel_scalar(const int16_t* src, int stride, int width, int height, int ch, int c,
                             uint8_t* texels);

// One implementation of the functions above. transform_impls() lists those this host can run,
// best first (the functions above use the first) and ends with the scalar reference, which
// defines the arithmetic; tests check every entry against it.
struct TransformImpl {
  const char* name;  // "avx2", "sse2", "scalar"
  void (*idct_block)(const int16_t* f, int nv, int nu, int16_t* out, int stride);
  void (*ycocg420_to_rgb)(const int16_t* y, int ystride, const int16_t* co, const int16_t* cg,
                          int cstride, int width, int height, int ch, uint8_t* texels);
  void (*ycocg_to_rgb)(const int16_t* y, int ystride, const int16_t* co, const int16_t* cg,
                       int cstride, int width, int height, int ch, uint8_t* texels);
  void (*plane_to_channel)(const int16_t* src, int stride, int width, int height, int ch, int c,
                           uint8_t* texels);
};
std::span<const TransformImpl> transform_impls();
const TransformImpl& scalar_transform();

}  // namespace vt::dct_detail
