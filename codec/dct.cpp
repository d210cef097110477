// The page DCT codec (see dct.h). Bitstream of a page: a kind byte (0 coded, 1 constant, 2
// stored); a constant page then holds its texel raw, a stored page all its texels raw. A coded page
// holds the byte length of its rANS part (LEB128), the rANS part (codec/dct_rans.h), then the raw
// bits. For every plane in order (Y, Co, Cg, alpha or channel 0..3), blocks in raster order; each
// block codes its AC nonzero count (context: neighbours' counts), its DC as a residual from a
// median predictor (context: neighbours' DC difference), then while nonzeros remain one token
// per pair of zigzag positions (context: the pair's band, nonzeros left two tokens back, the
// neighbours' magnitude over the pair), the signs of its nonzeros raw, and an escape token per
// magnitude of 3 or more. Token frequencies are static per layer unless the tables adapt.
#include "codec/dct.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <numbers>
#include <string>
#include <tuple>

#include "codec/dct_rans.h"
#include "codec/dct_transform.h"
#include "common/hash.h"

namespace vt {

using dct_detail::BitReader;
using dct_detail::BitWriter;
using dct_detail::idct_block;
using dct_detail::idct_dc_block;
using dct_detail::kFreqTotal;
using dct_detail::kTokens;
using dct_detail::plane_to_channel;
using dct_detail::RansDecoder;
using dct_detail::RansEncoder;
using dct_detail::TokenModel;
using dct_detail::ycocg420_to_rgb;
using dct_detail::ycocg_to_rgb;

namespace {

constexpr int kMaxPageSize = 4096;
constexpr int kMaxQuantized = 4095;
constexpr int kMaxDequantized = 2047;  // far beyond any 8-bit block's coefficients

constexpr uint8_t kZigzag[64] = {0,  1,  8,  16, 9,  2,  3,  10, 17, 24, 32, 25, 18, 11, 4,  5,
                                 12, 19, 26, 33, 40, 48, 41, 34, 27, 20, 13, 6,  7,  14, 21, 28,
                                 35, 42, 49, 56, 57, 50, 43, 36, 29, 22, 15, 23, 30, 37, 44, 51,
                                 58, 59, 52, 45, 38, 31, 39, 46, 53, 60, 61, 54, 47, 55, 62, 63};

// Tokens of unsigned values (AC count, DC residual magnitude): 0-3 are the values themselves,
// 4-7 pairs and quads, 8-15 powers of two from 16 to 2048; `extra` low bits follow raw.
constexpr uint16_t kUintBase[kTokens] = {0,  1,  2,  3,   4,   6,   8,    12,
                                         16, 32, 64, 128, 256, 512, 1024, 2048};
constexpr uint8_t kUintExtra[kTokens] = {0, 0, 0, 0, 1, 1, 2, 2, 4, 5, 6, 7, 8, 9, 10, 11};

inline int bit_length(unsigned v) {
  return v == 0 ? 0 : 32 - __builtin_clz(v);
}

// v <= 4095.
inline int uint_token(unsigned v) {
  return v < 4    ? int(v)
         : v < 8  ? 4 + int((v - 4) >> 1)
         : v < 16 ? 6 + int((v - 8) >> 2)
                  : 3 + bit_length(v);
}

// AC coefficients go in pairs of zigzag positions (2j+1, 2j+2; the last pair's second is a
// phantom position 64, always zero): a pair token is c0 + 4 * c1 with c = min(|v|, 3). The signs
// of the pair's nonzeros follow raw (first position first). After the block's pairs, each c = 3
// in position order has an escape token for |v| - 3, an unsigned value. Pairs halve the tokens
// of per-position coding and keep every token's position fixed, so no token's context waits on
// the token just before it.
constexpr int kPairs = 32;
constexpr int kEscapeClass = 3;
struct PairToken {
  uint8_t nonzeros;  // raw sign bits that follow
  uint8_t mask;      // 2^nonzeros - 1
  uint8_t escapes;   // bit 0 (1): the first (second) position's class is kEscapeClass
  uint8_t unused;
};

// Two int16 coefficients as they lie in memory, first position first.
constexpr uint32_t coefficient_pair(int v0, int v1) {
  const uint32_t lo = uint16_t(v0), hi = uint16_t(v1);
  return __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__ ? lo | (hi << 16) : hi | (lo << 16);
}

// The pair's coefficients from its magnitudes and sign bits (first nonzero first). A sign bit
// on a zero would be harmless (-0), and none is read for one.
constexpr uint32_t signed_pair(int a0, int a1, uint32_t signs, int has0) {
  const int n0 = -int(signs & unsigned(has0)), n1 = -int(signs >> has0);
  return coefficient_pair((a0 ^ n0) - n0, (a1 ^ n1) - n1);
}

inline int pair_class(int v) {
  return std::min(std::abs(v), kEscapeClass);
}

// Read as a neighbour where there is none; long enough for the phantom position 64.
constexpr int16_t kZeroBlock[72] = {};

// Token models of one plane (offsets into its model array).
constexpr int kNzCtx = 11;  // predicted AC count buckets + "no neighbour"
constexpr int kDcCtx = 8;   // bit length of the neighbours' DC difference
constexpr int kBands = 10;  // pair position bands
constexpr int kRemCtx = 7;  // nonzeros left
constexpr int kNbCtx = 6;   // neighbours' magnitude at the pair's positions
constexpr int kNzHist = 0;
constexpr int kDcHist = kNzHist + kNzCtx;
constexpr int kPairHist = kDcHist + kDcCtx;
constexpr int kEscHist = kPairHist + kBands * kRemCtx * kNbCtx;  // per band and neighbours
constexpr int kHistPerPlane = kEscHist + kBands * kNbCtx;

constexpr uint8_t kMagic[4] = {'V', 'T', 'D', 'C'};
// Version 4 added the per-page modes (kinds 3 and 4); version 3 tables still read, and their
// pages may use only kinds 0-2.
constexpr uint8_t kTablesVersion = 4;
constexpr uint8_t kOldestTablesVersion = 3;
constexpr uint8_t kPageCoded = 0;
constexpr uint8_t kPageConstant = 1;
constexpr uint8_t kPageStored = 2;     // texels raw, when coding would not make the page smaller
constexpr uint8_t kPageCodedMode = 3;  // a mode byte (DctPageMode), then as kPageCoded
static_assert(kDctPageLossless == 4);

struct BucketTables {
  uint8_t nz[64];
  uint8_t rem[64];                   // index: nonzeros left (>= 1); model offset of its bucket
  uint16_t rem_bytes[64];            // the same offsets in bytes
  alignas(16) int32_t pair[kPairs];  // first model of pair j's band
  alignas(16) int32_t esc[kPairs];   // first escape model of pair j's band
  uint8_t nb[64];                    // index: min(sum of neighbour magnitudes, 63)
  uint8_t max_row[64];               // largest row / column among zigzag positions 0..k
  uint8_t max_col[64];
  PairToken pair_token[kTokens];
  uint32_t pair_value[kTokens][4];  // coefficient_pair of a token without escapes, by sign bits
  constexpr BucketTables()
      : nz(),
        rem(),
        rem_bytes(),
        pair(),
        esc(),
        nb(),
        max_row(),
        max_col(),
        pair_token(),
        pair_value() {
    for (int t = 0; t < kTokens; t++) {
      const int a0 = t & 3, a1 = t >> 2;
      const int nonzeros = (a0 != 0) + (a1 != 0);
      pair_token[t] = {uint8_t(nonzeros), uint8_t((1 << nonzeros) - 1),
                       uint8_t((a0 == kEscapeClass) | (a1 == kEscapeClass) << 1), 0};
      for (uint32_t signs = 0; signs < 4; signs++) {
        pair_value[t][signs] = signed_pair(a0, a1, signs & ((1u << nonzeros) - 1), a0 != 0);
      }
    }
    for (int j = 0; j < kPairs; j++) {
      const int band = j <= 4 ? j : j <= 6 ? 5 : j <= 9 ? 6 : j <= 13 ? 7 : j <= 18 ? 8 : 9;
      pair[j] = kPairHist + band * kRemCtx * kNbCtx;
      esc[j] = kEscHist + band * kNbCtx;
    }
    for (int i = 0; i < 64; i++) {
      nz[i] = i <= 3 ? i : i <= 5 ? 4 : i <= 7 ? 5 : i <= 11 ? 6 : i <= 17 ? 7 : i <= 27 ? 8 : 9;
      rem[i] = kNbCtx * (i <= 1 ? 0 : i <= 3 ? i - 1 : i <= 5 ? 3 : i <= 8 ? 4 : i <= 14 ? 5 : 6);
      rem_bytes[i] = uint16_t(rem[i] * sizeof(TokenModel));
      nb[i] = i <= 2 ? i : i <= 4 ? 3 : i <= 8 ? 4 : 5;  // as pair_contexts computes it
      int r = 0, c = 0;
      for (int k = 0; k <= i; k++) {
        r = std::max(r, kZigzag[k] >> 3);
        c = std::max(c, kZigzag[k] & 7);
      }
      max_row[i] = uint8_t(r);
      max_col[i] = uint8_t(c);
    }
  }
};
constexpr BucketTables kBuckets;

int plane_count(const DctSettings& s) {
  return s.channels;
}

bool plane_is_chroma(const DctSettings& s, int plane) {
  return s.layout != DctPlaneLayout::kPlanes && (plane == 1 || plane == 2);
}

bool plane_is_half(const DctSettings& s, int plane) {
  return s.layout == DctPlaneLayout::kYCoCg420 && (plane == 1 || plane == 2);
}

int round_up8(int v) {
  return (v + 7) & ~7;
}

struct PlaneDims {
  int w, h;  // padded to whole blocks
  int bw, bh;
};

PlaneDims plane_dims(const DctSettings& s, int plane, int width, int height) {
  const bool half = plane_is_half(s, plane);
  const int w = round_up8(half ? (width + 1) / 2 : width);
  const int h = round_up8(half ? (height + 1) / 2 : height);
  return {w, h, w / 8, h / 8};
}

Status check_settings(const DctSettings& s) {
  if (s.quality < 1 || s.quality > 100) {
    return Error(ErrorCode::kInvalidArgument,
                 "dct: quality " + std::to_string(s.quality) + " is outside 1..100");
  }
  if (s.channels < 1 || s.channels > 4) {
    return Error(ErrorCode::kInvalidArgument,
                 "dct: " + std::to_string(s.channels) + " channels (1..4 supported)");
  }
  if (s.layout != DctPlaneLayout::kPlanes && s.layout != DctPlaneLayout::kYCoCg &&
      s.layout != DctPlaneLayout::kYCoCg420) {
    return Error(ErrorCode::kInvalidArgument, "dct: unknown plane layout");
  }
  if (s.layout != DctPlaneLayout::kPlanes && s.channels < 3) {
    return Error(ErrorCode::kInvalidArgument,
                 "dct: the YCoCg layouts need 3 or 4 channels, got " + std::to_string(s.channels));
  }
  return Status::Ok();
}

Status check_size(int width, int height) {
  if (width <= 0 || height <= 0 || width % 8 != 0 || height % 8 != 0 || width > kMaxPageSize ||
      height > kMaxPageSize) {
    return Error(ErrorCode::kInvalidArgument,
                 "dct: page size " + std::to_string(width) + "x" + std::to_string(height) +
                     " is not a multiple of 8 in 8.." + std::to_string(kMaxPageSize));
  }
  return Status::Ok();
}

// Quantiser steps for a plane, natural order. Close to flat (what PSNR rewards) with a mild
// rise toward high frequencies; chroma a little coarser. Scaled by quality as libjpeg does.
void make_quant(const DctSettings& s, int plane, uint8_t* q) {
  const int quality = s.quality;
  const double scale = (quality < 50 ? 5000.0 / quality : 200.0 - 2.0 * quality) / 100.0;
  const bool chroma = plane_is_chroma(s, plane);
  const double base = chroma ? 13.0 : 12.0;
  const double slope = chroma ? 0.12 : 0.10;
  for (int v = 0; v < 8; v++) {
    for (int u = 0; u < 8; u++) {
      const double step = base * scale * (1.0 + slope * (u + v));
      q[v * 8 + u] = uint8_t(std::clamp(std::lround(step), 1L, 255L));
    }
  }
}

}  // namespace

struct DctTables {
  DctSettings settings;
  int width = 0;
  int height = 0;
  uint8_t quant[4][64] = {};
  // Zigzag order, for the decoder: the steps, and the largest magnitudes that do not saturate
  // (ceil(kMaxDequantized / step)), so that clamping before the multiply gives the same result
  // as after it and the product fits 16 bits.
  alignas(16) int16_t dequant_step[4][64] = {};
  alignas(16) int16_t dequant_limit[4][64] = {};
  // Token models per plane (kHistPerPlane each). Trained models stay fixed (static, the fast
  // path); untrained ones adapt while a page is coded.
  bool adaptive = true;
  std::vector<TokenModel> models[4];
  std::vector<float> token_bits[4];  // the encoder's rate estimate from the models (token_bits)
  uint8_t version = kTablesVersion;
  // The tables of each page mode byte (full chroma | finer << 1), made with the tables; null
  // where the mode does not apply. Mode 0 is these tables themselves.
  std::array<std::unique_ptr<DctTables>, kDctPageModes> variant;
};

void DctTablesDeleter::operator()(DctTables* t) const {
  delete t;
}

DctTablesShape dct_tables_shape(const DctTables& tables) {
  return {tables.settings.channels, tables.width, tables.height};
}

namespace {

// Per-block side information the neighbours' contexts read.
struct BlockInfo {
  int16_t dc;
  uint8_t nz;
  uint8_t last;  // zigzag index of the last nonzero coefficient, 0 when only DC
};

// A block's neighbours, and the contexts and prediction they give its first two tokens.
struct BlockNeighbours {
  const int16_t* left;  // coefficients, zigzag order
  const int16_t* up;
  int nz_ctx;
  int dc_pred;
  int dc_ctx;
};

// `z` is block (bx, by) of a plane bw blocks wide. A missing neighbour is the other one, or
// zeros for the first block.
[[gnu::always_inline]] inline BlockNeighbours block_neighbours(const int16_t* z,
                                                               const BlockInfo* info, int bx,
                                                               int by, int bw) {
  const int index = by * bw + bx;
  const bool has_left = bx > 0, has_up = by > 0;
  BlockNeighbours n;
  n.left = has_left ? z - 64 : has_up ? z - size_t(bw) * 64 : kZeroBlock;
  n.up = has_up ? z - size_t(bw) * 64 : n.left;
  n.nz_ctx = kNzCtx - 1;
  if (has_left || has_up) {
    const int a = has_left ? info[index - 1].nz : info[index - bw].nz;
    const int b = has_up ? info[index - bw].nz : a;
    n.nz_ctx = kBuckets.nz[(a + b + 1) >> 1];
  }
  // DC: a median (LOCO-I) predictor.
  n.dc_pred = 0;
  n.dc_ctx = 0;
  if (has_left && has_up) {
    const int l = info[index - 1].dc, a = info[index - bw].dc;
    const int al = info[index - bw - 1].dc;
    n.dc_pred = std::clamp(l + a - al, std::min(l, a), std::max(l, a));
    n.dc_ctx = std::min(bit_length(unsigned(std::abs(l - a))), kDcCtx - 1);
  } else if (has_left) {
    n.dc_pred = info[index - 1].dc;
  } else if (has_up) {
    n.dc_pred = info[index - bw].dc;
  }
  return n;
}

// Pair contexts of pairs j0..j0+3 (j0 a multiple of 4), before the nonzeros-left term: the
// pair's band plus the bucket of the neighbours' summed magnitude over its two positions, times
// `scale` (1 for model indices, sizeof(TokenModel) for byte offsets), into `pair`; the escape
// model (band and the same bucket, an index) into `esc`. Four pairs at once keep this off the
// per-token path.
inline void pair_contexts(const int16_t* left, const int16_t* up, int j0, int scale, uint16_t* pair,
                          uint16_t* esc) {
  const int k0 = 2 * j0 + 1;  // positions k0..k0+7; position 64 is the phantom, counted as 0
#if defined(__SSE2__)
  const __m128i zero = _mm_setzero_si128();
  const __m128i l = _mm_loadu_si128(reinterpret_cast<const __m128i*>(left + k0));
  const __m128i u = _mm_loadu_si128(reinterpret_cast<const __m128i*>(up + k0));
  // |l| + |u| <= 8196: decoded coefficients never exceed 3 + 4095.
  __m128i sum = _mm_add_epi16(_mm_max_epi16(l, _mm_sub_epi16(zero, l)),
                              _mm_max_epi16(u, _mm_sub_epi16(zero, u)));
  if (k0 == 57) sum = _mm_and_si128(sum, _mm_setr_epi16(-1, -1, -1, -1, -1, -1, -1, 0));
  const __m128i pair_sum = _mm_madd_epi16(sum, _mm_set1_epi16(1));
  // The bucket is [sum >= 1] + [sum >= 2] + [sum >= 3] + [sum >= 5] + [sum >= 9] (kBuckets.nb);
  // each comparison gives -1 where it holds.
  __m128i minus_bucket = _mm_cmpgt_epi32(pair_sum, zero);
  minus_bucket = _mm_add_epi32(minus_bucket, _mm_cmpgt_epi32(pair_sum, _mm_set1_epi32(1)));
  minus_bucket = _mm_add_epi32(minus_bucket, _mm_cmpgt_epi32(pair_sum, _mm_set1_epi32(2)));
  minus_bucket = _mm_add_epi32(minus_bucket, _mm_cmpgt_epi32(pair_sum, _mm_set1_epi32(4)));
  minus_bucket = _mm_add_epi32(minus_bucket, _mm_cmpgt_epi32(pair_sum, _mm_set1_epi32(8)));
  const __m128i p = _mm_sub_epi32(
      _mm_load_si128(reinterpret_cast<const __m128i*>(kBuckets.pair + j0)), minus_bucket);
  const __m128i e = _mm_sub_epi32(
      _mm_load_si128(reinterpret_cast<const __m128i*>(kBuckets.esc + j0)), minus_bucket);
  // Both fit 16 bits: indices < kHistPerPlane, byte offsets < kHistPerPlane * 48.
  const __m128i packed = _mm_packs_epi32(p, e);
  _mm_storel_epi64(reinterpret_cast<__m128i*>(pair),
                   _mm_mullo_epi16(packed, _mm_set1_epi16(int16_t(scale))));
  _mm_storel_epi64(reinterpret_cast<__m128i*>(esc), _mm_unpackhi_epi64(packed, packed));
#else
  for (int q = 0; q < 4; q++) {
    int sum = 0;
    for (int k = k0 + 2 * q; k < k0 + 2 * q + 2 && k < 64; k++) {
      sum += std::abs(left[k]) + std::abs(up[k]);
    }
    const int bucket = kBuckets.nb[std::min(sum, 63)];
    pair[q] = uint16_t((kBuckets.pair[j0 + q] + bucket) * scale);
    esc[q] = uint16_t(kBuckets.esc[j0 + q] + bucket);
  }
#endif
}

// The two ways of walking a plane's tokens for the encoder: encoding records them, counting
// trains the models. Each has token(models, index, token) and raw(value, bits).

template <bool kAdaptive>
class TokenEncoder {
 public:
  void token(TokenModel* models, int i, int t) {
    rans.put(models[i], t);
    if constexpr (kAdaptive) dct_detail::adapt(models[i], t);
  }
  void raw(uint32_t v, int n) { bits.put(v, n); }
  RansEncoder rans;
  BitWriter bits;
};

class TokenCounter {
 public:
  explicit TokenCounter(std::array<uint32_t, kTokens>* counts) : counts_(counts) {}
  void token(TokenModel*, int i, int t) { counts_[i][t]++; }
  void raw(uint32_t, int) {}

 private:
  std::array<uint32_t, kTokens>* counts_;
};

// An unsigned value as a token in model i plus its low bits raw.
template <class Coder>
void code_uint(Coder& c, TokenModel* models, int i, unsigned v) {
  const int t = uint_token(v);
  c.token(models, i, t);
  c.raw(v - kUintBase[t], kUintExtra[t]);
}

// Codes one plane's blocks from `coefs` (quantised, zigzag order, one block after another).
// decode_plane mirrors it token for token.
template <class Coder>
void code_plane(Coder& c, TokenModel* models, int bw, int bh, const int16_t* coefs,
                BlockInfo* info) {
  for (int by = 0; by < bh; by++) {
    for (int bx = 0; bx < bw; bx++) {
      const int index = by * bw + bx;
      const int16_t* z = coefs + size_t(index) * 64;
      const BlockNeighbours n = block_neighbours(z, info, bx, by, bw);
      int nz = 0;
      for (int k = 1; k < 64; k++) nz += z[k] != 0;
      code_uint(c, models, kNzHist + n.nz_ctx, unsigned(nz));
      // The DC residual: a magnitude token, then the sign raw.
      const int res = z[0] - n.dc_pred;
      code_uint(c, models, kDcHist + n.dc_ctx, unsigned(std::abs(res)));
      if (res != 0) c.raw(res < 0, 1);
      // Pair tokens while nonzeros remain. The context takes the nonzeros left as they were
      // two tokens back, so that a decoded token's context never waits on the token just
      // before it.
      uint16_t pair_ctx[4], esc_ctx[kPairs];
      int escaped[64], escapes = 0;                  // zigzag positions, in order
      int rem = nz, rem1 = nz, rem2 = nz, last = 0;  // rem1, rem2: after tokens j - 1, j - 2
      for (int j = 0, k = 1; rem > 0; j++, k += 2) {
        if ((j & 3) == 0) pair_contexts(n.left, n.up, j, 1, pair_ctx, esc_ctx + j);
        const int i = pair_ctx[j & 3] + kBuckets.rem[rem2];
        const int v0 = z[k], v1 = k < 63 ? z[k + 1] : 0;
        const int a0 = pair_class(v0), a1 = pair_class(v1);
        c.token(models, i, a0 + 4 * a1);
        c.raw(uint32_t(v0 < 0) | (uint32_t(v1 < 0) << (v0 != 0)), (v0 != 0) + (v1 != 0));
        if (a0 == kEscapeClass) escaped[escapes++] = k;
        if (a1 == kEscapeClass) escaped[escapes++] = k + 1;
        rem -= (v0 != 0) + (v1 != 0);
        rem2 = rem1;
        rem1 = rem;
        last = v1 != 0 ? k + 1 : v0 != 0 ? k : last;
      }
      // The block's escapes after its pairs: the pair loop then has no branch on them.
      for (int e = 0; e < escapes; e++) {
        const int k = escaped[e];
        code_uint(c, models, esc_ctx[(k - 1) >> 1], unsigned(std::abs(z[k])) - 3);
      }
      info[index] = {z[0], uint8_t(nz), uint8_t(last)};
    }
  }
}

// ---- encoder side (floating point is fine here: only the decoder must be exact) ----

struct FloatPlane {
  PlaneDims dims;
  std::vector<float> v;  // centred samples, padded by edge replication
};

void build_planes(const DctSettings& s, const uint8_t* texels, int width, int height,
                  FloatPlane* planes) {
  const int ch = s.channels;
  const int n = plane_count(s);
  const size_t count = size_t(width) * height;
  // Full-resolution values of every plane first (each texel's colour transform once), then
  // 4:2:0 means and edge padding from them.
  thread_local std::vector<float> full;  // per thread: no allocation per page
  full.resize(count * size_t(n));
  if (s.layout == DctPlaneLayout::kPlanes) {
    for (int p = 0; p < n; p++) {
      float* f = full.data() + size_t(p) * count;
      for (size_t i = 0; i < count; i++) f[i] = float(texels[i * size_t(ch) + size_t(p)]) - 128.0f;
    }
  } else {
    float* y = full.data();
    float* co = y + count;
    float* cg = co + count;
    for (size_t i = 0; i < count; i++) {
      const uint8_t* t = texels + i * size_t(ch);
      const float r = t[0], g = t[1], b = t[2];
      y[i] = (r + 2 * g + b) * 0.25f - 128.0f;
      co[i] = (r - b) * 0.5f;
      cg[i] = (2 * g - r - b) * 0.25f;
    }
    if (n == 4) {
      float* a = cg + count;
      for (size_t i = 0; i < count; i++) a[i] = float(texels[i * 4 + 3]) - 128.0f;
    }
  }
  for (int p = 0; p < n; p++) {
    FloatPlane& fp = planes[p];
    fp.dims = plane_dims(s, p, width, height);
    fp.v.resize(size_t(fp.dims.w) * fp.dims.h);
    const float* src = full.data() + size_t(p) * count;
    const bool half = plane_is_half(s, p);
    const int sw = half ? (width + 1) / 2 : width, sh = half ? (height + 1) / 2 : height;
    for (int y = 0; y < fp.dims.h; y++) {
      const int sy = std::min(y, sh - 1);
      float* row = fp.v.data() + size_t(y) * fp.dims.w;
      if (half) {
        const float* r0 = src + size_t(2 * sy) * width;
        const float* r1 = src + size_t(std::min(2 * sy + 1, height - 1)) * width;
        for (int x = 0; x < sw; x++) {
          const int x0 = 2 * x, x1 = std::min(x0 + 1, width - 1);
          row[x] = 0.25f * (r0[x0] + r0[x1] + r1[x0] + r1[x1]);
        }
      } else {
        std::memcpy(row, src + size_t(sy) * width, size_t(sw) * sizeof(float));
      }
      for (int x = sw; x < fp.dims.w; x++) row[x] = row[sw - 1];
    }
  }
  // Kept for the next page of usual sizes, not for huge ones.
  if (full.size() > (size_t(1) << 22)) std::vector<float>().swap(full);
}

// The orthonormal DCT-II basis, float: b[u][x].
struct ForwardBasis {
  float b[8][8];
  ForwardBasis() {
    for (int u = 0; u < 8; u++) {
      const double s = u == 0 ? std::sqrt(0.125) : 0.5;
      for (int x = 0; x < 8; x++)
        b[u][x] = float(s * std::cos((2 * x + 1) * u * std::numbers::pi / 16.0));
    }
  }
};

// Forward DCT and deadzone quantisation of every block of a plane into zigzag order. Written as
// broadcast multiply-adds over whole rows so that compilers vectorise it.
// With `scaled`, also each coefficient over its step (signed, zigzag order), for the
// rate-distortion pass (rdo_plane).
void quantize_plane(const FloatPlane& fp, const uint8_t* quant, int16_t* coefs,
                    float* scaled = nullptr) {
  static const ForwardBasis basis;
  float bt[8][8];  // bt[x][u] = b[u][x]
  for (int u = 0; u < 8; u++)
    for (int x = 0; x < 8; x++) bt[x][u] = basis.b[u][x];
  alignas(16) float inv_step[64];
  // Rounding offset below 1/2 on AC: cheaper, and near MSE-optimal for Laplacian data.
  alignas(16) float rounding[64];
  for (int i = 0; i < 64; i++) {
    inv_step[i] = 1.0f / float(quant[i]);
    rounding[i] = i == 0 ? 0.5f : 0.36f;
  }
  const PlaneDims& d = fp.dims;
  for (int by = 0; by < d.bh; by++) {
    for (int bx = 0; bx < d.bw; bx++) {
      const float* src = fp.v.data() + size_t(by) * 8 * d.w + bx * 8;
      float tmp[8][8];  // tmp[y][u]: rows transformed
      for (int y = 0; y < 8; y++) {
        float acc[8] = {};
        for (int x = 0; x < 8; x++) {
          const float v = src[size_t(y) * d.w + x];
          for (int u = 0; u < 8; u++) acc[u] += v * bt[x][u];
        }
        std::memcpy(tmp[y], acc, sizeof(acc));
      }
      alignas(16) float c[64];  // c[v * 8 + u]
      for (int v = 0; v < 8; v++) {
        float acc[8] = {};
        for (int y = 0; y < 8; y++) {
          const float b = basis.b[v][y];
          for (int u = 0; u < 8; u++) acc[u] += b * tmp[y][u];
        }
        std::memcpy(c + v * 8, acc, sizeof(acc));
      }
      alignas(16) int32_t q[64];  // natural order
      for (int i = 0; i < 64; i++) {
        const float a = std::fabs(c[i]) * inv_step[i];
        int mag = std::min(int(a + rounding[i]), kMaxDequantized);
        // For the rate-distortion pass, from half a step a one that it may drop.
        if (scaled) mag = std::max(mag, int(a >= 0.5f));
        q[i] = c[i] < 0.0f ? -mag : mag;
      }
      const size_t block = size_t(by) * d.bw + bx;
      int16_t* z = coefs + block * 64;
      for (int k = 0; k < 64; k++) z[k] = q[kZigzag[k]];
      if (scaled) {
        for (int k = 0; k < 64; k++) scaled[block * 64 + k] = c[kZigzag[k]] * inv_step[kZigzag[k]];
      }
    }
  }
}

// ---- rate-distortion optimised quantisation ----

// The price of a token in bits, beside its own: the decoder's time goes by tokens, so the pass
// also ends blocks earlier where that costs little. And the pass's lambda over the uniform
// quantiser's slope (rdo_lambda). Chosen at equal PSNR on photographs (Kodak q50, trained tables,
// docs/BENCHMARKS.md "Rate-distortion optimised levels"): 1.4% fewer bytes and 7% fewer decode
// instructions a page than the deadzone levels alone; with no token price, 2% and 6%.
constexpr float kRdoTokenBits = 2.0f;
constexpr double kRdoSlopeScale = 1.25;

// The rate-distortion pass's costs of one plane's tokens (kHistPerPlane * kTokens, from each
// token's -log2 probability), pair tokens with their sign bits and the price of their tokens
// (kRdoTokenBits each, escapes included) added, so that the pass prices a pair with one lookup.
void price_pair_tokens(float* bits) {
  for (int i = kPairHist; i < kEscHist; i++) {
    for (int t = 0; t < kTokens; t++) {
      const PairToken& e = kBuckets.pair_token[t];
      bits[size_t(i) * kTokens + size_t(t)] +=
          float(e.nonzeros) + kRdoTokenBits * float(1 + std::popcount(unsigned(e.escapes)));
    }
  }
}

// The pass's token costs from a plane's models: exact for static models, the starting point for
// adaptive ones.
std::vector<float> token_bits(const std::vector<TokenModel>& models) {
  std::vector<float> bits(models.size() * kTokens);
  for (size_t i = 0; i < models.size(); i++) {
    for (int t = 0; t < kTokens; t++) {
      const unsigned f = models[i].above()[t] - dct_detail::token_start(models[i], unsigned(t));
      bits[i * kTokens + size_t(t)] = float(dct_detail::kFreqBits - std::log2(double(f)));
    }
  }
  price_pair_tokens(bits.data());
  return bits;
}

// Bit k set where AC position k of block z is nonzero; in `ones`, where it is +-1.
inline uint64_t ac_masks(const int16_t* z, uint64_t* ones) {
  uint64_t nonzero = 0, one = 0;
#if defined(__SSE2__)
  const __m128i zero = _mm_setzero_si128(), plus = _mm_set1_epi16(1), minus = _mm_set1_epi16(-1);
  auto ones_of = [&](__m128i v) {
    return _mm_or_si128(_mm_cmpeq_epi16(v, plus), _mm_cmpeq_epi16(v, minus));
  };
  for (int i = 0; i < 64; i += 16) {
    const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(z + i));
    const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(z + i + 8));
    const unsigned zeros = unsigned(
        _mm_movemask_epi8(_mm_packs_epi16(_mm_cmpeq_epi16(a, zero), _mm_cmpeq_epi16(b, zero))));
    const unsigned o = unsigned(_mm_movemask_epi8(_mm_packs_epi16(ones_of(a), ones_of(b))));
    nonzero |= uint64_t(~zeros & 0xFFFFu) << i;
    one |= uint64_t(o) << i;
  }
#else
  for (int k = 0; k < 64; k++) {
    nonzero |= uint64_t(z[k] != 0) << k;
    one |= uint64_t(z[k] == 1 || z[k] == -1) << k;
  }
#endif
  *ones = one & ~uint64_t(1);
  return nonzero & ~uint64_t(1);
}

// Bits a one in the middle of a block can save at most: its sign bit and a change of its pair
// token's class. Ones whose added error is dearer are not tried.
constexpr float kRdoMaxSavedBits = 6.0f;

// Levels chosen by rate and distortion for one plane, in coding order so that each block's
// contexts see its neighbours' final levels. Levels of 2 and more keep the deadzone rounding
// (quantize_plane's); each level of 1 (from a coefficient of at least half a step) may become 0:
// first the block's end where J = SSE + lambda * bits is least (trailing ones cost a token per
// pair up to them), then each remaining one, last first, where that lowers J. DC levels are kept.
// The rate is code_plane's: the count token, and each pair token with its sign bits under its
// contexts (nonzeros left included); escapes are left out, as dropping a one never changes them.
// `bits`: the plane's token costs (token_bits); `scaled`: the coefficients over their steps
// (quantize_plane); `lambda`: coefficient SSE per bit.
void rdo_plane(const float* bits, double lambda, const uint8_t* quant, int bw, int bh,
               const float* scaled, int16_t* coefs, BlockInfo* info) {
  const float lam = float(lambda);
  for (int by = 0; by < bh; by++) {
    for (int bx = 0; bx < bw; bx++) {
      const int index = by * bw + bx;
      int16_t* z = coefs + size_t(index) * 64;
      const float* x = scaled + size_t(index) * 64;
      uint64_t ones;
      uint64_t nonzero = ac_masks(z, &ones);
      if (ones != 0) {
        const BlockNeighbours n = block_neighbours(z, info, bx, by, bw);
        const int last = 63 - std::countl_zero(nonzero);
        const int pairs = (last + 1) / 2;  // pair j holds positions 2j + 1, 2j + 2
        uint16_t pair_ctx[kPairs], esc_ctx[kPairs];
        for (int j = 0; j < pairs; j += 4)
          pair_contexts(n.left, n.up, j, 1, pair_ctx + j, esc_ctx + j);
        // Per pair: its nonzeros, and its token's offset in `bits` under its neighbour
        // contexts (the nonzeros-left term is added as a walk goes).
        uint8_t pair_nz[kPairs];
        uint16_t offset[kPairs];
        for (int j = 0, k = 1; j < pairs; j++, k += 2) {
          const int v1 = k < 63 ? z[k + 1] : 0;
          pair_nz[j] = uint8_t((z[k] != 0) + (v1 != 0));
          offset[j] = uint16_t(pair_ctx[j] * kTokens + pair_class(z[k]) + 4 * pair_class(v1));
        }
        const float* nz_bits = bits + (kNzHist + n.nz_ctx) * kTokens;
        auto rate = [&](uint64_t nonzeros) {
          const int count = std::popcount(nonzeros);
          const int end = nonzeros ? (64 - std::countl_zero(nonzeros)) / 2 : 0;
          const int t = uint_token(unsigned(count));
          float total = nz_bits[t] + float(kUintExtra[t]);
          for (int j = 0, rem1 = count, rem2 = count; j < end; j++) {
            total += bits[offset[j] + kBuckets.rem[rem2] * kTokens];
            rem2 = rem1;
            rem1 -= pair_nz[j];
          }
          return lam * total;
        };
        // Position k's one becomes zero (dir -1) or comes back (+1) in the pair tables: its
        // class is bit 0 of the token for the pair's first position, bit 2 for its second.
        auto toggle = [&](int k, int dir) {
          const int j = (k - 1) >> 1;
          offset[j] = uint16_t(offset[j] + dir * (k & 1 ? 1 : 4));
          pair_nz[j] = uint8_t(pair_nz[j] + dir);
        };
        // SSE added by a one becoming zero: s^2 (|x|^2 - (|x| - 1)^2) = s^2 (2 |x| - 1).
        auto added = [&](int k) {
          const float s = quant[kZigzag[k]];
          return s * s * (2.0f * std::fabs(x[k]) - 1.0f);
        };
        // The end: trailing ones dropped while no larger level is met.
        float best = rate(nonzero), best_rate = best, dropped = 0;
        uint64_t best_nonzero = nonzero;
        for (uint64_t trial = nonzero; trial != 0;) {
          const int k = 63 - std::countl_zero(trial);
          if (!((ones >> k) & 1)) break;
          dropped += added(k);
          if (dropped >= best) break;  // no shorter end can win: the rate is at least 0
          trial &= ~(uint64_t(1) << k);
          const float r = rate(trial);
          if (dropped + r < best) {
            best = dropped + r;
            best_rate = r;
            best_nonzero = trial;
          }
        }
        for (uint64_t gone = nonzero & ~best_nonzero; gone != 0; gone &= gone - 1) {
          const int k = std::countr_zero(gone);
          toggle(k, -1);
          z[k] = 0;
        }
        nonzero = best_nonzero;
        // Each remaining one, last first, unless dearer than a mid-block one ever saves (its
        // sign bit and a change of its pair token's class: a few bits).
        float current = best_rate;
        for (uint64_t left = ones & nonzero; left != 0;) {
          const int k = 63 - std::countl_zero(left);
          left &= ~(uint64_t(1) << k);
          const float cost = added(k);
          if (cost >= lam * kRdoMaxSavedBits) continue;
          const uint64_t trial = nonzero & ~(uint64_t(1) << k);
          toggle(k, -1);
          const float r = rate(trial);
          if (cost + r < current) {
            current = r;
            nonzero = trial;
            z[k] = 0;
          } else {
            toggle(k, +1);
          }
        }
      }
      info[index] = {z[0], uint8_t(std::popcount(nonzero)),
                     uint8_t(nonzero ? 63 - std::countl_zero(nonzero) : 0)};
    }
  }
}

// The distortion-rate slope of a uniform quantiser of step `step`, SSE per bit: 2 ln 2 step^2 / 12.
double uniform_quantiser_slope(int step) {
  return 2.0 * std::numbers::ln2 * step * step / 12.0;
}

// The layer's rate-distortion slope, texel SSE (summed over channels) per bit, at luma DC step
// `step`: the default mode's curve on photographs (Kodak, all levels, chords between q50/75/90/95)
// has slopes of about 62, 31, 7.8 and 3.5 SSE per bit at steps 12, 6, 2 and 1, about 5 * step;
// bounded below by the slope of a uniform quantiser of that step, 2 ln 2 * step^2 / 12.
double layer_slope(int step) {
  return std::max(uniform_quantiser_slope(step), 5.0 * step);
}

// The rate-distortion pass's lambda for plane p, coefficient SSE per bit: a uniform quantiser's
// slope at the luma DC step, 2 ln 2 * step^2 / 12, for luma, and for the other planes the same
// texel SSE per bit over the texel SSE one unit of their error makes. YCoCg: Y adds to R, G and
// B (3), Co to R and B (2), Cg to all three (3); a 4:2:0 chroma sample covers four texels. (The
// layer's slope above is steeper: it carries the 4:2:0 chroma error no level buys back, and at
// fine steps it dropped levels that smooth content needed.)
double rdo_lambda(const DctSettings& s, int step, int p) {
  double luma_weight = 1, weight = 1;
  if (s.layout != DctPlaneLayout::kPlanes && p < 3) {
    luma_weight = 3;
    weight = p == 1 ? 2 : 3;
    if (plane_is_half(s, p)) weight *= 4;
  }
  return kRdoSlopeScale * uniform_quantiser_slope(step) * luma_weight / weight;
}

// Plane p's levels as the encoder codes them, zigzag order: quantised, then, with `bits` (the
// plane's token costs) and below quality 100, through the rate-distortion pass. Quality 100 keeps
// every level the deadzone quantiser gives: the pass would trade error for bytes (on smooth
// content up to 4.5 dB for half the bytes), and q100 asks for the least error.
void plane_levels(const DctSettings& s, const FloatPlane& fp, int p, int luma_step,
                  const uint8_t* quant, const float* bits, int16_t* coefs, BlockInfo* info) {
  if (!bits || s.quality == 100) {
    quantize_plane(fp, quant, coefs);
    return;
  }
  thread_local std::vector<float> scaled;  // per thread: no allocation per page
  scaled.resize(size_t(fp.dims.bw) * fp.dims.bh * 64);
  quantize_plane(fp, quant, coefs, scaled.data());
  rdo_plane(bits, rdo_lambda(s, luma_step, p), quant, fp.dims.bw, fp.dims.bh, scaled.data(), coefs,
            info);
}

// ---- tables: static token frequencies ----

// A model whose frequencies sum to kFreqTotal, each >= 1, from non-negative weights.
TokenModel make_model(const double* w) {
  double total = 0;
  for (int t = 0; t < kTokens; t++) total += w[t];
  int f[kTokens], sum = 0, largest = 0;
  for (int t = 0; t < kTokens; t++) {
    const double share = total > 0 ? w[t] / total : 1.0 / kTokens;
    f[t] = std::max(1, int(std::lround(share * (kFreqTotal - kTokens))));
    sum += f[t];
    if (f[t] > f[largest]) largest = t;
  }
  f[largest] += int(kFreqTotal) - sum;  // rounding leaves at most a few units to move
  TokenModel m;
  uint32_t above = 0;
  for (int t = 0; t < kTokens; t++) m.above()[t] = uint16_t(above += uint32_t(f[t]));
  return m;
}

using TokenCounts = std::vector<std::array<uint32_t, kTokens>>;  // [plane * kHistPerPlane + i]

// Deterministic stand-in for content when no training pages are given: value noise over
// several octaves (roughly the 1/f spectrum of photographs and textures), mostly shared by the
// channels, whose fine detail fades in and out across the page so that busy, smooth and flat
// areas all occur, plus a hard edge. The last page is a flat field with a gentle gradient.
std::vector<uint8_t> synthetic_page(int size, int channels, uint32_t seed, bool flat) {
  auto lattice = [&](int x, int y, uint32_t salt) {
    return float(hash32(uint32_t(x) * 73856093u ^ uint32_t(y) * 19349663u ^ salt) >> 8) /
               float(1 << 24) -
           0.5f;
  };
  auto noise = [&](int x, int y, int cell, uint32_t salt) {
    const int gx = x / cell, gy = y / cell;
    const float fx = float(x % cell) / float(cell), fy = float(y % cell) / float(cell);
    const float sx = fx * fx * (3 - 2 * fx), sy = fy * fy * (3 - 2 * fy);
    const float a = lattice(gx, gy, salt), b = lattice(gx + 1, gy, salt);
    const float c = lattice(gx, gy + 1, salt), d = lattice(gx + 1, gy + 1, salt);
    return (a + (b - a) * sx) * (1 - sy) + (c + (d - c) * sx) * sy;
  };
  std::vector<uint8_t> page(size_t(size) * size * channels);
  const float edge_a = float(int(hash32(seed) % 7) - 3),
              edge_b = float(int(hash32(seed + 1) % 5) - 2);
  const float edge_c = float(int(hash32(seed + 2) % uint32_t(size)));
  for (int y = 0; y < size; y++) {
    for (int x = 0; x < size; x++) {
      const float detail = std::clamp(noise(x, y, 48, seed * 7) * 5.0f + 0.6f, 0.0f, 1.0f);
      float shared = 0;
      for (int cell = 64, o = 0; cell >= 1; cell /= 2, o++) {
        const float amp = 130.0f * std::pow(float(cell) / 64.0f, 0.85f);
        shared += (cell >= 16 ? amp : amp * detail * detail) * noise(x, y, cell, seed * 131 + o);
      }
      if (edge_a * float(x - size / 2) + edge_b * float(y) > edge_c) shared += 45.0f;
      if (flat) shared = 0.1f * float(x + y) + (x > size / 2 ? 3.0f : 0.0f);
      for (int c = 0; c < channels; c++) {
        float v = 128.0f + shared * (1.0f - 0.15f * float(c));
        for (int cell = 32; cell >= 2 && !flat; cell /= 4) {
          v += 30.0f * detail * std::pow(float(cell) / 32.0f, 0.85f) *
               noise(x, y, cell, seed * 977 + uint32_t(c) * 31 + uint32_t(cell));
        }
        page[(size_t(y) * size + x) * channels + c] = uint8_t(std::clamp(v, 0.0f, 255.0f));
      }
    }
  }
  return page;
}

void count_tokens(const DctSettings& s, const uint8_t* const quant[4], const uint8_t* texels,
                  int width, int height, TokenCounts& counts, const float* bits = nullptr);

// Prior token probabilities per histogram from synthetic pages, smoothed toward broader
// groups (the AC position band and nonzeros left, then every histogram of the kind) so that
// contexts the synthetic content never reaches still get a sensible shape. Cached: the fuzz
// harness and tests make many tables.
const std::vector<std::array<double, kTokens>>& prior_probabilities(const DctSettings& s) {
  static std::mutex mutex;
  static std::map<std::tuple<int, int, int>, std::vector<std::array<double, kTokens>>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto key = std::make_tuple(s.quality, s.channels, int(s.layout));
  if (auto it = cache.find(key); it != cache.end()) return it->second;

  const int n = plane_count(s);
  uint8_t quant[4][64];
  const uint8_t* qp[4] = {quant[0], quant[1], quant[2], quant[3]};
  for (int p = 0; p < n; p++) make_quant(s, p, quant[p]);
  TokenCounts counts(size_t(n) * kHistPerPlane, std::array<uint32_t, kTokens>{});
  constexpr int kSize = 128, kPages = 4;
  for (int i = 0; i < kPages; i++) {
    const std::vector<uint8_t> page =
        synthetic_page(kSize, s.channels, uint32_t(i + 1), i == kPages - 1);
    count_tokens(s, qp, page.data(), kSize, kSize, counts);
  }
  auto normalised = [](const std::array<double, kTokens>& w) {
    double total = 0;
    for (double v : w) total += v;
    std::array<double, kTokens> out{};
    for (int t = 0; t < kTokens; t++) out[t] = total > 0 ? w[t] / total : 1.0 / kTokens;
    return out;
  };
  std::vector<std::array<double, kTokens>> probs(counts.size());
  for (int p = 0; p < n; p++) {
    const auto* c = counts.data() + size_t(p) * kHistPerPlane;
    auto sum_range = [&](int from, int to, int step) {
      std::array<double, kTokens> w{};
      for (int i = from; i < to; i += step)
        for (int t = 0; t < kTokens; t++) w[t] += c[i][t];
      for (int t = 0; t < kTokens; t++) w[t] += 0.5;  // every token stays possible
      return normalised(w);
    };
    const auto nz_all = sum_range(kNzHist, kDcHist, 1);
    const auto dc_all = sum_range(kDcHist, kPairHist, 1);
    const auto pair_all = sum_range(kPairHist, kEscHist, 1);
    const auto esc_all = sum_range(kEscHist, kHistPerPlane, 1);
    for (int i = 0; i < kHistPerPlane; i++) {
      std::array<double, kTokens> parent;
      if (i < kDcHist) {
        parent = nz_all;
      } else if (i < kPairHist) {
        parent = dc_all;
      } else {
        // The same band (and nonzeros left) over every neighbour bucket.
        const int group = i - (i - kPairHist) % kNbCtx;
        const auto g = sum_range(group, group + kNbCtx, 1);
        const auto& all = i < kEscHist ? pair_all : esc_all;
        for (int t = 0; t < kTokens; t++) parent[t] = 0.8 * g[t] + 0.2 * all[t];
      }
      std::array<double, kTokens> w{};
      for (int t = 0; t < kTokens; t++) w[t] = c[i][t] + 4.0 * parent[t];
      // A thin uniform tail keeps content far from the synthetic pages (noise at high
      // quality) from costing more than a few bits per token.
      w = normalised(w);
      for (int t = 0; t < kTokens; t++) w[t] = 0.97 * w[t] + 0.03 / kTokens;
      probs[size_t(p) * kHistPerPlane + i] = w;
    }
  }
  return cache.emplace(key, std::move(probs)).first->second;
}

// Counts the tokens of a page. With `bits` (per plane, kHistPerPlane * kTokens each), the levels
// go through the rate-distortion pass with those costs, as the encoder's will.
void count_tokens(const DctSettings& s, const uint8_t* const quant[4], const uint8_t* texels,
                  int width, int height, TokenCounts& counts, const float* bits) {
  FloatPlane planes[4];
  build_planes(s, texels, width, height, planes);
  std::vector<int16_t> coefs;
  std::vector<BlockInfo> info;
  for (int p = 0; p < plane_count(s); p++) {
    const PlaneDims& d = planes[p].dims;
    coefs.assign(size_t(d.bw) * d.bh * 64, 0);
    info.assign(size_t(d.bw) * d.bh, BlockInfo{});
    plane_levels(s, planes[p], p, quant[0][0], quant[p],
                 bits ? bits + size_t(p) * kHistPerPlane * kTokens : nullptr, coefs.data(),
                 info.data());
    TokenCounter counter(counts.data() + size_t(p) * kHistPerPlane);
    code_plane(counter, nullptr, d.bw, d.bh, coefs.data(), info.data());
  }
}

// ---- decoder side: integer-exact ----

struct DecodeScratch {
  std::vector<uint8_t> rans;  // the page's rANS bytes and RansDecoder::kPadding zeros
  std::vector<uint8_t> raw;   // its raw bits and BitReader::kPadding zeros
  std::vector<TokenModel> models;
  std::vector<int16_t> coefs;
  std::vector<BlockInfo> info;
  std::vector<int16_t> samples[4];
};

template <bool kAdaptive>
unsigned decode_token(RansDecoder& rans, TokenModel& m) {
  const unsigned t = rans.get(m);
  if constexpr (kAdaptive) dct_detail::adapt(m, t);
  return t;
}

template <bool kAdaptive>
int decode_uint(RansDecoder& rans, BitReader& bits, TokenModel& m) {
  const int t = decode_token<kAdaptive>(rans, m);
  return kUintBase[t] + int(bits.take(kUintExtra[t], (1u << kUintExtra[t]) - 1));
}

inline void zero_block(int16_t* z) {
#if defined(__SSE2__)
  // Eight stores; a memset call here costs more than the block's tokens when they are few.
  for (int i = 0; i < 64; i += 8)
    _mm_storeu_si128(reinterpret_cast<__m128i*>(z + i), _mm_setzero_si128());
#else
  std::memset(z, 0, 64 * sizeof(int16_t));
#endif
}

// Decodes one plane's blocks into `coefs`: code_plane's mirror, written out for speed (states
// in registers, no branch per position) with the same context helpers. False when the rANS
// data ran out.
template <bool kAdaptive>
[[gnu::always_inline]] inline bool decode_plane_body(RansDecoder& rans_state, BitReader& bits_state,
                                                     TokenModel* models, int bw, int bh,
                                                     int16_t* coefs, BlockInfo* info) {
  // Local copies stay in registers.
  RansDecoder rans = rans_state;
  BitReader bits = bits_state;
  for (int by = 0; by < bh; by++) {
    for (int bx = 0; bx < bw; bx++) {
      const int index = by * bw + bx;
      int16_t* z = coefs + size_t(index) * 64;
      // A block reads at most 98 tokens and 100 raw bytes: within the padding when it starts
      // inside the data.
      if (rans.overran() || bits.overran()) return false;
      zero_block(z);  // the DC is written below
      const BlockNeighbours n = block_neighbours(z, info, bx, by, bw);
      bits.refill();  // enough for both values and the sign
      const int nz = std::min(decode_uint<kAdaptive>(rans, bits, models[kNzHist + n.nz_ctx]), 63);
      int res = decode_uint<kAdaptive>(rans, bits, models[kDcHist + n.dc_ctx]);
      // Signs without a branch: they are coin flips to a predictor.
      const int dc_negative = -int(bits.take(res != 0, res != 0));
      res = (res ^ dc_negative) - dc_negative;
      z[0] = int16_t(std::clamp(n.dc_pred + res, -kMaxQuantized, kMaxQuantized));
      // Models for the first eight pairs up front: most blocks end within them, and a
      // data-dependent "next four pairs?" branch would mispredict. Pair j's model is its
      // neighbour part (pair_ctx, off the token chain) plus the nonzeros-left term after token
      // j - 2 (the first two take the block's count), kept in registers: a token's model
      // address waits on the token two back through a shift, a subtraction and one load only.
      uint16_t pair_ctx[kPairs], esc_ctx[kPairs];
      if (nz > 0) {
        pair_contexts(n.left, n.up, 0, sizeof(TokenModel), pair_ctx, esc_ctx);
        pair_contexts(n.left, n.up, 4, sizeof(TokenModel), pair_ctx + 4, esc_ctx + 4);
      }
      // Bit k - 1 set: position k has an escape. A mask rather than a list: two operations a
      // pair instead of six (the pair loop is as much bound by its integer operations as by its
      // token chain).
      uint64_t escapes = 0;
      int rem = nz, j = 0;
      size_t rem_now = kBuckets.rem_bytes[nz], rem_next = rem_now;  // pairs j and j + 1
      for (; rem > 0 && j < kPairs; j++) {
        // The next four two pairs ahead: at j = 6, 10, ..., 26.
        if ((0x4444440u >> j) & 1) {
          pair_contexts(n.left, n.up, j + 2, sizeof(TokenModel), pair_ctx + j + 2, esc_ctx + j + 2);
        }
        TokenModel& m =
            *reinterpret_cast<TokenModel*>(reinterpret_cast<char*>(models) + pair_ctx[j] + rem_now);
        const unsigned t = decode_token<kAdaptive>(rans, m);
        const PairToken& e = kBuckets.pair_token[t];
        // A refill gives 56 bits: enough for 16 pairs' signs.
        if ((j & 15) == 0) bits.refill();
        const uint32_t signs = bits.take(e.nonzeros, e.mask);
        const uint32_t pair = kBuckets.pair_value[t][signs];  // an escape as +-3 for now
        // Position 64 of the last pair is the next block's DC, written before it is decoded
        // (the coefficients have a block of slack at the end).
        std::memcpy(z + 2 * j + 1, &pair, sizeof(pair));
        escapes |= uint64_t(e.escapes) << (2 * j);
        // rem < 0 only in damaged data, and then the loop ends.
        rem -= e.nonzeros;
        rem_now = rem_next;
        rem_next = kBuckets.rem_bytes[rem & 63];
      }
      // The escapes follow the block's pairs (see code_plane): each adds to a magnitude of 3.
      for (; escapes != 0; escapes &= escapes - 1) {
        const int k = __builtin_ctzll(escapes) + 1;
        bits.refill();
        const int v = decode_uint<kAdaptive>(rans, bits, models[esc_ctx[(k - 1) >> 1]]);
        const int negative = z[k] >> 15;  // the +-3 written by the pair loop
        z[k] = int16_t(z[k] + ((v ^ negative) - negative));
      }
      // A valid block's last pair holds its last nonzero.
      info[index] = {z[0], uint8_t(nz), uint8_t(std::min(2 * j, 63))};
    }
  }
  rans_state = rans;
  bits_state = bits;
  return true;
}

// decode_plane_body built for the baseline target and, on x86-64 hosts that have them, for AVX2
// and BMI2: three-operand SIMD, a one-instruction broadcast and shifts by any register take a
// few operations off each token (about 2% of the decode, docs/BENCHMARKS.md issue 22). Both
// builds decode the same tokens (Dct.BaselineAndAvx2PlaneDecodersAgree).
template <bool kAdaptive>
[[gnu::noinline]] bool decode_plane_baseline(RansDecoder& rans, BitReader& bits, TokenModel* models,
                                             int bw, int bh, int16_t* coefs, BlockInfo* info) {
  return decode_plane_body<kAdaptive>(rans, bits, models, bw, bh, coefs, info);
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
template <bool kAdaptive>
[[gnu::noinline, gnu::target("avx2,bmi,bmi2")]] bool decode_plane_avx2(RansDecoder& rans,
                                                                       BitReader& bits,
                                                                       TokenModel* models, int bw,
                                                                       int bh, int16_t* coefs,
                                                                       BlockInfo* info) {
  return decode_plane_body<kAdaptive>(rans, bits, models, bw, bh, coefs, info);
}

bool host_has_avx2_bmi2() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("bmi2");
}
#endif

std::atomic<bool> g_force_baseline_plane_decoder{false};

bool avx2_plane_decoder() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  static const bool avx2 = host_has_avx2_bmi2();
  return avx2;
#else
  return false;
#endif
}

template <bool kAdaptive>
bool decode_plane(RansDecoder& rans, BitReader& bits, TokenModel* models, int bw, int bh,
                  int16_t* coefs, BlockInfo* info) {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  if (avx2_plane_decoder() && !g_force_baseline_plane_decoder.load(std::memory_order_relaxed))
    return decode_plane_avx2<kAdaptive>(rans, bits, models, bw, bh, coefs, info);
#endif
  return decode_plane_baseline<kAdaptive>(rans, bits, models, bw, bh, coefs, info);
}

void set_dequantisation(DctTables& t, int p) {
  for (int k = 0; k < 64; k++) {
    const int step = t.quant[p][kZigzag[k]];
    t.dequant_step[p][k] = int16_t(step);
    t.dequant_limit[p][k] = int16_t((kMaxDequantized + step - 1) / step);
  }
}

// Dequantised coefficients of one block, natural order, into f (zeroed): clamp(z[k] * step,
// +-kMaxDequantized) for k <= last.
inline void dequantise_block(const int16_t* z, int last, const int16_t* step, const int16_t* limit,
                             int16_t* f) {
  alignas(16) int16_t dq[64];
#if defined(__SSE2__)
  const __m128i max = _mm_set1_epi16(kMaxDequantized), min = _mm_set1_epi16(-kMaxDequantized);
  for (int k = 0; k <= last; k += 8) {
    const __m128i lim = _mm_load_si128(reinterpret_cast<const __m128i*>(limit + k));
    __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(z + k));
    v = _mm_min_epi16(_mm_max_epi16(v, _mm_sub_epi16(_mm_setzero_si128(), lim)), lim);
    v = _mm_mullo_epi16(v, _mm_load_si128(reinterpret_cast<const __m128i*>(step + k)));
    _mm_store_si128(reinterpret_cast<__m128i*>(dq + k), _mm_min_epi16(_mm_max_epi16(v, min), max));
  }
#else
  for (int k = 0; k < ((last + 8) & ~7); k++) {
    const int v = std::clamp(int(z[k]), -int(limit[k]), int(limit[k])) * step[k];
    dq[k] = int16_t(std::clamp(v, -kMaxDequantized, kMaxDequantized));
  }
#endif
  // Whole groups of eight: dq is zero past `last`, and f is zeroed.
  for (int k = 0; k <= last; k += 8) {
    for (int i = 0; i < 8; i++) f[kZigzag[k + i]] = dq[k + i];
  }
}

void reconstruct_plane(const PlaneDims& d, const DctTables& t, int p, const int16_t* coefs,
                       const BlockInfo* info, int16_t* samples) {
  const uint8_t* quant = t.quant[p];
  for (int by = 0; by < d.bh; by++) {
    for (int bx = 0; bx < d.bw; bx++) {
      const int16_t* z = coefs + (size_t(by) * d.bw + bx) * 64;
      int16_t* out = samples + size_t(by) * 8 * d.w + bx * 8;
      const int last = info[size_t(by) * d.bw + bx].last;
      if (last == 0) {
        idct_dc_block(std::clamp(int(z[0]) * quant[0], -kMaxDequantized, kMaxDequantized), out,
                      d.w);
        continue;
      }
      alignas(32) int16_t f[64];
      zero_block(f);
      dequantise_block(z, last, t.dequant_step[p], t.dequant_limit[p], f);
      idct_block(f, kBuckets.max_row[last] + 1, kBuckets.max_col[last] + 1, out, d.w);
    }
  }
}

uint8_t mode_byte(const DctPageMode& m) {
  return uint8_t((m.full_chroma ? 1 : 0) | (m.finer << 1));
}

// The tables of every page mode: the same token models, full-resolution chroma and/or quantiser
// steps divided by 2^finer (at least 1).
void make_variants(DctTables& t) {
  if (t.version < 4) return;
  for (int m = 1; m < kDctPageModes; m++) {
    const bool full_chroma = m & 1;
    const int finer = m >> 1;
    if (full_chroma && t.settings.layout != DctPlaneLayout::kYCoCg420) continue;
    auto v = std::make_unique<DctTables>();
    v->settings = t.settings;
    if (full_chroma) v->settings.layout = DctPlaneLayout::kYCoCg;
    v->width = t.width;
    v->height = t.height;
    v->adaptive = t.adaptive;
    v->version = t.version;
    for (int p = 0; p < plane_count(t.settings); p++) {
      for (int i = 0; i < 64; i++)
        v->quant[p][i] = uint8_t(std::max(1, (t.quant[p][i] + (1 << finer) / 2) >> finer));
      set_dequantisation(*v, p);
      v->models[p] = t.models[p];
      v->token_bits[p] = t.token_bits[p];
    }
    t.variant[size_t(m)] = std::move(v);
  }
}

Status corrupt_page(size_t size, const char* what) {
  return Error(ErrorCode::kCorrupt,
               std::string("dct page: ") + what + " (" + std::to_string(size) + " bytes)");
}

// Plane p's models for coding one page: adaptive ones are copied into `models` (they change as
// tokens go by); static ones are the tables' own, never written.
template <bool kAdaptive>
TokenModel* plane_models(const DctTables& t, int p, std::vector<TokenModel>& models) {
  if constexpr (kAdaptive) {
    models = t.models[p];
    return models.data();
  }
  return const_cast<TokenModel*>(t.models[p].data());
}

// Appends a coded page's length field, rANS part and raw bits.
template <bool kAdaptive>
void encode_tokens(const DctTables& t, const FloatPlane* planes, std::vector<uint8_t>& out) {
  // Per thread, so that a page costs no allocations; finish() leaves the encoder empty.
  thread_local TokenEncoder<kAdaptive> enc;
  thread_local std::vector<TokenModel> models;
  thread_local std::vector<int16_t> coefs;   // every element written by quantize_plane
  thread_local std::vector<BlockInfo> info;  // and by code_plane before it is read
  for (int p = 0; p < plane_count(t.settings); p++) {
    const PlaneDims& d = planes[p].dims;
    coefs.resize(size_t(d.bw) * d.bh * 64);
    info.resize(size_t(d.bw) * d.bh);
    plane_levels(t.settings, planes[p], p, t.quant[0][0], t.quant[p], t.token_bits[p].data(),
                 coefs.data(), info.data());
    code_plane(enc, plane_models<kAdaptive>(t, p, models), d.bw, d.bh, coefs.data(), info.data());
  }
  std::vector<uint8_t> rans;
  enc.rans.finish(rans);
  for (size_t v = rans.size();; v >>= 7) {
    out.push_back(uint8_t((v & 0x7F) | (v >= 0x80 ? 0x80 : 0)));
    if (v < 0x80) break;
  }
  out.insert(out.end(), rans.begin(), rans.end());
  enc.bits.finish(out);
}

// `bytes` followed by `padding` zeros, in `buffer`.
const uint8_t* padded_copy(std::span<const uint8_t> bytes, size_t padding,
                           std::vector<uint8_t>& buffer) {
  buffer.resize(bytes.size() + padding);
  if (!bytes.empty()) std::memcpy(buffer.data(), bytes.data(), bytes.size());
  std::memset(buffer.data() + bytes.size(), 0, padding);
  return buffer.data();
}

// Decodes every plane's tokens and reconstructs its samples into scratch.samples.
template <bool kAdaptive>
Status decode_tokens(const DctTables& t, std::span<const uint8_t> rans,
                     std::span<const uint8_t> raw, int width, int height, DecodeScratch& scratch) {
  const size_t size = 1 + rans.size() + raw.size();
  if (rans.size() < 8) return corrupt_page(size, "data cut short");
  RansDecoder rans_dec(padded_copy(rans, RansDecoder::kPadding, scratch.rans), rans.size());
  BitReader bits(padded_copy(raw, BitReader::kPadding, scratch.raw), raw.size());
  for (int p = 0; p < plane_count(t.settings); p++) {
    const PlaneDims d = plane_dims(t.settings, p, width, height);
    const size_t blocks = size_t(d.bw) * d.bh;
    scratch.coefs.resize((blocks + 1) * 64);
    scratch.info.resize(blocks);
    scratch.samples[p].resize(size_t(d.w) * d.h);
    if (!decode_plane<kAdaptive>(rans_dec, bits, plane_models<kAdaptive>(t, p, scratch.models),
                                 d.bw, d.bh, scratch.coefs.data(), scratch.info.data())) {
      return corrupt_page(size, "data ends early");
    }
    reconstruct_plane(d, t, p, scratch.coefs.data(), scratch.info.data(),
                      scratch.samples[p].data());
  }
  if (!rans_dec.valid_end() || !bits.valid_end())
    return corrupt_page(size, "data cut short, damaged or over-long");
  return Status::Ok();
}

}  // namespace

bool dct_detail::plane_decoder_uses_avx2() {
  return avx2_plane_decoder() && !g_force_baseline_plane_decoder.load();
}

void dct_detail::force_baseline_plane_decoder(bool on) {
  g_force_baseline_plane_decoder.store(on);
}

Expected<DctTablesPtr> dct_make_tables(const DctSettings& settings, int width, int height,
                                       std::span<const std::span<const uint8_t>> training_pages) {
  VT_RETURN_IF_ERROR(check_settings(settings));
  VT_RETURN_IF_ERROR(check_size(width, height));
  DctTablesPtr t(new DctTables);
  t->settings = settings;
  t->width = width;
  t->height = height;
  const int n = plane_count(settings);
  const uint8_t* quant[4] = {t->quant[0], t->quant[1], t->quant[2], t->quant[3]};
  for (int p = 0; p < n; p++) {
    make_quant(settings, p, t->quant[p]);
    set_dequantisation(*t, p);
  }

  const size_t page_bytes = size_t(width) * height * settings.channels;
  TokenCounts counts(size_t(n) * kHistPerPlane, std::array<uint32_t, kTokens>{});
  const auto& prior = prior_probabilities(settings);
  // The training pages' levels as the encoder will choose them, priced by the prior.
  std::vector<float> prior_bits(prior.size() * kTokens);
  for (size_t i = 0; i < prior.size(); i++)
    for (int tk = 0; tk < kTokens; tk++)
      prior_bits[i * kTokens + size_t(tk)] = float(-std::log2(prior[i][size_t(tk)]));
  for (int p = 0; p < n; p++)
    price_pair_tokens(prior_bits.data() + size_t(p) * kHistPerPlane * kTokens);
  bool trained = false;
  for (size_t i = 0; i < training_pages.size(); i++) {
    if (training_pages[i].size() != page_bytes) {
      return Error(ErrorCode::kInvalidArgument,
                   "dct: training page " + std::to_string(i) + " has " +
                       std::to_string(training_pages[i].size()) + " bytes, expected " +
                       std::to_string(page_bytes));
    }
    const uint8_t* px = training_pages[i].data();
    bool constant = true;
    for (size_t j = settings.channels; j < page_bytes && constant; j++) {
      constant = px[j] == px[j % settings.channels];
    }
    if (!constant) count_tokens(settings, quant, px, width, height, counts, prior_bits.data());
    trained = trained || !constant;
  }
  t->adaptive = settings.adaptive || !trained;
  // Observed counts plus the prior worth a few observations: well-trained contexts start
  // settled on the content, rare ones from the prior's shape and adapt fast.
  constexpr double kPriorWeight = 8.0;
  for (int p = 0; p < n; p++) {
    t->models[p].resize(kHistPerPlane);
    for (int i = 0; i < kHistPerPlane; i++) {
      const size_t k = size_t(p) * kHistPerPlane + i;
      double w[kTokens];
      uint32_t observed = 0;
      for (int tk = 0; tk < kTokens; tk++) {
        w[tk] = counts[k][tk] + kPriorWeight * prior[k][tk];
        observed += counts[k][tk];
      }
      t->models[p][i] = make_model(w);
      t->models[p][i].seen() = uint16_t(std::min<uint32_t>(observed, dct_detail::kRateCap));
    }
  }
  for (int p = 0; p < plane_count(t->settings); p++) t->token_bits[p] = token_bits(t->models[p]);
  make_variants(*t);
  return t;
}

// Tables bytes: "VTDC", version, quality, channels, layout, width u16, height u16, mode (0
// static models, 1 adaptive), then per plane: 64 quantiser steps (natural order), then per token
// model its observation count (one byte, <= kRateCap) and 16 initial token frequencies, each minus
// one as LEB128 (1-2 bytes), summing to kFreqTotal.
std::vector<uint8_t> dct_serialize_tables(const DctTables& t) {
  std::vector<uint8_t> out(std::begin(kMagic), std::end(kMagic));
  out.push_back(t.version);
  out.push_back(uint8_t(t.settings.quality));
  out.push_back(uint8_t(t.settings.channels));
  out.push_back(uint8_t(t.settings.layout));
  out.push_back(uint8_t(t.width & 0xFF));
  out.push_back(uint8_t(t.width >> 8));
  out.push_back(uint8_t(t.height & 0xFF));
  out.push_back(uint8_t(t.height >> 8));
  out.push_back(t.adaptive ? 1 : 0);
  for (int p = 0; p < plane_count(t.settings); p++) {
    out.insert(out.end(), t.quant[p], t.quant[p] + 64);
    for (int i = 0; i < kHistPerPlane; i++) {
      const TokenModel& m = t.models[p][i];
      out.push_back(uint8_t(m.seen()));
      for (int tk = 0; tk < kTokens; tk++) {
        const unsigned v = m.above()[tk] - dct_detail::token_start(m, tk) - 1u;
        if (v < 0x80) {
          out.push_back(uint8_t(v));
        } else {
          out.push_back(uint8_t(0x80 | (v & 0x7F)));
          out.push_back(uint8_t(v >> 7));
        }
      }
    }
  }
  return out;
}

Expected<DctTablesPtr> dct_parse_tables(std::span<const uint8_t> bytes) {
  auto corrupt = [](const std::string& what) {
    return Error(ErrorCode::kCorrupt, "dct tables: " + what);
  };
  if (bytes.size() < 13)
    return corrupt("truncated header (" + std::to_string(bytes.size()) + " bytes)");
  if (std::memcmp(bytes.data(), kMagic, 4) != 0) return corrupt("bad magic");
  if (bytes[4] < kOldestTablesVersion || bytes[4] > kTablesVersion) {
    return Error(ErrorCode::kUnsupported,
                 "dct tables: version " + std::to_string(bytes[4]) + " (this build reads " +
                     std::to_string(kOldestTablesVersion) + " to " +
                     std::to_string(kTablesVersion) + "; a newer vtbake wrote this file)");
  }
  DctTablesPtr t(new DctTables);
  t->version = bytes[4];
  t->settings.quality = bytes[5];
  t->settings.channels = bytes[6];
  t->settings.layout = DctPlaneLayout(bytes[7]);
  t->width = bytes[8] | (bytes[9] << 8);
  t->height = bytes[10] | (bytes[11] << 8);
  if (Status s = check_settings(t->settings); !s.ok()) return corrupt(s.message());
  if (Status s = check_size(t->width, t->height); !s.ok()) return corrupt(s.message());
  if (bytes[12] > 1) return corrupt("bad model mode " + std::to_string(bytes[12]));
  t->adaptive = bytes[12] == 1;
  t->settings.adaptive = t->adaptive;
  size_t pos = 13;
  for (int p = 0; p < plane_count(t->settings); p++) {
    if (bytes.size() - pos < 64) return corrupt("truncated quantiser table");
    for (int i = 0; i < 64; i++) {
      t->quant[p][i] = bytes[pos++];
      if (t->quant[p][i] == 0) return corrupt("zero quantiser step");
    }
    set_dequantisation(*t, p);
    t->models[p].resize(kHistPerPlane);
    for (int i = 0; i < kHistPerPlane; i++) {
      TokenModel& m = t->models[p][i];
      if (pos >= bytes.size()) return corrupt("truncated token models");
      m.seen() = bytes[pos++];
      if (m.seen() > dct_detail::kRateCap) return corrupt("bad observation count");
      uint32_t start = 0;
      for (int tk = 0; tk < kTokens; tk++) {
        if (pos >= bytes.size()) return corrupt("truncated token frequencies");
        uint32_t v = bytes[pos++];
        if (v & 0x80) {
          if (pos >= bytes.size()) return corrupt("truncated token frequencies");
          if (bytes[pos] == 0 || bytes[pos] >= (kFreqTotal >> 7)) {
            return corrupt("bad token frequency");
          }
          v = (v & 0x7F) | (uint32_t(bytes[pos++]) << 7);
        }
        start += v + 1;
        m.above()[tk] = uint16_t(std::min(start, kFreqTotal));
      }
      if (start != kFreqTotal) {
        return corrupt("token frequencies do not sum to " + std::to_string(kFreqTotal));
      }
    }
  }
  if (pos != bytes.size()) {
    return corrupt(std::to_string(bytes.size() - pos) + " trailing bytes");
  }
  for (int p = 0; p < plane_count(t->settings); p++) t->token_bits[p] = token_bits(t->models[p]);
  make_variants(*t);
  return t;
}

Status dct_encode_page(const DctTables& tables, const uint8_t* texels, int width, int height,
                       std::vector<uint8_t>& out, DctPageMode mode) {
  VT_RETURN_IF_ERROR(check_size(width, height));
  if (texels == nullptr) return Error(ErrorCode::kInvalidArgument, "dct: null texels");
  if (!dct_mode_applies(tables, mode))
    return Error(ErrorCode::kInvalidArgument,
                 "dct: page mode (full chroma " + std::to_string(mode.full_chroma) + ", finer " +
                     std::to_string(mode.finer) + ") does not apply to these tables");
  const uint8_t m = mode_byte(mode);
  const DctTables& t = m == 0 ? tables : *tables.variant[m];
  const DctSettings& s = tables.settings;
  out.clear();
  // A page of one colour is flagged and its texel stored raw, so it decodes exactly.
  const size_t texel_count = size_t(width) * height;
  const int ch = s.channels;
  bool constant = true;
  for (size_t i = 1; i < texel_count && constant; i++) {
    constant = std::memcmp(texels, texels + i * ch, size_t(ch)) == 0;
  }
  if (constant) {
    out.push_back(kPageConstant);
    out.insert(out.end(), texels, texels + ch);
    return Status::Ok();
  }
  FloatPlane planes[4];
  build_planes(t.settings, texels, width, height, planes);
  if (m == 0) {
    out.push_back(kPageCoded);
  } else {
    out.push_back(kPageCodedMode);
    out.push_back(m);
  }
  if (t.adaptive) {
    encode_tokens<true>(t, planes, out);
  } else {
    encode_tokens<false>(t, planes, out);
  }
  const size_t raw_bytes = texel_count * size_t(ch);
  if (out.size() > raw_bytes) {
    out.assign(1, kPageStored);
    out.insert(out.end(), texels, texels + raw_bytes);
  }
  return Status::Ok();
}

bool dct_mode_applies(const DctTables& tables, DctPageMode mode) {
  const uint8_t m = mode_byte(mode);
  return mode.finer <= kDctMaxFiner && (m == 0 || tables.variant[m] != nullptr);
}

int dct_base_step(const DctTables& tables) {
  return tables.quant[0][0];
}

double dct_layer_slope(const DctTables& tables) {
  return layer_slope(tables.quant[0][0]);
}

int dct_tables_version(const DctTables& tables) {
  return tables.version;
}

Status dct_decode_page(const DctTables& tables, std::span<const uint8_t> data, int width,
                       int height, uint8_t* texels) {
  VT_RETURN_IF_ERROR(check_size(width, height));
  if (texels == nullptr) return Error(ErrorCode::kInvalidArgument, "dct: null texels");
  const size_t bytes = size_t(width) * size_t(height) * size_t(tables.settings.channels);
  return dct_decode_page(tables, data, width, height, std::span<uint8_t>(texels, bytes));
}

Status dct_decode_page(const DctTables& tables, std::span<const uint8_t> data, int width,
                       int height, std::span<uint8_t> out) {
  VT_RETURN_IF_ERROR(check_size(width, height));
  const DctSettings& s = tables.settings;
  const size_t texel_bytes = size_t(width) * size_t(height) * size_t(s.channels);
  if (out.size() != texel_bytes)
    return Error(ErrorCode::kInvalidArgument,
                 "dct: output of " + std::to_string(out.size()) + " bytes, the tables decode " +
                     std::to_string(s.channels) + " channels of " + std::to_string(width) + "x" +
                     std::to_string(height) + " (" + std::to_string(texel_bytes) + " bytes)");
  uint8_t* const texels = out.data();
  const int n = plane_count(s);
  const int ch = s.channels;
  if (data.empty()) return corrupt_page(0, "empty");
  if (data[0] == kPageConstant) {
    if (data.size() != size_t(1 + ch)) return corrupt_page(data.size(), "bad constant page");
    const size_t count = size_t(width) * height;
    for (size_t i = 0; i < count; i++) std::memcpy(texels + i * ch, data.data() + 1, size_t(ch));
    return Status::Ok();
  }
  if (data[0] == kPageStored) {
    const size_t raw_bytes = size_t(width) * height * ch;
    if (data.size() != 1 + raw_bytes) return corrupt_page(data.size(), "bad stored page");
    std::memcpy(texels, data.data() + 1, raw_bytes);
    return Status::Ok();
  }
  size_t pos = 1, rans_size = 0;
  const DctTables* coded = &tables;
  if (data[0] == kPageCodedMode && tables.version >= 4) {
    if (data.size() < 2 || data[1] >= kDctPageModes || data[1] == 0 || !tables.variant[data[1]])
      return corrupt_page(data.size(), "bad page mode");
    coded = tables.variant[data[1]].get();
    pos = 2;
  } else if (data[0] == kDctPageLossless && tables.version >= 4) {
    return corrupt_page(data.size(), "lossless page: the layer codec decodes it (zstd)");
  } else if (data[0] != kPageCoded) {
    return corrupt_page(data.size(), "unknown page kind");
  }
  for (int shift = 0;; shift += 7) {
    if (pos >= data.size() || shift > 28) return corrupt_page(data.size(), "bad length field");
    const uint8_t b = data[pos++];
    rans_size |= size_t(b & 0x7F) << shift;
    if (!(b & 0x80)) break;
  }
  if (rans_size > data.size() - pos) return corrupt_page(data.size(), "data cut short");
  thread_local DecodeScratch scratch;
  const std::span<const uint8_t> rans = data.subspan(pos, rans_size);
  const std::span<const uint8_t> raw = data.subspan(pos + rans_size);
  VT_RETURN_IF_ERROR(coded->adaptive
                         ? decode_tokens<true>(*coded, rans, raw, width, height, scratch)
                         : decode_tokens<false>(*coded, rans, raw, width, height, scratch));

  const DctSettings& cs = coded->settings;
  if (cs.layout == DctPlaneLayout::kPlanes) {
    for (int p = 0; p < n; p++) {
      plane_to_channel(scratch.samples[p].data(), plane_dims(cs, p, width, height).w, width, height,
                       ch, p, texels);
    }
    return Status::Ok();
  }
  const int16_t* yp = scratch.samples[0].data();
  const int ystride = plane_dims(cs, 0, width, height).w;
  const int16_t* co = scratch.samples[1].data();
  const int16_t* cg = scratch.samples[2].data();
  const int cstride = plane_dims(cs, 1, width, height).w;
  if (cs.layout == DctPlaneLayout::kYCoCg420) {
    ycocg420_to_rgb(yp, ystride, co, cg, cstride, width, height, ch, texels);
  } else {
    ycocg_to_rgb(yp, ystride, co, cg, cstride, width, height, ch, texels);
  }
  if (ch == 4) {
    plane_to_channel(scratch.samples[3].data(), plane_dims(cs, 3, width, height).w, width, height,
                     4, 3, texels);
  }
  return Status::Ok();
}

}  // namespace vt
