// The DCT decoder's pixel back end (see dct_transform.h): a scalar reference that defines the
// arithmetic, and x86 versions (SSE2 baseline, AVX2 picked at run time) that give the same bytes.
//
// SIMD IDCT: both passes run on 8 lanes at once (pass 1 on the rows of F, pass 2 on the rows of
// the transposed intermediate). Each 1-D transform splits the 8 inputs into even and odd halves,
// since B[7-y][v] = (-1)^v B[y][v]: out[y] = E[y] + O[y], out[7-y] = E[y] - O[y], where E and O
// are pmaddwd sums over pairs of inputs. Every product and sum is an exact int32, so regrouping
// the sums changes nothing. Rows (pass 1) and columns (pass 2) past nv/nu are zero and skipped.
// SSE2 runs each pass as two 4-lane halves; AVX2 runs all 8 lanes in one ymm and transposes
// in-lane. Colour: 16 (SSE2) or 32 (AVX2) texels per step in int16 lanes, packus to bytes.
#include "codec/dct_transform.h"

#include <algorithm>
#include <cstring>

// VT_TRANSFORM_NO_SIMD builds the scalar reference alone (as on non-x86 hosts).
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && \
    !defined(VT_TRANSFORM_NO_SIMD)
#define VT_TRANSFORM_X86 1
#include <immintrin.h>
#endif

namespace vt::dct_detail {

namespace {

constexpr int kMaxWidth = 4096;

inline uint8_t to_u8(int v8) {
  return uint8_t(std::clamp((v8 + 4) >> 3, 0, 255));
}

inline void put_ycocg(uint8_t* o, int y8, int co8, int cg8) {
  const int yy = y8 + 1024, t = yy - cg8;
  o[0] = to_u8(t + co8);
  o[1] = to_u8(yy + cg8);
  o[2] = to_u8(t - co8);
}

inline int clamp_chroma(int v) {
  return std::clamp(v, -2047, 2047);
}

// One output row of the 4:2:0 path from the vertically blended chroma rows `vco`, `vcg`
// (cw entries each), texels [2 * cx0, 2 * cx1).
void ycocg420_row_scalar(const int16_t* yr, const int* vco, const int* vcg, int cw, int cx0,
                         int cx1, int ch, uint8_t* o) {
  for (int cx = cx0; cx < cx1; cx++) {
    const int l = cx > 0 ? cx - 1 : 0, r = cx + 1 < cw ? cx + 1 : cw - 1;
    const int co3 = 3 * vco[cx] + 8, cg3 = 3 * vcg[cx] + 8;
    put_ycocg(o + size_t(2 * cx) * ch, yr[2 * cx], (co3 + vco[l]) >> 4, (cg3 + vcg[l]) >> 4);
    put_ycocg(o + size_t(2 * cx + 1) * ch, yr[2 * cx + 1], (co3 + vco[r]) >> 4,
              (cg3 + vcg[r]) >> 4);
  }
}

}  // namespace

// ---- scalar reference ----

namespace {

// NV, NU (2, 4 or 8) bound the nonzero rows and columns at compile time so that the loops
// vectorise; the rows and columns skipped are zeros and contribute nothing.
template <int NV, int NU>
void idct_block_n(const int16_t* f, int16_t* out, int stride) {
  int32_t tmp[8][8];
  for (int y = 0; y < 8; y++) {
    int32_t acc[8] = {};
    for (int v = 0; v < NV; v++) {
      const int32_t b = kIdctBasis[y][v];
      for (int u = 0; u < 8; u++) acc[u] += b * f[v * 8 + u];
    }
    for (int u = 0; u < 8; u++) tmp[y][u] = std::clamp((acc[u] + 256) >> 9, -32768, 32767);
  }
  for (int y = 0; y < 8; y++) {
    int32_t acc[8] = {};
    for (int u = 0; u < NU; u++) {
      const int32_t t = tmp[y][u];
      for (int x = 0; x < 8; x++) acc[x] += t * kIdctBasis[x][u];
    }
    for (int x = 0; x < 8; x++) {
      out[y * stride + x] = int16_t(std::clamp((acc[x] + 2048) >> 12, -4095, 4095));
    }
  }
}

}  // namespace

void idct_block_scalar(const int16_t* f, int nv, int nu, int16_t* out, int stride) {
  const int rv = nv <= 2 ? 0 : nv <= 4 ? 1 : 2;
  const int ru = nu <= 2 ? 0 : nu <= 4 ? 1 : 2;
  switch (rv * 3 + ru) {
    case 0:
      return idct_block_n<2, 2>(f, out, stride);
    case 1:
      return idct_block_n<2, 4>(f, out, stride);
    case 2:
      return idct_block_n<2, 8>(f, out, stride);
    case 3:
      return idct_block_n<4, 2>(f, out, stride);
    case 4:
      return idct_block_n<4, 4>(f, out, stride);
    case 5:
      return idct_block_n<4, 8>(f, out, stride);
    case 6:
      return idct_block_n<8, 2>(f, out, stride);
    case 7:
      return idct_block_n<8, 4>(f, out, stride);
    default:
      return idct_block_n<8, 8>(f, out, stride);
  }
}

void ycocg420_to_rgb_scalar(const int16_t* yp, int ystride, const int16_t* co, const int16_t* cg,
                            int cstride, int width, int height, int ch, uint8_t* texels) {
  const int cw = width / 2, chh = height / 2;
  int vco[kMaxWidth / 2], vcg[kMaxWidth / 2];
  for (int y = 0; y < height; y++) {
    const int cy = y >> 1;
    const int ny = std::clamp((y & 1) ? cy + 1 : cy - 1, 0, chh - 1);
    const int16_t* a0 = co + size_t(cy) * cstride;
    const int16_t* a1 = co + size_t(ny) * cstride;
    const int16_t* b0 = cg + size_t(cy) * cstride;
    const int16_t* b1 = cg + size_t(ny) * cstride;
    for (int x = 0; x < cw; x++) {
      vco[x] = 3 * clamp_chroma(a0[x]) + clamp_chroma(a1[x]);
      vcg[x] = 3 * clamp_chroma(b0[x]) + clamp_chroma(b1[x]);
    }
    ycocg420_row_scalar(yp + size_t(y) * ystride, vco, vcg, cw, 0, cw, ch,
                        texels + size_t(y) * width * ch);
  }
}

void ycocg_to_rgb_scalar(const int16_t* yp, int ystride, const int16_t* co, const int16_t* cg,
                         int cstride, int width, int height, int ch, uint8_t* texels) {
  for (int y = 0; y < height; y++) {
    uint8_t* o = texels + size_t(y) * width * ch;
    const int16_t* yr = yp + size_t(y) * ystride;
    const int16_t* cor = co + size_t(y) * cstride;
    const int16_t* cgr = cg + size_t(y) * cstride;
    for (int x = 0; x < width; x++) put_ycocg(o + size_t(x) * ch, yr[x], cor[x], cgr[x]);
  }
}

void plane_to_channel_scalar(const int16_t* src, int stride, int width, int height, int ch, int c,
                             uint8_t* texels) {
  for (int y = 0; y < height; y++) {
    uint8_t* o = texels + size_t(y) * width * ch + c;
    const int16_t* r = src + size_t(y) * stride;
    for (int x = 0; x < width; x++) o[size_t(x) * ch] = to_u8(r[x] + 1024);
  }
}

#if VT_TRANSFORM_X86

namespace {

#define VT_INLINE inline __attribute__((always_inline))

// (a, b) in every 32-bit lane: the multipliers of one pmaddwd.
VT_INLINE __m128i pair(int a, int b) {
  return _mm_set1_epi32(int32_t(uint32_t(uint16_t(a)) | (uint32_t(uint16_t(b)) << 16)));
}

template <int H>
VT_INLINE __m128i zip16(__m128i a, __m128i b) {
  return H == 0 ? _mm_unpacklo_epi16(a, b) : _mm_unpackhi_epi16(a, b);
}

// One half (H = 0: lanes 0-3, H = 1: lanes 4-7) of an 8-point inverse transform of the rows
// x[0..N) (rows from N on are zero): acc[y] = bias + sum_v B[y][v] * x[v], shifted right.
template <int N, int kShift, int H>
VT_INLINE void idct_1d_half(const __m128i* x, int bias, __m128i* res) {
  const __m128i zero = _mm_setzero_si128();
  const __m128i one = _mm_set1_epi16(1);
  __m128i e[4], o[4];
  if constexpr (N <= 2) {
    // Even part: B[y][0] = 1448 for all y; the bias rides on a (x0, 1) pair.
    const __m128i ee = _mm_madd_epi16(zip16<H>(x[0], one), pair(1448, bias));
    e[0] = e[1] = e[2] = e[3] = ee;
    const __m128i p1 = zip16<H>(x[1], zero);
    for (int y = 0; y < 4; y++) o[y] = _mm_madd_epi16(p1, pair(kIdctBasis[y][1], 0));
  } else if constexpr (N <= 4) {
    const __m128i ee = _mm_madd_epi16(zip16<H>(x[0], one), pair(1448, bias));
    const __m128i p2 = zip16<H>(x[2], zero);
    const __m128i eo0 = _mm_madd_epi16(p2, pair(1892, 0));
    const __m128i eo1 = _mm_madd_epi16(p2, pair(784, 0));
    e[0] = _mm_add_epi32(ee, eo0);
    e[1] = _mm_add_epi32(ee, eo1);
    e[2] = _mm_sub_epi32(ee, eo1);
    e[3] = _mm_sub_epi32(ee, eo0);
    const __m128i p13 = zip16<H>(x[1], x[3]);
    for (int y = 0; y < 4; y++) {
      o[y] = _mm_madd_epi16(p13, pair(kIdctBasis[y][1], kIdctBasis[y][3]));
    }
  } else {
    const __m128i b = _mm_set1_epi32(bias);
    const __m128i p04 = zip16<H>(x[0], x[4]);
    const __m128i ee0 = _mm_add_epi32(_mm_madd_epi16(p04, pair(1448, 1448)), b);
    const __m128i ee1 = _mm_add_epi32(_mm_madd_epi16(p04, pair(1448, -1448)), b);
    const __m128i p26 = zip16<H>(x[2], x[6]);
    const __m128i eo0 = _mm_madd_epi16(p26, pair(1892, 784));
    const __m128i eo1 = _mm_madd_epi16(p26, pair(784, -1892));
    e[0] = _mm_add_epi32(ee0, eo0);
    e[1] = _mm_add_epi32(ee1, eo1);
    e[2] = _mm_sub_epi32(ee1, eo1);
    e[3] = _mm_sub_epi32(ee0, eo0);
    const __m128i p13 = zip16<H>(x[1], x[3]);
    const __m128i p57 = zip16<H>(x[5], x[7]);
    for (int y = 0; y < 4; y++) {
      o[y] = _mm_add_epi32(_mm_madd_epi16(p13, pair(kIdctBasis[y][1], kIdctBasis[y][3])),
                           _mm_madd_epi16(p57, pair(kIdctBasis[y][5], kIdctBasis[y][7])));
    }
  }
  for (int y = 0; y < 4; y++) {
    res[y] = _mm_srai_epi32(_mm_add_epi32(e[y], o[y]), kShift);
    res[7 - y] = _mm_srai_epi32(_mm_sub_epi32(e[y], o[y]), kShift);
  }
}

// Full 8-point inverse transform of 8 lanes; results saturated to int16 (packssdw).
template <int N, int kShift>
VT_INLINE void idct_1d(const __m128i* x, int bias, __m128i* out) {
  __m128i lo[8], hi[8];
  idct_1d_half<N, kShift, 0>(x, bias, lo);
  idct_1d_half<N, kShift, 1>(x, bias, hi);
  for (int y = 0; y < 8; y++) out[y] = _mm_packs_epi32(lo[y], hi[y]);
}

// Transposes an 8x8 int16 matrix; only the first M (2, 4 or 8) output rows are produced.
template <int M>
VT_INLINE void transpose8(const __m128i* r, __m128i* c) {
  const __m128i a0 = _mm_unpacklo_epi16(r[0], r[1]), a2 = _mm_unpacklo_epi16(r[2], r[3]);
  const __m128i a4 = _mm_unpacklo_epi16(r[4], r[5]), a6 = _mm_unpacklo_epi16(r[6], r[7]);
  const __m128i b0 = _mm_unpacklo_epi32(a0, a2), b4 = _mm_unpacklo_epi32(a4, a6);
  c[0] = _mm_unpacklo_epi64(b0, b4);
  c[1] = _mm_unpackhi_epi64(b0, b4);
  if constexpr (M > 2) {
    const __m128i b1 = _mm_unpackhi_epi32(a0, a2), b5 = _mm_unpackhi_epi32(a4, a6);
    c[2] = _mm_unpacklo_epi64(b1, b5);
    c[3] = _mm_unpackhi_epi64(b1, b5);
  }
  if constexpr (M > 4) {
    const __m128i a1 = _mm_unpackhi_epi16(r[0], r[1]), a3 = _mm_unpackhi_epi16(r[2], r[3]);
    const __m128i a5 = _mm_unpackhi_epi16(r[4], r[5]), a7 = _mm_unpackhi_epi16(r[6], r[7]);
    const __m128i b2 = _mm_unpacklo_epi32(a1, a3), b6 = _mm_unpacklo_epi32(a5, a7);
    const __m128i b3 = _mm_unpackhi_epi32(a1, a3), b7 = _mm_unpackhi_epi32(a5, a7);
    c[4] = _mm_unpacklo_epi64(b2, b6);
    c[5] = _mm_unpackhi_epi64(b2, b6);
    c[6] = _mm_unpacklo_epi64(b3, b7);
    c[7] = _mm_unpackhi_epi64(b3, b7);
  }
}

template <int NV, int NU>
VT_INLINE void idct_block_x86(const int16_t* f, int16_t* out, int stride) {
  __m128i x[8], tmp[8], t[8], r[8];
  for (int v = 0; v < NV; v++) x[v] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(f + 8 * v));
  idct_1d<NV, 9>(x, 256, tmp);  // pass 1: rows of F, saturated to int16
  transpose8<NU>(tmp, t);       // t[u]: column u of tmp (lanes y)
  idct_1d<NU, 12>(t, 2048, r);  // pass 2: r[x] lanes y
  const __m128i lo = _mm_set1_epi16(-4095), hi = _mm_set1_epi16(4095);
  for (int i = 0; i < 8; i++) r[i] = _mm_min_epi16(_mm_max_epi16(r[i], lo), hi);
  transpose8<8>(r, t);
  for (int y = 0; y < 8; y++) _mm_storeu_si128(reinterpret_cast<__m128i*>(out + y * stride), t[y]);
}

VT_INLINE void idct_block_dispatch(const int16_t* f, int nv, int nu, int16_t* out, int stride) {
  const int rv = nv <= 2 ? 0 : nv <= 4 ? 1 : 2;
  const int ru = nu <= 2 ? 0 : nu <= 4 ? 1 : 2;
  switch (rv * 3 + ru) {
    case 0:
      return idct_block_x86<2, 2>(f, out, stride);
    case 1:
      return idct_block_x86<2, 4>(f, out, stride);
    case 2:
      return idct_block_x86<2, 8>(f, out, stride);
    case 3:
      return idct_block_x86<4, 2>(f, out, stride);
    case 4:
      return idct_block_x86<4, 4>(f, out, stride);
    case 5:
      return idct_block_x86<4, 8>(f, out, stride);
    case 6:
      return idct_block_x86<8, 2>(f, out, stride);
    case 7:
      return idct_block_x86<8, 4>(f, out, stride);
    default:
      return idct_block_x86<8, 8>(f, out, stride);
  }
}

void idct_block_sse2(const int16_t* f, int nv, int nu, int16_t* out, int stride) {
  idct_block_dispatch(f, nv, nu, out, stride);
}

// SSE2 colour conversion: 16 texels per step. Without pshufb, RGB is packed from RGB0 dwords
// with shifts.

VT_INLINE __m128i loadu128(const int16_t* p) {
  return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
}

// 4 RGB0 texels (dwords) to 12 RGB bytes in bytes 0-11 (bytes 12-15 zero).
VT_INLINE __m128i pack_rgb0(__m128i x) {
  const __m128i lo32 = _mm_set_epi32(0, -1, 0, -1);
  const __m128i q = _mm_or_si128(_mm_and_si128(x, lo32), _mm_slli_epi64(_mm_srli_epi64(x, 32), 24));
  return _mm_or_si128(_mm_move_epi64(q), _mm_slli_si128(_mm_srli_si128(q, 8), 6));
}

// 16 texels from luma row `yr` and full-resolution chroma: *0 = texels 0-7, *1 = texels 8-15.
template <int CH>
VT_INLINE void put16_sse2(const int16_t* yr, __m128i co0, __m128i co1, __m128i cg0, __m128i cg1,
                          uint8_t* o) {
  const __m128i k = _mm_set1_epi16(1028);  // +1024 centre, +4 rounding
  const __m128i y0 = _mm_add_epi16(loadu128(yr), k), y1 = _mm_add_epi16(loadu128(yr + 8), k);
  const __m128i t0 = _mm_sub_epi16(y0, cg0), t1 = _mm_sub_epi16(y1, cg1);
  const __m128i r = _mm_packus_epi16(_mm_srai_epi16(_mm_add_epi16(t0, co0), 3),
                                     _mm_srai_epi16(_mm_add_epi16(t1, co1), 3));
  const __m128i g = _mm_packus_epi16(_mm_srai_epi16(_mm_add_epi16(y0, cg0), 3),
                                     _mm_srai_epi16(_mm_add_epi16(y1, cg1), 3));
  const __m128i b = _mm_packus_epi16(_mm_srai_epi16(_mm_sub_epi16(t0, co0), 3),
                                     _mm_srai_epi16(_mm_sub_epi16(t1, co1), 3));
  const __m128i zero = _mm_setzero_si128();
  const __m128i rg0 = _mm_unpacklo_epi8(r, g), rg1 = _mm_unpackhi_epi8(r, g);
  const __m128i b0 = _mm_unpacklo_epi8(b, zero), b1 = _mm_unpackhi_epi8(b, zero);
  const __m128i x[4] = {_mm_unpacklo_epi16(rg0, b0), _mm_unpackhi_epi16(rg0, b0),
                        _mm_unpacklo_epi16(rg1, b1), _mm_unpackhi_epi16(rg1, b1)};
  __m128i* d = reinterpret_cast<__m128i*>(o);
  if constexpr (CH == 3) {
    const __m128i p0 = pack_rgb0(x[0]), p1 = pack_rgb0(x[1]);
    const __m128i p2 = pack_rgb0(x[2]), p3 = pack_rgb0(x[3]);
    _mm_storeu_si128(d, _mm_or_si128(p0, _mm_slli_si128(p1, 12)));
    _mm_storeu_si128(d + 1, _mm_or_si128(_mm_srli_si128(p1, 4), _mm_slli_si128(p2, 8)));
    _mm_storeu_si128(d + 2, _mm_or_si128(_mm_srli_si128(p2, 8), _mm_slli_si128(p3, 4)));
  } else {
    const __m128i keep = _mm_set1_epi32(int32_t(0xFF000000u));  // channel 3 stays
    for (int i = 0; i < 4; i++) {
      const __m128i old = _mm_and_si128(_mm_loadu_si128(d + i), keep);
      _mm_storeu_si128(d + i, _mm_or_si128(old, x[i]));
    }
  }
}

VT_INLINE __m128i clamp_chroma_sse2(__m128i v) {
  return _mm_min_epi16(_mm_max_epi16(v, _mm_set1_epi16(-2047)), _mm_set1_epi16(2047));
}

// v[i] = 3 * clamp(a[i]) + clamp(b[i]) for i < n (n >= 8).
VT_INLINE void blend_rows_sse2(const int16_t* a, const int16_t* b, int n, int16_t* v) {
  for (int i = 0;; i += 8) {
    if (i > n - 8) i = n - 8;  // the last step may overlap the one before
    const __m128i x = clamp_chroma_sse2(loadu128(a + i));
    const __m128i y = clamp_chroma_sse2(loadu128(b + i));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(v + i),
                     _mm_add_epi16(_mm_add_epi16(x, _mm_add_epi16(x, x)), y));
    if (i == n - 8) break;
  }
}

// Horizontal 3:1 step of the 4:2:0 filter for 8 chroma samples at v (v[-1], v[8] valid).
VT_INLINE void upsample8_sse2(const int16_t* v, __m128i* lo, __m128i* hi) {
  const __m128i c = loadu128(v), l = loadu128(v - 1), r = loadu128(v + 1);
  const __m128i c3 = _mm_add_epi16(_mm_add_epi16(c, _mm_add_epi16(c, c)), _mm_set1_epi16(8));
  const __m128i even = _mm_srai_epi16(_mm_add_epi16(c3, l), 4);
  const __m128i odd = _mm_srai_epi16(_mm_add_epi16(c3, r), 4);
  *lo = _mm_unpacklo_epi16(even, odd);  // texels 0-7
  *hi = _mm_unpackhi_epi16(even, odd);  // texels 8-15
}

template <int CH>
void ycocg420_sse2(const int16_t* yp, int ystride, const int16_t* co, const int16_t* cg,
                   int cstride, int width, int height, uint8_t* texels) {
  const int cw = width / 2, chh = height / 2;
  alignas(16) int16_t vco[kMaxWidth / 2 + 2], vcg[kMaxWidth / 2 + 2];
  for (int y = 0; y < height; y++) {
    const int cy = y >> 1;
    const int ny = std::clamp((y & 1) ? cy + 1 : cy - 1, 0, chh - 1);
    blend_rows_sse2(co + size_t(cy) * cstride, co + size_t(ny) * cstride, cw, vco + 1);
    blend_rows_sse2(cg + size_t(cy) * cstride, cg + size_t(ny) * cstride, cw, vcg + 1);
    vco[0] = vco[1], vco[cw + 1] = vco[cw];
    vcg[0] = vcg[1], vcg[cw + 1] = vcg[cw];
    const int16_t* yr = yp + size_t(y) * ystride;
    uint8_t* o = texels + size_t(y) * width * CH;
    for (int cx = 0;; cx += 8) {
      if (cx > cw - 8) cx = cw - 8;
      __m128i co0, co1, cg0, cg1;
      upsample8_sse2(vco + 1 + cx, &co0, &co1);
      upsample8_sse2(vcg + 1 + cx, &cg0, &cg1);
      put16_sse2<CH>(yr + 2 * cx, co0, co1, cg0, cg1, o + size_t(2 * cx) * CH);
      if (cx == cw - 8) break;
    }
  }
}

template <int CH>
void ycocg_sse2(const int16_t* yp, int ystride, const int16_t* co, const int16_t* cg, int cstride,
                int width, int height, uint8_t* texels) {
  for (int y = 0; y < height; y++) {
    const int16_t* yr = yp + size_t(y) * ystride;
    const int16_t* cor = co + size_t(y) * cstride;
    const int16_t* cgr = cg + size_t(y) * cstride;
    uint8_t* o = texels + size_t(y) * width * CH;
    for (int x = 0;; x += 16) {
      if (x > width - 16) x = width - 16;
      put16_sse2<CH>(yr + x, loadu128(cor + x), loadu128(cor + x + 8), loadu128(cgr + x),
                     loadu128(cgr + x + 8), o + size_t(x) * CH);
      if (x == width - 16) break;
    }
  }
}

void ycocg420_to_rgb_sse2(const int16_t* yp, int ystride, const int16_t* co, const int16_t* cg,
                          int cstride, int width, int height, int ch, uint8_t* texels) {
  if (width < 16) {
    return ycocg420_to_rgb_scalar(yp, ystride, co, cg, cstride, width, height, ch, texels);
  }
  if (ch == 3) return ycocg420_sse2<3>(yp, ystride, co, cg, cstride, width, height, texels);
  ycocg420_sse2<4>(yp, ystride, co, cg, cstride, width, height, texels);
}

void ycocg_to_rgb_sse2(const int16_t* yp, int ystride, const int16_t* co, const int16_t* cg,
                       int cstride, int width, int height, int ch, uint8_t* texels) {
  if (width < 16) {
    return ycocg_to_rgb_scalar(yp, ystride, co, cg, cstride, width, height, ch, texels);
  }
  if (ch == 3) return ycocg_sse2<3>(yp, ystride, co, cg, cstride, width, height, texels);
  ycocg_sse2<4>(yp, ystride, co, cg, cstride, width, height, texels);
}

// clamp((v + 1028) >> 3, 0, 255) in 16-bit lanes, exact for any int16 (see the AVX2 version).
VT_INLINE __m128i to_u8_lanes_sse2(__m128i v) {
  const __m128i s = _mm_srai_epi16(_mm_adds_epi16(v, _mm_set1_epi16(1028)), 3);
  return _mm_min_epi16(_mm_max_epi16(s, _mm_setzero_si128()), _mm_set1_epi16(255));
}

void plane_to_channel_sse2(const int16_t* src, int stride, int width, int height, int ch, int c,
                           uint8_t* texels) {
  const int step = ch == 1 ? 16 : ch == 2 ? 8 : 4;
  if (ch == 3 || width < step) {
    return plane_to_channel_scalar(src, stride, width, height, ch, c, texels);
  }
  const __m128i keep = ch == 2 ? _mm_set1_epi16(int16_t(~(0xFF << (8 * c))))
                               : _mm_set1_epi32(int32_t(~(0xFFu << (8 * c))));
  const __m128i shift = _mm_cvtsi32_si128(8 * c);
  for (int y = 0; y < height; y++) {
    const int16_t* r = src + size_t(y) * stride;
    uint8_t* o = texels + size_t(y) * width * ch;
    for (int x = 0;; x += step) {
      if (x > width - step) x = width - step;  // the last step may overlap (same bytes again)
      __m128i* d = reinterpret_cast<__m128i*>(o + size_t(x) * ch);
      if (ch == 1) {
        _mm_storeu_si128(d, _mm_packus_epi16(to_u8_lanes_sse2(loadu128(r + x)),
                                             to_u8_lanes_sse2(loadu128(r + x + 8))));
      } else {
        __m128i v;
        if (ch == 2) {
          v = _mm_sll_epi16(to_u8_lanes_sse2(loadu128(r + x)), shift);
        } else {
          const __m128i w =
              to_u8_lanes_sse2(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(r + x)));
          v = _mm_sll_epi32(_mm_unpacklo_epi16(w, _mm_setzero_si128()), shift);
        }
        _mm_storeu_si128(d, _mm_or_si128(_mm_and_si128(_mm_loadu_si128(d), keep), v));
      }
      if (x == width - step) break;
    }
  }
}

// ---- AVX2 ----
// The colour conversion runs on 32 texels per step (pshufb packs RGB).

#define VT_AVX2 __attribute__((target("avx2")))

// AVX2 IDCT: one ymm holds all 8 lanes of a pass as int32 (columns 0-3 | 4-7 in pass 1, rows
// 0-3 | 4-7 in pass 2), so each pmaddwd does the work of two SSE2 ones. The odd pairs are
// (1,3), (5,7) in pass 1 and (1,5), (3,7) in pass 2 (what the in-lane transpose leaves side by
// side); any pairing gives the same exact sums.

VT_AVX2 VT_INLINE __m256i pair256(int a, int b) {
  return _mm256_set1_epi32(int32_t(uint32_t(uint16_t(a)) | (uint32_t(uint16_t(b)) << 16)));
}

// (a[i], b[i]) for i = 0..7 as int16 pairs, from rows broadcast to both lanes.
VT_AVX2 VT_INLINE __m256i zip_rows(__m256i a, __m256i b) {
  return _mm256_blend_epi32(_mm256_unpacklo_epi16(a, b), _mm256_unpackhi_epi16(a, b), 0xF0);
}

// res[y] = (bias + sum_i B[y][i] * x[i]) >> kShift, given x as pairs p04 = (x0, x4),
// p26 = (x2, x6), pa = (x[A0], x[A1]), pb = (x[B0], x[B1]); inputs from index N on are zero.
template <int N, int kShift, int A0, int A1, int B0, int B1>
VT_AVX2 VT_INLINE void idct_1d_avx2(__m256i p04, __m256i p26, __m256i pa, __m256i pb, int bias,
                                    __m256i* res) {
  const __m256i b = _mm256_set1_epi32(bias);
  __m256i e[4], o[4];
  const __m256i ee0 = _mm256_add_epi32(_mm256_madd_epi16(p04, pair256(1448, 1448)), b);
  const __m256i ee1 =
      N > 4 ? _mm256_add_epi32(_mm256_madd_epi16(p04, pair256(1448, -1448)), b) : ee0;
  if constexpr (N > 2) {
    const __m256i eo0 = _mm256_madd_epi16(p26, pair256(1892, 784));
    const __m256i eo1 = _mm256_madd_epi16(p26, pair256(784, -1892));
    e[0] = _mm256_add_epi32(ee0, eo0);
    e[1] = _mm256_add_epi32(ee1, eo1);
    e[2] = _mm256_sub_epi32(ee1, eo1);
    e[3] = _mm256_sub_epi32(ee0, eo0);
  } else {
    e[0] = e[1] = e[2] = e[3] = ee0;
  }
  for (int y = 0; y < 4; y++) {
    o[y] = _mm256_madd_epi16(pa, pair256(kIdctBasis[y][A0], kIdctBasis[y][A1]));
    if constexpr (B0 < N) {
      o[y] = _mm256_add_epi32(o[y],
                              _mm256_madd_epi16(pb, pair256(kIdctBasis[y][B0], kIdctBasis[y][B1])));
    }
  }
  for (int y = 0; y < 4; y++) {
    res[y] = _mm256_srai_epi32(_mm256_add_epi32(e[y], o[y]), kShift);
    res[7 - y] = _mm256_srai_epi32(_mm256_sub_epi32(e[y], o[y]), kShift);
  }
}

// In-lane transpose of q[k] = (rows k, k + 4 of an 8x8 int16 matrix, columns 0-3 | 4-7), as
// packssdw leaves them, into w[k] = (column k | column k + 4).
VT_AVX2 VT_INLINE void transpose_avx2(const __m256i* q, __m256i* w) {
  const __m256i u0 = _mm256_unpacklo_epi16(q[0], q[1]), u1 = _mm256_unpackhi_epi16(q[0], q[1]);
  const __m256i u2 = _mm256_unpacklo_epi16(q[2], q[3]), u3 = _mm256_unpackhi_epi16(q[2], q[3]);
  const __m256i v0 = _mm256_unpacklo_epi32(u0, u2), v1 = _mm256_unpackhi_epi32(u0, u2);
  const __m256i v2 = _mm256_unpacklo_epi32(u1, u3), v3 = _mm256_unpackhi_epi32(u1, u3);
  w[0] = _mm256_unpacklo_epi64(v0, v2);
  w[1] = _mm256_unpackhi_epi64(v0, v2);
  w[2] = _mm256_unpacklo_epi64(v1, v3);
  w[3] = _mm256_unpackhi_epi64(v1, v3);
}

// (column k | column k + 4) -> pairs (T[y][k], T[y][k + 4]) for rows 0-3 | 4-7.
VT_AVX2 VT_INLINE __m256i column_pairs(__m256i w) {
  const __m256i m = _mm256_setr_epi8(0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15, 0, 1, 8,
                                     9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15);
  return _mm256_shuffle_epi8(_mm256_permute4x64_epi64(w, 0xD8), m);
}

template <int NV, int NU>
VT_AVX2 VT_INLINE void idct_block_avx2_n(const int16_t* f, int16_t* out, int stride) {
  const __m256i zero = _mm256_setzero_si256();
  __m256i r[8];
  for (int v = 0; v < 8; v++) {
    r[v] = v < NV ? _mm256_broadcastsi128_si256(
                        _mm_loadu_si128(reinterpret_cast<const __m128i*>(f + 8 * v)))
                  : zero;
  }
  __m256i acc[8], q[4], w[4];
  // Pass 1: acc[y] = row y of tmp, columns 0-3 | 4-7.
  idct_1d_avx2<NV, 9, 1, 3, 5, 7>(zip_rows(r[0], r[4]), zip_rows(r[2], r[6]), zip_rows(r[1], r[3]),
                                  zip_rows(r[5], r[7]), 256, acc);
  for (int k = 0; k < 4; k++) q[k] = _mm256_packs_epi32(acc[k], acc[k + 4]);  // int16 saturation
  transpose_avx2(q, w);
  // Pass 2: acc[x] = output column x, rows 0-3 | 4-7.
  idct_1d_avx2<NU, 12, 1, 5, 3, 7>(column_pairs(w[0]), column_pairs(w[2]), column_pairs(w[1]),
                                   column_pairs(w[3]), 2048, acc);
  const __m256i lo = _mm256_set1_epi16(-4095), hi = _mm256_set1_epi16(4095);
  for (int k = 0; k < 4; k++) {
    q[k] = _mm256_min_epi16(_mm256_max_epi16(_mm256_packs_epi32(acc[k], acc[k + 4]), lo), hi);
  }
  transpose_avx2(q, w);  // w[k] = (output row k | row k + 4)
  for (int k = 0; k < 4; k++) {
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + k * stride), _mm256_castsi256_si128(w[k]));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + (k + 4) * stride),
                     _mm256_extracti128_si256(w[k], 1));
  }
}

VT_AVX2 void idct_block_avx2(const int16_t* f, int nv, int nu, int16_t* out, int stride) {
  const int rv = nv <= 2 ? 0 : nv <= 4 ? 1 : 2;
  const int ru = nu <= 2 ? 0 : nu <= 4 ? 1 : 2;
  switch (rv * 3 + ru) {
    case 0:
      return idct_block_avx2_n<2, 2>(f, out, stride);
    case 1:
      return idct_block_avx2_n<2, 4>(f, out, stride);
    case 2:
      return idct_block_avx2_n<2, 8>(f, out, stride);
    case 3:
      return idct_block_avx2_n<4, 2>(f, out, stride);
    case 4:
      return idct_block_avx2_n<4, 4>(f, out, stride);
    case 5:
      return idct_block_avx2_n<4, 8>(f, out, stride);
    case 6:
      return idct_block_avx2_n<8, 2>(f, out, stride);
    case 7:
      return idct_block_avx2_n<8, 4>(f, out, stride);
    default:
      return idct_block_avx2_n<8, 8>(f, out, stride);
  }
}

// pshufb masks spreading 16 R, G or B bytes over 48 RGB bytes: kRgbShuffle[k][c] gives channel
// c's bytes of output bytes 16k..16k+15 (both 128-bit lanes alike).
struct RgbShuffle {
  alignas(32) int8_t m[3][3][32];
  constexpr RgbShuffle() : m() {
    for (int k = 0; k < 3; k++)
      for (int c = 0; c < 3; c++)
        for (int j = 0; j < 32; j++) {
          const int g = 16 * k + (j & 15);
          m[k][c][j] = int8_t(g % 3 == c ? g / 3 : -128);
        }
  }
};
constexpr RgbShuffle kRgbShuffle;

VT_AVX2 VT_INLINE __m256i load2x128(const int16_t* lo, const int16_t* hi) {
  return _mm256_inserti128_si256(
      _mm256_castsi128_si256(_mm_loadu_si128(reinterpret_cast<const __m128i*>(lo))),
      _mm_loadu_si128(reinterpret_cast<const __m128i*>(hi)), 1);
}

VT_AVX2 VT_INLINE __m256i shuf_rgb(__m256i r, __m256i g, __m256i b, int k) {
  const auto* m = kRgbShuffle.m[k];
  const __m256i sr =
      _mm256_shuffle_epi8(r, _mm256_load_si256(reinterpret_cast<const __m256i*>(m[0])));
  const __m256i sg =
      _mm256_shuffle_epi8(g, _mm256_load_si256(reinterpret_cast<const __m256i*>(m[1])));
  const __m256i sb =
      _mm256_shuffle_epi8(b, _mm256_load_si256(reinterpret_cast<const __m256i*>(m[2])));
  return _mm256_or_si256(_mm256_or_si256(sr, sg), sb);
}

// 32 texels from luma row `yr` and full-resolution chroma in the lane order the 4:2:0 filter
// leaves them in: *A = texels 0-7 | 16-23, *B = texels 8-15 | 24-31.
template <int CH>
VT_AVX2 VT_INLINE void put32_avx2(const int16_t* yr, __m256i coA, __m256i coB, __m256i cgA,
                                  __m256i cgB, uint8_t* o) {
  const __m256i k = _mm256_set1_epi16(1028);  // +1024 centre, +4 rounding
  const __m256i yA = _mm256_add_epi16(load2x128(yr, yr + 16), k);
  const __m256i yB = _mm256_add_epi16(load2x128(yr + 8, yr + 24), k);
  const __m256i tA = _mm256_sub_epi16(yA, cgA), tB = _mm256_sub_epi16(yB, cgB);
  // packus: lane 0 = A.lane0, B.lane0 = texels 0-15; lane 1 = texels 16-31.
  const __m256i r = _mm256_packus_epi16(_mm256_srai_epi16(_mm256_add_epi16(tA, coA), 3),
                                        _mm256_srai_epi16(_mm256_add_epi16(tB, coB), 3));
  const __m256i g = _mm256_packus_epi16(_mm256_srai_epi16(_mm256_add_epi16(yA, cgA), 3),
                                        _mm256_srai_epi16(_mm256_add_epi16(yB, cgB), 3));
  const __m256i b = _mm256_packus_epi16(_mm256_srai_epi16(_mm256_sub_epi16(tA, coA), 3),
                                        _mm256_srai_epi16(_mm256_sub_epi16(tB, coB), 3));
  if constexpr (CH == 3) {
    // s[k]: lane 0 = output bytes 16k.., lane 1 = output bytes 48 + 16k..
    const __m256i s0 = shuf_rgb(r, g, b, 0), s1 = shuf_rgb(r, g, b, 1), s2 = shuf_rgb(r, g, b, 2);
    __m256i* d = reinterpret_cast<__m256i*>(o);
    _mm256_storeu_si256(d, _mm256_permute2x128_si256(s0, s1, 0x20));
    _mm256_storeu_si256(d + 1, _mm256_permute2x128_si256(s2, s0, 0x30));
    _mm256_storeu_si256(d + 2, _mm256_permute2x128_si256(s1, s2, 0x31));
  } else {
    const __m256i zero = _mm256_setzero_si256();
    const __m256i rg0 = _mm256_unpacklo_epi8(r, g), rg1 = _mm256_unpackhi_epi8(r, g);
    const __m256i b0 = _mm256_unpacklo_epi8(b, zero), b1 = _mm256_unpackhi_epi8(b, zero);
    const __m256i x0 = _mm256_unpacklo_epi16(rg0, b0);             // texels 0-3 | 16-19
    const __m256i x1 = _mm256_unpackhi_epi16(rg0, b0);             // 4-7 | 20-23
    const __m256i x2 = _mm256_unpacklo_epi16(rg1, b1);             // 8-11 | 24-27
    const __m256i x3 = _mm256_unpackhi_epi16(rg1, b1);             // 12-15 | 28-31
    const __m256i keep = _mm256_set1_epi32(int32_t(0xFF000000u));  // channel 3 stays
    __m256i* d = reinterpret_cast<__m256i*>(o);
    const __m256i q[4] = {
        _mm256_permute2x128_si256(x0, x1, 0x20), _mm256_permute2x128_si256(x2, x3, 0x20),
        _mm256_permute2x128_si256(x0, x1, 0x31), _mm256_permute2x128_si256(x2, x3, 0x31)};
    for (int i = 0; i < 4; i++) {
      const __m256i old = _mm256_and_si256(_mm256_loadu_si256(d + i), keep);
      _mm256_storeu_si256(d + i, _mm256_or_si256(old, q[i]));
    }
  }
}

VT_AVX2 VT_INLINE __m256i clamp_chroma_avx2(__m256i v) {
  return _mm256_min_epi16(_mm256_max_epi16(v, _mm256_set1_epi16(-2047)), _mm256_set1_epi16(2047));
}

VT_AVX2 VT_INLINE void blend16_avx2(const int16_t* a, const int16_t* b, int16_t* v) {
  const __m256i x = clamp_chroma_avx2(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(a)));
  const __m256i y = clamp_chroma_avx2(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(b)));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(v),
                      _mm256_add_epi16(_mm256_add_epi16(x, _mm256_add_epi16(x, x)), y));
}

// v[i] = 3 * clamp(a[i]) + clamp(b[i]) for i < n (n >= 16), |v| <= 8188. Whole steps, then
// one ending at n that overlaps the one before (the same values again): a plain counted loop
// keeps the addressing to pointer increments (pages are 128 wide: no overlap step).
VT_AVX2 VT_INLINE void blend_rows_avx2(const int16_t* a, const int16_t* b, int n, int16_t* v) {
  int i = 0;
  for (; i + 16 <= n; i += 16) blend16_avx2(a + i, b + i, v + i);
  if (i < n) blend16_avx2(a + n - 16, b + n - 16, v + n - 16);
}

// Horizontal 3:1 step of the 4:2:0 filter for 16 chroma samples at v (v[-1], v[16] valid):
// even/odd full-resolution samples, interleaved in the lane order put32_avx2 takes.
VT_AVX2 VT_INLINE void upsample16_avx2(const int16_t* v, __m256i* A, __m256i* B) {
  const __m256i c = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(v));
  const __m256i l = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(v - 1));
  const __m256i r = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(v + 1));
  const __m256i c3 =
      _mm256_add_epi16(_mm256_add_epi16(c, _mm256_add_epi16(c, c)), _mm256_set1_epi16(8));
  const __m256i even = _mm256_srai_epi16(_mm256_add_epi16(c3, l), 4);
  const __m256i odd = _mm256_srai_epi16(_mm256_add_epi16(c3, r), 4);
  *A = _mm256_unpacklo_epi16(even, odd);  // texels 0-7 | 16-23
  *B = _mm256_unpackhi_epi16(even, odd);  // texels 8-15 | 24-31
}

// Texels [2 * cx, 2 * cx + 32) of an output row from the blended chroma at vco, vcg (chroma
// sample cx; one sample each side valid).
template <int CH>
VT_AVX2 VT_INLINE void ycocg420_step_avx2(const int16_t* vco, const int16_t* vcg, const int16_t* yr,
                                          uint8_t* o, int cx) {
  __m256i coA, coB, cgA, cgB;
  upsample16_avx2(vco, &coA, &coB);
  upsample16_avx2(vcg, &cgA, &cgB);
  put32_avx2<CH>(yr + 2 * cx, coA, coB, cgA, cgB, o + size_t(2 * cx) * CH);
}

template <int CH>
VT_AVX2 void ycocg420_avx2(const int16_t* yp, int ystride, const int16_t* co, const int16_t* cg,
                           int cstride, int width, int height, uint8_t* texels) {
  const int cw = width / 2, chh = height / 2;
  // Blended chroma rows with the clamped edge copied at [0] and [cw + 1].
  alignas(32) int16_t vco[kMaxWidth / 2 + 2], vcg[kMaxWidth / 2 + 2];
  for (int y = 0; y < height; y++) {
    const int cy = y >> 1;
    const int ny = std::clamp((y & 1) ? cy + 1 : cy - 1, 0, chh - 1);
    blend_rows_avx2(co + size_t(cy) * cstride, co + size_t(ny) * cstride, cw, vco + 1);
    blend_rows_avx2(cg + size_t(cy) * cstride, cg + size_t(ny) * cstride, cw, vcg + 1);
    vco[0] = vco[1], vco[cw + 1] = vco[cw];
    vcg[0] = vcg[1], vcg[cw + 1] = vcg[cw];
    const int16_t* yr = yp + size_t(y) * ystride;
    uint8_t* o = texels + size_t(y) * width * CH;
    // Whole steps, then one ending at cw that overlaps the one before (the same bytes again).
    int cx = 0;
    for (; cx + 16 <= cw; cx += 16) ycocg420_step_avx2<CH>(vco + 1 + cx, vcg + 1 + cx, yr, o, cx);
    if (cx < cw) ycocg420_step_avx2<CH>(vco + 1 + cw - 16, vcg + 1 + cw - 16, yr, o, cw - 16);
  }
}

template <int CH>
VT_AVX2 void ycocg_avx2(const int16_t* yp, int ystride, const int16_t* co, const int16_t* cg,
                        int cstride, int width, int height, uint8_t* texels) {
  for (int y = 0; y < height; y++) {
    const int16_t* yr = yp + size_t(y) * ystride;
    const int16_t* cor = co + size_t(y) * cstride;
    const int16_t* cgr = cg + size_t(y) * cstride;
    uint8_t* o = texels + size_t(y) * width * CH;
    for (int x = 0;; x += 32) {
      if (x > width - 32) x = width - 32;
      put32_avx2<CH>(yr + x, load2x128(cor + x, cor + x + 16), load2x128(cor + x + 8, cor + x + 24),
                     load2x128(cgr + x, cgr + x + 16), load2x128(cgr + x + 8, cgr + x + 24),
                     o + size_t(x) * CH);
      if (x == width - 32) break;
    }
  }
}

void ycocg420_to_rgb_avx2(const int16_t* yp, int ystride, const int16_t* co, const int16_t* cg,
                          int cstride, int width, int height, int ch, uint8_t* texels) {
  if (width < 32) {
    return ycocg420_to_rgb_scalar(yp, ystride, co, cg, cstride, width, height, ch, texels);
  }
  if (ch == 3) return ycocg420_avx2<3>(yp, ystride, co, cg, cstride, width, height, texels);
  ycocg420_avx2<4>(yp, ystride, co, cg, cstride, width, height, texels);
}

void ycocg_to_rgb_avx2(const int16_t* yp, int ystride, const int16_t* co, const int16_t* cg,
                       int cstride, int width, int height, int ch, uint8_t* texels) {
  if (width < 32) {
    return ycocg_to_rgb_scalar(yp, ystride, co, cg, cstride, width, height, ch, texels);
  }
  if (ch == 3) return ycocg_avx2<3>(yp, ystride, co, cg, cstride, width, height, texels);
  ycocg_avx2<4>(yp, ystride, co, cg, cstride, width, height, texels);
}

// clamp((v + 1028) >> 3, 0, 255) in 16-bit lanes; the saturating add makes it exact for any
// int16 (a saturated sum is still >= 2040 and gives 255).
VT_AVX2 VT_INLINE __m256i to_u8_lanes_avx2(__m256i v) {
  const __m256i s = _mm256_srai_epi16(_mm256_adds_epi16(v, _mm256_set1_epi16(1028)), 3);
  return _mm256_min_epi16(_mm256_max_epi16(s, _mm256_setzero_si256()), _mm256_set1_epi16(255));
}

VT_AVX2 void plane_to_channel_avx2(const int16_t* src, int stride, int width, int height, int ch,
                                   int c, uint8_t* texels) {
  const int step = ch == 1 ? 32 : ch == 2 ? 16 : 8;
  if (ch == 3 || width < step) {
    return plane_to_channel_scalar(src, stride, width, height, ch, c, texels);
  }
  for (int y = 0; y < height; y++) {
    const int16_t* r = src + size_t(y) * stride;
    uint8_t* o = texels + size_t(y) * width * ch;
    for (int x = 0;; x += step) {
      if (x > width - step) x = width - step;  // the last step may overlap (same bytes again)
      __m256i* d = reinterpret_cast<__m256i*>(o + size_t(x) * ch);
      if (ch == 1) {
        const __m256i a =
            to_u8_lanes_avx2(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(r + x)));
        const __m256i b =
            to_u8_lanes_avx2(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(r + x + 16)));
        _mm256_storeu_si256(d, _mm256_permute4x64_epi64(_mm256_packus_epi16(a, b), 0xD8));
      } else {
        __m256i v, keep;
        if (ch == 2) {
          v = to_u8_lanes_avx2(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(r + x)));
          v = _mm256_slli_epi16(v, 8 * c);
          keep = _mm256_set1_epi16(int16_t(~(0xFF << (8 * c))));
        } else {
          v = to_u8_lanes_avx2(
              _mm256_castsi128_si256(_mm_loadu_si128(reinterpret_cast<const __m128i*>(r + x))));
          v = _mm256_slli_epi32(_mm256_cvtepu16_epi32(_mm256_castsi256_si128(v)), 8 * c);
          keep = _mm256_set1_epi32(int32_t(~(0xFFu << (8 * c))));
        }
        _mm256_storeu_si256(d, _mm256_or_si256(_mm256_and_si256(_mm256_loadu_si256(d), keep), v));
      }
      if (x == width - step) break;
    }
  }
}

bool host_has_avx2() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2");
}

}  // namespace

#endif  // VT_TRANSFORM_X86

namespace {

constexpr TransformImpl kScalar = {"scalar", idct_block_scalar, ycocg420_to_rgb_scalar,
                                   ycocg_to_rgb_scalar, plane_to_channel_scalar};

#if VT_TRANSFORM_X86
constexpr TransformImpl kImpls[] = {
    {"avx2", idct_block_avx2, ycocg420_to_rgb_avx2, ycocg_to_rgb_avx2, plane_to_channel_avx2},
    {"sse2", idct_block_sse2, ycocg420_to_rgb_sse2, ycocg_to_rgb_sse2, plane_to_channel_sse2},
    kScalar,
};
#else
constexpr TransformImpl kImpls[] = {kScalar};
#endif

const TransformImpl& best() {
  static const TransformImpl& impl = transform_impls().front();
  return impl;
}

}  // namespace

std::span<const TransformImpl> transform_impls() {
#if VT_TRANSFORM_X86
  static const std::span<const TransformImpl> impls =
      host_has_avx2() ? std::span<const TransformImpl>(kImpls)
                      : std::span<const TransformImpl>(kImpls).subspan(1);
  return impls;
#else
  return kImpls;
#endif
}

const TransformImpl& scalar_transform() {
  return kScalar;
}

void idct_block(const int16_t* f, int nv, int nu, int16_t* out, int stride) {
  best().idct_block(f, nv, nu, out, stride);
}

void ycocg420_to_rgb(const int16_t* y, int ystride, const int16_t* co, const int16_t* cg,
                     int cstride, int width, int height, int ch, uint8_t* texels) {
  best().ycocg420_to_rgb(y, ystride, co, cg, cstride, width, height, ch, texels);
}

void ycocg_to_rgb(const int16_t* y, int ystride, const int16_t* co, const int16_t* cg, int cstride,
                  int width, int height, int ch, uint8_t* texels) {
  best().ycocg_to_rgb(y, ystride, co, cg, cstride, width, height, ch, texels);
}

void plane_to_channel(const int16_t* src, int stride, int width, int height, int ch, int c,
                      uint8_t* texels) {
  best().plane_to_channel(src, stride, width, height, ch, c, texels);
}

}  // namespace vt::dct_detail
