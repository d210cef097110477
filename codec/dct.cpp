// The page DCT codec (see dct.h). Bitstream of a page: one range-coded stream, no header. For
// every plane in order (Y, Co, Cg, alpha or channel 0..3), blocks in raster order; each block
// codes its AC nonzero count (Exp-Golomb-like bins, context: neighbours' counts), its DC as a
// residual from a median predictor (context: neighbours' DC difference), then the AC coefficients
// in zigzag order: a zero flag per position while nonzeros remain (context: position, nonzeros
// left, neighbours' magnitude at that position), an Exp-Golomb-like magnitude with adaptive
// exponent bins, then its low bits and sign raw. Context probabilities start from the per-layer
// tables.
#include "codec/dct.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "codec/dct_range_coder.h"

namespace vt {

using dct_detail::BinCounter;
using dct_detail::BitModel;
using dct_detail::RangeDecoder;
using dct_detail::RangeEncoder;

namespace {

constexpr int kMaxPageSize = 4096;
constexpr int kMaxExp = 12;  // magnitudes below 2^12
constexpr int kMaxQuantized = 4095;
constexpr int kMaxDequantized = 2047;  // far beyond any 8-bit block's coefficients

constexpr uint8_t kZigzag[64] = {0,  1,  8,  16, 9,  2,  3,  10, 17, 24, 32, 25, 18, 11, 4,  5,
                                 12, 19, 26, 33, 40, 48, 41, 34, 27, 20, 13, 6,  7,  14, 21, 28,
                                 35, 42, 49, 56, 57, 50, 43, 36, 29, 22, 15, 23, 30, 37, 44, 51,
                                 58, 59, 52, 45, 38, 31, 39, 46, 53, 60, 61, 54, 47, 55, 62, 63};

// Orthonormal 8-point DCT basis B[x][u] in 1/4096, rounded once (hard-coded, not computed,
// so that no libm difference can change a decoded texel).
constexpr int16_t kIdctBasis[8][8] = {
    {1448, 2009, 1892, 1703, 1448, 1138, 784, 400},
    {1448, 1703, 784, -400, -1448, -2009, -1892, -1138},
    {1448, 1138, -784, -2009, -1448, 400, 1892, 1703},
    {1448, 400, -1892, -1138, 1448, 1703, -784, -2009},
    {1448, -400, -1892, 1138, 1448, -1703, -784, 2009},
    {1448, -1138, -784, 2009, -1448, -400, 1892, -1703},
    {1448, -1703, 784, 400, -1448, 2009, -1892, 1138},
    {1448, -2009, 1892, -1703, 1448, -1138, 784, -400},
};

struct TransposedBasis {
  int32_t b[8][8];  // b[u][x] = kIdctBasis[x][u], rows the second pass combines
  constexpr TransposedBasis() : b() {
    for (int u = 0; u < 8; u++)
      for (int x = 0; x < 8; x++) b[u][x] = kIdctBasis[x][u];
  }
};
constexpr TransposedBasis kIdctBasisT;

// Context layout of one plane's models (offsets into a flat BitModel array).
constexpr int kNzCtx = 11;                          // predicted AC count buckets + "no neighbour"
constexpr int kDcCtx = 8;                           // bit length of the neighbours' DC difference
constexpr int kRemCtx = 7;                          // nonzeros left
constexpr int kNbCtx = 6;                           // neighbours' magnitude at the same position
constexpr int kBandCtx = 6;                         // zigzag position bands
constexpr int kNzExpOff = 0;                        // [ctx][bit length 0..6]
constexpr int kNzMantOff = kNzExpOff + kNzCtx * 7;  // [ctx][bit length][bit]
constexpr int kDcZeroOff = kNzMantOff + kNzCtx * 7 * 5;
constexpr int kDcSignOff = kDcZeroOff + kDcCtx;
constexpr int kDcExpOff = kDcSignOff + kDcCtx;
constexpr int kDcMantOff = kDcExpOff + kDcCtx * kMaxExp;
constexpr int kAcZeroOff = kDcMantOff + kMaxExp;
constexpr int kAcExpOff = kAcZeroOff + 64 * kRemCtx * kNbCtx;
constexpr int kAcMantOff = kAcExpOff + kBandCtx * kNbCtx * kMaxExp;
constexpr int kConstOff = kAcMantOff + kBandCtx * kMaxExp;  // plane 0 only: constant page
constexpr int kModelsPerPlane = kConstOff + 1;

constexpr uint8_t kMagic[4] = {'V', 'T', 'D', 'C'};
// Raw bits closing every page: a cut or damaged stream decodes them wrong (odds 1 in 65536 of
// missing it), where the arithmetic decoder alone would just read zeros and carry on.
constexpr int kEndMarker = 0xA55A;
constexpr uint8_t kTablesVersion = 1;

struct BucketTables {
  uint8_t nz[64];
  uint8_t rem[64];
  uint8_t band[64];
  uint8_t nb[64];       // index: min(sum of neighbour magnitudes, 63)
  uint8_t max_row[64];  // largest row / column among zigzag positions 0..k
  uint8_t max_col[64];
  constexpr BucketTables() : nz(), rem(), band(), nb(), max_row(), max_col() {
    for (int i = 0; i < 64; i++) {
      nz[i] = i <= 3 ? i : i <= 5 ? 4 : i <= 7 ? 5 : i <= 11 ? 6 : i <= 17 ? 7 : i <= 27 ? 8 : 9;
      rem[i] = i <= 1 ? 0 : i <= 3 ? i - 1 : i <= 5 ? 3 : i <= 8 ? 4 : i <= 14 ? 5 : 6;
      band[i] = i <= 2 ? 0 : i <= 5 ? 1 : i <= 9 ? 2 : i <= 14 ? 3 : i <= 27 ? 4 : 5;
      nb[i] = i <= 2 ? i : i <= 4 ? 3 : i <= 8 ? 4 : 5;
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

int bit_length(unsigned v) {
  return v == 0 ? 0 : 32 - __builtin_clz(v);
}

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
  std::vector<BitModel> models[4];  // initial context state per plane
};

void DctTablesDeleter::operator()(DctTables* t) const {
  delete t;
}

namespace {

// Per-block side information the neighbours' contexts read.
struct BlockInfo {
  int16_t dc;
  uint8_t nz;
  uint8_t last;  // zigzag index of the last nonzero coefficient, 0 when only DC
};

// Codes one plane's blocks. Encoding reads `coefs` (quantised, zigzag order, one block after
// another); decoding writes them. One template so both sides select contexts identically.
template <class Coder>
void code_plane(Coder& c, BitModel* m, int bw, int bh, int16_t* coefs, BlockInfo* info) {
  for (int by = 0; by < bh; by++) {
    for (int bx = 0; bx < bw; bx++) {
      const int index = by * bw + bx;
      int16_t* z = coefs + size_t(index) * 64;
      const bool has_left = bx > 0, has_up = by > 0;
      const int16_t* left = has_left ? z - 64 : nullptr;
      const int16_t* up = has_up ? z - size_t(bw) * 64 : nullptr;
      if (!left) left = up;
      if (!up) up = left;

      // AC nonzero count.
      int nz = 0;
      if constexpr (!Coder::kDecoding) {
        for (int k = 1; k < 64; k++) nz += z[k] != 0;
      }
      int nz_ctx = kNzCtx - 1;
      if (has_left || has_up) {
        const int a = has_left ? info[index - 1].nz : info[index - bw].nz;
        const int b = has_up ? info[index - bw].nz : a;
        nz_ctx = kBuckets.nz[(a + b + 1) >> 1];
      }
      {
        // Bit length of the count in unary, then the bits below its top bit.
        BitModel* exp = m + kNzExpOff + nz_ctx * 7;
        int e = 0;
        if constexpr (Coder::kDecoding) {
          while (e < 6 && c.bit(exp[e])) e++;
        } else {
          e = bit_length(unsigned(nz));
          for (int i = 0; i < e; i++) c.bit(exp[i], 1);
          if (e < 6) c.bit(exp[e], 0);
        }
        if (e > 1) {
          BitModel* mant = m + kNzMantOff + (nz_ctx * 7 + e) * 5;
          int v = 1;
          for (int i = e - 2; i >= 0; i--) v = v * 2 + c.bit(mant[i], (nz >> i) & 1);
          nz = v;
        } else {
          nz = e;
        }
      }

      // DC: residual from a median (LOCO-I) predictor.
      int pred = 0, dc_ctx = 0;
      if (has_left && has_up) {
        const int l = info[index - 1].dc, a = info[index - bw].dc;
        const int al = info[index - bw - 1].dc;
        pred = std::clamp(l + a - al, std::min(l, a), std::max(l, a));
        dc_ctx = std::min(bit_length(unsigned(std::abs(l - a))), kDcCtx - 1);
      } else if (has_left) {
        pred = info[index - 1].dc;
      } else if (has_up) {
        pred = info[index - bw].dc;
      }
      {
        int res = 0;
        if constexpr (!Coder::kDecoding) res = z[0] - pred;
        if (c.bit(m[kDcZeroOff + dc_ctx], res != 0)) {
          const int neg = c.bit(m[kDcSignOff + dc_ctx], res < 0);
          int mag = std::abs(res);
          BitModel* exp = m + kDcExpOff + dc_ctx * kMaxExp;
          int e = 0;
          if constexpr (Coder::kDecoding) {
            while (e < kMaxExp - 1 && c.bit(exp[e])) e++;
          } else {
            e = bit_length(unsigned(mag)) - 1;
            for (int i = 0; i < e; i++) c.bit(exp[i], 1);
            if (e < kMaxExp - 1) c.bit(exp[e], 0);
          }
          if (e > 0) {
            const int hi = c.bit(m[kDcMantOff + e], (mag >> (e - 1)) & 1);
            const int lo = c.direct(mag & ((1 << (e - 1)) - 1), e - 1);
            mag = (((2 | hi) << (e - 1)) | lo);
          } else {
            mag = 1;
          }
          res = neg ? -mag : mag;
        } else {
          res = 0;
        }
        if constexpr (Coder::kDecoding) {
          z[0] = int16_t(std::clamp(pred + res, -kMaxQuantized, kMaxQuantized));
        }
      }

      // AC coefficients.
      if constexpr (Coder::kDecoding) std::memset(z + 1, 0, 63 * sizeof(int16_t));
      int rem = nz, last = 0;
      for (int k = 1; k < 64 && rem > 0; k++) {
        int nb_sum = 0;
        if (left) nb_sum = std::abs(left[k]) + std::abs(up[k]);
        const int nb = kBuckets.nb[std::min(nb_sum, 63)];
        int v = 0;
        if constexpr (!Coder::kDecoding) v = z[k];
        if (64 - k != rem) {
          BitModel& zm = m[kAcZeroOff + (k * kRemCtx + kBuckets.rem[rem]) * kNbCtx + nb];
          if (!c.bit(zm, v != 0)) continue;
        }
        rem--;
        last = k;
        int mag = std::abs(v);
        const int band = kBuckets.band[k];
        BitModel* exp = m + kAcExpOff + (band * kNbCtx + nb) * kMaxExp;
        int e = 0;
        if constexpr (Coder::kDecoding) {
          while (e < kMaxExp - 1 && c.bit(exp[e])) e++;
        } else {
          e = bit_length(unsigned(mag)) - 1;
          for (int i = 0; i < e; i++) c.bit(exp[i], 1);
          if (e < kMaxExp - 1) c.bit(exp[e], 0);
        }
        int neg;
        if (e > 0) {
          const int hi = c.bit(m[kAcMantOff + band * kMaxExp + e], (mag >> (e - 1)) & 1);
          // The bits below and the sign are equiprobable: one raw field.
          const int lo_sign = c.direct(((mag & ((1 << (e - 1)) - 1)) << 1) | (v < 0), e);
          mag = (((2 | hi) << (e - 1)) | (lo_sign >> 1));
          neg = lo_sign & 1;
        } else {
          mag = 1;
          neg = c.direct(v < 0, 1);
        }
        if constexpr (Coder::kDecoding) z[k] = int16_t(neg ? -mag : mag);
      }
      info[index].dc = z[0];
      info[index].nz = uint8_t(nz);
      info[index].last = uint8_t(last);
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
  for (int p = 0; p < n; p++) {
    planes[p].dims = plane_dims(s, p, width, height);
    planes[p].v.assign(size_t(planes[p].dims.w) * planes[p].dims.h, 0.0f);
  }
  auto at = [&](int x, int y, int c) { return float(texels[(size_t(y) * width + x) * ch + c]); };
  // Full-resolution values of plane p at (x, y) before any subsampling.
  auto full = [&](int p, int x, int y) -> float {
    if (s.layout == DctPlaneLayout::kPlanes || p == 3) return at(x, y, p) - 128.0f;
    const float r = at(x, y, 0), g = at(x, y, 1), b = at(x, y, 2);
    if (p == 0) return (r + 2 * g + b) * 0.25f - 128.0f;
    if (p == 1) return (r - b) * 0.5f;
    return (2 * g - r - b) * 0.25f;
  };
  for (int p = 0; p < n; p++) {
    FloatPlane& fp = planes[p];
    const bool half = plane_is_half(s, p);
    const int sw = half ? (width + 1) / 2 : width, sh = half ? (height + 1) / 2 : height;
    for (int y = 0; y < fp.dims.h; y++) {
      for (int x = 0; x < fp.dims.w; x++) {
        const int sx = std::min(x, sw - 1), sy = std::min(y, sh - 1);
        float value;
        if (half) {
          const int x0 = 2 * sx, y0 = 2 * sy;
          const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
          value = 0.25f * (full(p, x0, y0) + full(p, x1, y0) + full(p, x0, y1) + full(p, x1, y1));
        } else {
          value = full(p, sx, sy);
        }
        fp.v[size_t(y) * fp.dims.w + x] = value;
      }
    }
  }
}

struct ForwardBasis {
  double b[8][8];  // b[u][x]
  ForwardBasis() {
    for (int u = 0; u < 8; u++) {
      const double s = u == 0 ? std::sqrt(0.125) : 0.5;
      for (int x = 0; x < 8; x++) b[u][x] = s * std::cos((2 * x + 1) * u * M_PI / 16.0);
    }
  }
};

// Forward DCT and deadzone quantisation of every block of a plane into zigzag order.
void quantize_plane(const FloatPlane& fp, const uint8_t* quant, int16_t* coefs) {
  static const ForwardBasis basis;
  const PlaneDims& d = fp.dims;
  for (int by = 0; by < d.bh; by++) {
    for (int bx = 0; bx < d.bw; bx++) {
      double tmp[8][8];  // tmp[y][u]
      const float* src = fp.v.data() + size_t(by) * 8 * d.w + bx * 8;
      for (int y = 0; y < 8; y++) {
        for (int u = 0; u < 8; u++) {
          double acc = 0;
          for (int x = 0; x < 8; x++) acc += basis.b[u][x] * src[size_t(y) * d.w + x];
          tmp[y][u] = acc;
        }
      }
      int16_t* z = coefs + (size_t(by) * d.bw + bx) * 64;
      for (int k = 0; k < 64; k++) {
        const int pos = kZigzag[k], v = pos >> 3, u = pos & 7;
        double acc = 0;
        for (int y = 0; y < 8; y++) acc += basis.b[v][y] * tmp[y][u];
        // Rounding offset below 1/2 on AC: cheaper, and near MSE-optimal for Laplacian data.
        const double a = std::abs(acc) / quant[pos] + (k == 0 ? 0.5 : 0.36);
        const int mag = std::min(int(a), kMaxDequantized);
        z[k] = int16_t(acc < 0 ? -mag : mag);
      }
    }
  }
}

// ---- decoder side: integer-exact ----

// Inverse DCT of a dequantised block (natural order, |F| <= 2047) whose nonzeros lie in rows
// < nv and columns < nu. Output in 1/8 texel units, clamped to +-4095.
// Rounding is part of the format: pass 1 keeps 3 fractional bits ((x + 2^8) >> 9), pass 2
// rounds to 1/8 ((x + 2^11) >> 12). |F| <= 2^11 and |B| <= 2^11 keep every sum inside int32.
// NV and NU are compile-time bounds (2, 4 or 8) so the loops vectorise cleanly; the rows and
// columns beyond the last nonzero contribute zeros and are skipped exactly.
template <int NV, int NU>
inline void idct_block_n(const int32_t* f, int16_t* out, int stride) {
  int32_t tmp[8][8];
  for (int y = 0; y < 8; y++) {
    int32_t acc[8] = {};
    for (int v = 0; v < NV; v++) {
      const int32_t b = kIdctBasis[y][v];
      for (int u = 0; u < 8; u++) acc[u] += b * f[v * 8 + u];
    }
    for (int u = 0; u < 8; u++) tmp[y][u] = (acc[u] + 256) >> 9;
  }
  for (int y = 0; y < 8; y++) {
    int32_t acc[8] = {};
    for (int u = 0; u < NU; u++) {
      const int32_t t = tmp[y][u];
      for (int x = 0; x < 8; x++) acc[x] += t * kIdctBasisT.b[u][x];
    }
    for (int x = 0; x < 8; x++) {
      out[y * stride + x] = int16_t(std::clamp((acc[x] + 2048) >> 12, -4095, 4095));
    }
  }
}

#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
__attribute__((target_clones("avx2", "default"), flatten))
#endif
void idct_block(const int32_t* f, int nv, int nu, int16_t* out, int stride) {
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

// Decodes one plane into 1/8-unit samples. Returns false when the range decoder ran out of
// data (corrupt or truncated).
struct DecodeScratch {
  std::vector<int16_t> coefs;
  std::vector<BlockInfo> info;
  std::vector<int16_t> samples[4];
  std::vector<int32_t> row;
  std::vector<BitModel> models;
};

void reconstruct_plane(const PlaneDims& d, const uint8_t* quant, const int16_t* coefs,
                       const BlockInfo* info, int16_t* samples) {
  for (int by = 0; by < d.bh; by++) {
    for (int bx = 0; bx < d.bw; bx++) {
      const int16_t* z = coefs + (size_t(by) * d.bw + bx) * 64;
      int16_t* out = samples + size_t(by) * 8 * d.w + bx * 8;
      const int last = info[size_t(by) * d.bw + bx].last;
      int32_t f[64];
      if (last == 0) {
        // DC only: the same arithmetic as idct_block, without the loops.
        const int32_t dc = std::clamp(int32_t(z[0]) * quant[0], -kMaxDequantized, kMaxDequantized);
        const int32_t t = (kIdctBasis[0][0] * dc + 256) >> 9;
        const int16_t v = int16_t(std::clamp((t * kIdctBasis[0][0] + 2048) >> 12, -4095, 4095));
        for (int y = 0; y < 8; y++)
          for (int x = 0; x < 8; x++) out[y * d.w + x] = v;
        continue;
      }
      std::memset(f, 0, sizeof(f));
      for (int k = 0; k <= last; k++) {
        const int pos = kZigzag[k];
        f[pos] = std::clamp(int32_t(z[k]) * quant[pos], -kMaxDequantized, kMaxDequantized);
      }
      idct_block(f, kBuckets.max_row[last] + 1, kBuckets.max_col[last] + 1, out, d.w);
    }
  }
}

inline uint8_t to_u8(int v8) {
  return uint8_t(std::clamp((v8 + 4) >> 3, 0, 255));
}

inline void put_ycocg(uint8_t* o, int y8, int co8, int cg8) {
  const int yy = y8 + 1024, t = yy - cg8;
  o[0] = to_u8(t + co8);
  o[1] = to_u8(yy + cg8);
  o[2] = to_u8(t - co8);
}

// YCoCg with 4:2:0 chroma to interleaved RGB(A). Chroma comes back to full resolution with the
// 9-3-3-1 triangle filter (chroma sited at 2x2 centres, edges clamped), computed as a vertical
// 3:1 blend and then a horizontal 3:1 blend with one rounding, all in 1/8 units.
void ycocg420_to_rgb(const int16_t* yp, int ystride, const int16_t* co, const int16_t* cg,
                     int cstride, int width, int height, int ch, uint8_t* texels,
                     std::vector<int32_t>& rows) {
  const int cw = width / 2, chh = height / 2;
  rows.resize(size_t(cw) * 2);
  int32_t* vco = rows.data();
  int32_t* vcg = rows.data() + cw;
  for (int y = 0; y < height; y++) {
    const int cy = y >> 1;
    const int ny = std::clamp((y & 1) ? cy + 1 : cy - 1, 0, chh - 1);
    const int16_t* a0 = co + size_t(cy) * cstride;
    const int16_t* a1 = co + size_t(ny) * cstride;
    const int16_t* b0 = cg + size_t(cy) * cstride;
    const int16_t* b1 = cg + size_t(ny) * cstride;
    for (int x = 0; x < cw; x++) {
      vco[x] = 3 * a0[x] + a1[x];
      vcg[x] = 3 * b0[x] + b1[x];
    }
    const int16_t* yr = yp + size_t(y) * ystride;
    uint8_t* o = texels + size_t(y) * width * ch;
    for (int cx = 0; cx < cw; cx++) {
      const int l = cx > 0 ? cx - 1 : 0, r = cx + 1 < cw ? cx + 1 : cw - 1;
      const int co3 = 3 * vco[cx] + 8, cg3 = 3 * vcg[cx] + 8;
      put_ycocg(o + size_t(2 * cx) * ch, yr[2 * cx], (co3 + vco[l]) >> 4, (cg3 + vcg[l]) >> 4);
      put_ycocg(o + size_t(2 * cx + 1) * ch, yr[2 * cx + 1], (co3 + vco[r]) >> 4,
                (cg3 + vcg[r]) >> 4);
    }
  }
}

// A valid page ends with the marker, overreads at most 5 bytes (the zeros the encoder trimmed
// plus one) and leaves no byte unread.
Status check_end(RangeDecoder& dec, size_t size) {
  const int marker = dec.direct(0, 16);
  if (marker != kEndMarker || dec.overread() > 8) {
    return Error(ErrorCode::kCorrupt,
                 "dct page: data cut short or damaged (" + std::to_string(size) + " bytes)");
  }
  if (!dec.consumed_all()) {
    return Error(ErrorCode::kCorrupt, "dct page: trailing bytes after the page data");
  }
  return Status::Ok();
}

}  // namespace

Expected<DctTablesPtr> dct_make_tables(const DctSettings& settings, int width, int height,
                                       std::span<const std::span<const uint8_t>> training_pages) {
  VT_RETURN_IF_ERROR(check_settings(settings));
  VT_RETURN_IF_ERROR(check_size(width, height));
  DctTablesPtr t(new DctTables);
  t->settings = settings;
  t->width = width;
  t->height = height;
  const int n = plane_count(settings);
  for (int p = 0; p < n; p++) {
    make_quant(settings, p, t->quant[p]);
    t->models[p].assign(kModelsPerPlane, BitModel{});
  }
  if (training_pages.empty()) return t;

  const size_t page_bytes = size_t(width) * height * settings.channels;
  std::vector<uint32_t> counts[4];
  for (int p = 0; p < n; p++) counts[p].assign(size_t(kModelsPerPlane) * 2, 0);
  FloatPlane planes[4];
  std::vector<int16_t> coefs;
  std::vector<BlockInfo> info;
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
    counts[0][2 * kConstOff + (constant ? 1 : 0)]++;
    if (constant) continue;
    build_planes(settings, px, width, height, planes);
    for (int p = 0; p < n; p++) {
      const PlaneDims& d = planes[p].dims;
      coefs.assign(size_t(d.bw) * d.bh * 64, 0);
      info.assign(size_t(d.bw) * d.bh, BlockInfo{});
      quantize_plane(planes[p], t->quant[p], coefs.data());
      BinCounter counter(t->models[p].data(), reinterpret_cast<uint32_t(*)[2]>(counts[p].data()));
      code_plane(counter, t->models[p].data(), d.bw, d.bh, coefs.data(), info.data());
    }
  }
  // Initial probability from the counts (a small prior keeps it off the extremes); contexts
  // seen often start settled, rare ones keep adapting fast.
  for (int p = 0; p < n; p++) {
    for (int i = 0; i < kModelsPerPlane; i++) {
      const double c0 = counts[p][2 * i], c1 = counts[p][2 * i + 1];
      if (c0 + c1 < 1) continue;
      const int p8 = std::clamp(int(std::lround(256.0 * (c0 + 0.5) / (c0 + c1 + 1.0))), 1, 255);
      BitModel& m = t->models[p][i];
      m.p = uint16_t(p8 * 16 + 8);
      m.n = uint8_t(std::min<double>(c0 + c1, dct_detail::kRateCap));
    }
  }
  return t;
}

// Tables bytes: "VTDC", version, quality, channels, layout, width u16, height u16, then per
// plane: 64 quantiser steps (natural order), then per context one byte p8 (0: untrained,
// probability 1/2 and fast adaptation) and, for p8 != 0, one byte of observation count.
std::vector<uint8_t> dct_serialize_tables(const DctTables& t) {
  std::vector<uint8_t> out(std::begin(kMagic), std::end(kMagic));
  out.push_back(kTablesVersion);
  out.push_back(uint8_t(t.settings.quality));
  out.push_back(uint8_t(t.settings.channels));
  out.push_back(uint8_t(t.settings.layout));
  out.push_back(uint8_t(t.width & 0xFF));
  out.push_back(uint8_t(t.width >> 8));
  out.push_back(uint8_t(t.height & 0xFF));
  out.push_back(uint8_t(t.height >> 8));
  for (int p = 0; p < plane_count(t.settings); p++) {
    out.insert(out.end(), t.quant[p], t.quant[p] + 64);
    for (const BitModel& m : t.models[p]) {
      if (m.n == 0) {
        out.push_back(0);
      } else {
        out.push_back(uint8_t(std::clamp(m.p >> 4, 1, 255)));
        out.push_back(m.n);
      }
    }
  }
  return out;
}

Expected<DctTablesPtr> dct_parse_tables(std::span<const uint8_t> bytes) {
  auto corrupt = [](const std::string& what) {
    return Error(ErrorCode::kCorrupt, "dct tables: " + what);
  };
  if (bytes.size() < 12)
    return corrupt("truncated header (" + std::to_string(bytes.size()) + " bytes)");
  if (std::memcmp(bytes.data(), kMagic, 4) != 0) return corrupt("bad magic");
  if (bytes[4] != kTablesVersion) {
    return Error(ErrorCode::kUnsupported,
                 "dct tables: version " + std::to_string(bytes[4]) + " (this build reads 1)");
  }
  DctTablesPtr t(new DctTables);
  t->settings.quality = bytes[5];
  t->settings.channels = bytes[6];
  t->settings.layout = DctPlaneLayout(bytes[7]);
  t->width = bytes[8] | (bytes[9] << 8);
  t->height = bytes[10] | (bytes[11] << 8);
  if (Status s = check_settings(t->settings); !s.ok()) return corrupt(s.message());
  if (Status s = check_size(t->width, t->height); !s.ok()) return corrupt(s.message());
  size_t pos = 12;
  for (int p = 0; p < plane_count(t->settings); p++) {
    if (bytes.size() - pos < 64) return corrupt("truncated quantiser table");
    for (int i = 0; i < 64; i++) {
      t->quant[p][i] = bytes[pos++];
      if (t->quant[p][i] == 0) return corrupt("zero quantiser step");
    }
    t->models[p].assign(kModelsPerPlane, BitModel{});
    for (BitModel& m : t->models[p]) {
      if (pos >= bytes.size()) return corrupt("truncated context table");
      const uint8_t p8 = bytes[pos++];
      if (p8 == 0) continue;
      if (pos >= bytes.size()) return corrupt("truncated context table");
      const uint8_t n = bytes[pos++];
      if (n == 0 || n > dct_detail::kRateCap) return corrupt("bad context count");
      m.p = uint16_t(p8 * 16 + 8);
      m.n = n;
    }
  }
  if (pos != bytes.size()) {
    return corrupt(std::to_string(bytes.size() - pos) + " trailing bytes");
  }
  return t;
}

Status dct_encode_page(const DctTables& tables, const uint8_t* texels, int width, int height,
                       std::vector<uint8_t>& out) {
  VT_RETURN_IF_ERROR(check_size(width, height));
  if (texels == nullptr) return Error(ErrorCode::kInvalidArgument, "dct: null texels");
  const DctSettings& s = tables.settings;
  const int n = plane_count(s);
  FloatPlane planes[4];
  build_planes(s, texels, width, height, planes);
  out.clear();
  RangeEncoder enc(out);
  std::vector<BitModel> models = tables.models[0];
  // A page of one colour is flagged and its texel stored raw, so it decodes exactly.
  const size_t texel_count = size_t(width) * height;
  const int ch = s.channels;
  bool constant = true;
  for (size_t i = 1; i < texel_count && constant; i++) {
    constant = std::memcmp(texels, texels + i * ch, size_t(ch)) == 0;
  }
  if (enc.bit(models[kConstOff], constant)) {
    for (int c = 0; c < ch; c++) enc.direct(texels[c], 8);
    enc.direct(kEndMarker, 16);
    enc.finish();
    return Status::Ok();
  }
  std::vector<int16_t> coefs;
  std::vector<BlockInfo> info;
  for (int p = 0; p < n; p++) {
    const PlaneDims& d = planes[p].dims;
    coefs.assign(size_t(d.bw) * d.bh * 64, 0);
    info.assign(size_t(d.bw) * d.bh, BlockInfo{});
    quantize_plane(planes[p], tables.quant[p], coefs.data());
    models = tables.models[p];
    code_plane(enc, models.data(), d.bw, d.bh, coefs.data(), info.data());
  }
  enc.direct(kEndMarker, 16);
  enc.finish();
  return Status::Ok();
}

Status dct_decode_page(const DctTables& tables, std::span<const uint8_t> data, int width,
                       int height, uint8_t* texels) {
  VT_RETURN_IF_ERROR(check_size(width, height));
  if (texels == nullptr) return Error(ErrorCode::kInvalidArgument, "dct: null texels");
  const DctSettings& s = tables.settings;
  const int n = plane_count(s);
  const int ch = s.channels;
  thread_local DecodeScratch scratch;
  RangeDecoder dec(data.data(), data.size());
  BitModel const_model = tables.models[0][kConstOff];
  if (dec.bit(const_model)) {
    uint8_t texel[4];
    for (int c = 0; c < ch; c++) texel[c] = uint8_t(dec.direct(0, 8));
    VT_RETURN_IF_ERROR(check_end(dec, data.size()));
    const size_t count = size_t(width) * height;
    for (size_t i = 0; i < count; i++) std::memcpy(texels + i * ch, texel, size_t(ch));
    return Status::Ok();
  }
  for (int p = 0; p < n; p++) {
    const PlaneDims d = plane_dims(s, p, width, height);
    const size_t blocks = size_t(d.bw) * d.bh;
    scratch.coefs.resize(blocks * 64);
    scratch.info.resize(blocks);
    scratch.samples[p].resize(size_t(d.w) * d.h);
    scratch.models = tables.models[p];
    code_plane(dec, scratch.models.data(), d.bw, d.bh, scratch.coefs.data(), scratch.info.data());
    // A valid stream overreads at most 5 bytes; stop early on garbage.
    if (dec.overread() > 8) {
      return Error(ErrorCode::kCorrupt, "dct page: data ends early (" +
                                            std::to_string(data.size()) + " bytes, plane " +
                                            std::to_string(p) + ")");
    }
    reconstruct_plane(d, tables.quant[p], scratch.coefs.data(), scratch.info.data(),
                      scratch.samples[p].data());
  }
  VT_RETURN_IF_ERROR(check_end(dec, data.size()));

  if (s.layout == DctPlaneLayout::kPlanes) {
    for (int p = 0; p < n; p++) {
      const int w = plane_dims(s, p, width, height).w;
      const int16_t* src = scratch.samples[p].data();
      for (int y = 0; y < height; y++) {
        uint8_t* o = texels + size_t(y) * width * ch + p;
        const int16_t* r = src + size_t(y) * w;
        for (int x = 0; x < width; x++) o[x * ch] = to_u8(r[x] + 1024);
      }
    }
    return Status::Ok();
  }

  const int16_t* yp = scratch.samples[0].data();
  const int ystride = plane_dims(s, 0, width, height).w;
  const int16_t* co = scratch.samples[1].data();
  const int16_t* cg = scratch.samples[2].data();
  const int cstride = plane_dims(s, 1, width, height).w;
  if (s.layout == DctPlaneLayout::kYCoCg420) {
    ycocg420_to_rgb(yp, ystride, co, cg, cstride, width, height, ch, texels, scratch.row);
  } else {
    for (int y = 0; y < height; y++) {
      uint8_t* o = texels + size_t(y) * width * ch;
      const int16_t* yr = yp + size_t(y) * ystride;
      const int16_t* cor = co + size_t(y) * cstride;
      const int16_t* cgr = cg + size_t(y) * cstride;
      for (int x = 0; x < width; x++) put_ycocg(o + size_t(x) * ch, yr[x], cor[x], cgr[x]);
    }
  }
  if (ch == 4) {
    const int w = plane_dims(s, 3, width, height).w;
    const int16_t* a = scratch.samples[3].data();
    for (int y = 0; y < height; y++) {
      uint8_t* o = texels + size_t(y) * width * 4 + 3;
      for (int x = 0; x < width; x++) o[x * 4] = to_u8(a[size_t(y) * w + x] + 1024);
    }
  }
  return Status::Ok();
}

}  // namespace vt
