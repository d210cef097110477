// BC1 encoder and decoder. The encoder fits endpoints along the principal axis of the block's
// colours (power iteration on the covariance), insets them, then refines by least squares on
// the chosen indices; kNormal iterates the refinement, kHigh adds a greedy +-1 endpoint search
// and the 3-colour mode. Indices are always chosen against the palette the decoder produces
// (truncating interpolation), so the error the encoder minimises is the error a GPU shows.
#include "codec/bc1.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include "common/target_clones.h"

// a * b + c stays two roundings in every build, the AVX-512 clone below included: the codec is
// compiled with -ffp-contract=off (codec/CMakeLists.txt).

namespace vt {
namespace {

inline int expand5(int v) {
  return (v << 3) | (v >> 2);
}
inline int expand6(int v) {
  return (v << 2) | (v >> 4);
}

inline uint16_t pack565(int r, int g, int b) {
  return uint16_t((r << 11) | (g << 5) | b);
}

struct Palette {
  float r[4], g[4], b[4];
};

// The palette exactly as the decoder builds it (see bc1.h).
void decode_palette(uint16_t c0, uint16_t c1, bool four, int out[4][3]) {
  int a[3] = {expand5(c0 >> 11), expand6((c0 >> 5) & 63), expand5(c0 & 31)};
  int b[3] = {expand5(c1 >> 11), expand6((c1 >> 5) & 63), expand5(c1 & 31)};
  for (int c = 0; c < 3; ++c) {
    out[0][c] = a[c];
    out[1][c] = b[c];
    if (four) {
      out[2][c] = (2 * a[c] + b[c]) / 3;
      out[3][c] = (a[c] + 2 * b[c]) / 3;
    } else {
      out[2][c] = (a[c] + b[c] + 1) / 2;
      out[3][c] = 0;
    }
  }
}

struct Pixels {
  float r[16], g[16], b[16];
};

// Best endpoint pair per 8-bit value for a block of one colour, through index 2.
struct SingleColourTables {
  uint8_t e5[256][2];
  uint8_t e6[256][2];
};

void build_single(int bits, uint8_t (*table)[2]) {
  const int levels = 1 << bits;
  for (int v = 0; v < 256; ++v) {
    int best_err = 1 << 30, best0 = 0, best1 = 0;
    for (int e0 = 0; e0 < levels; ++e0) {
      for (int e1 = 0; e1 < levels; ++e1) {
        const int x0 = bits == 5 ? expand5(e0) : expand6(e0);
        const int x1 = bits == 5 ? expand5(e1) : expand6(e1);
        // Ties prefer the narrowest pair: it degrades least if a neighbour texel differs.
        const int err = std::abs((2 * x0 + x1) / 3 - v) * 1024 + std::abs(x0 - x1);
        if (err < best_err) {
          best_err = err;
          best0 = e0;
          best1 = e1;
        }
      }
    }
    table[v][0] = uint8_t(best0);
    table[v][1] = uint8_t(best1);
  }
}

const SingleColourTables& single_colour_tables() {
  static const SingleColourTables tables = [] {
    SingleColourTables t{};
    build_single(5, t.e5);
    build_single(6, t.e6);
    return t;
  }();
  return tables;
}

inline int quantise(float v, int max) {
  int q = int(v * float(max) / 255.0f + 0.5f);
  return std::clamp(q, 0, max);
}

inline uint16_t quantise565(const float c[3]) {
  return pack565(quantise(c[0], 31), quantise(c[1], 63), quantise(c[2], 31));
}

// Chooses the nearest palette entry for every texel; returns the summed squared error.
// `four` is the mode the block will be decoded in; c0 == c1 collapses to one colour.
float select_indices(const Pixels& px, uint16_t c0, uint16_t c1, bool four, int idx[16]) {
  int pal[4][3];
  decode_palette(c0, c1, four, pal);
  const int entries = (c0 == c1 && four) ? 1 : 4;
  float best[16];
  const float r0 = float(pal[0][0]), g0 = float(pal[0][1]), b0 = float(pal[0][2]);
  for (int i = 0; i < 16; ++i) {
    const float dr = px.r[i] - r0, dg = px.g[i] - g0, db = px.b[i] - b0;
    best[i] = dr * dr + dg * dg + db * db;
    idx[i] = 0;
  }
  for (int k = 1; k < entries; ++k) {
    const float rk = float(pal[k][0]), gk = float(pal[k][1]), bk = float(pal[k][2]);
    for (int i = 0; i < 16; ++i) {
      const float dr = px.r[i] - rk, dg = px.g[i] - gk, db = px.b[i] - bk;
      const float d = dr * dr + dg * dg + db * db;
      const bool better = d < best[i];
      best[i] = better ? d : best[i];
      idx[i] = better ? k : idx[i];
    }
  }
  float err = 0;
  for (int i = 0; i < 16; ++i) err += best[i];
  return err;
}

// Least-squares endpoints for fixed indices. Returns false when the system is singular (all
// texels on one index), leaving the endpoints alone.
bool least_squares(const Pixels& px, const int idx[16], bool four, float e0[3], float e1[3]) {
  static const float kW4[4] = {1.0f, 0.0f, 2.0f / 3.0f, 1.0f / 3.0f};
  static const float kW3[4] = {1.0f, 0.0f, 0.5f, 0.0f};
  const float* w = four ? kW4 : kW3;
  float aa = 0, bb = 0, ab = 0, ax[3] = {0, 0, 0}, bx[3] = {0, 0, 0};
  for (int i = 0; i < 16; ++i) {
    if (!four && idx[i] == 3) continue;  // black: fixed, not a function of the endpoints
    const float a = w[idx[i]], b = 1.0f - a;
    aa += a * a;
    bb += b * b;
    ab += a * b;
    ax[0] += a * px.r[i];
    ax[1] += a * px.g[i];
    ax[2] += a * px.b[i];
    bx[0] += b * px.r[i];
    bx[1] += b * px.g[i];
    bx[2] += b * px.b[i];
  }
  const float det = aa * bb - ab * ab;
  if (!(std::fabs(det) > 1e-3f)) return false;
  const float inv = 1.0f / det;
  for (int c = 0; c < 3; ++c) {
    e0[c] = std::clamp((ax[c] * bb - bx[c] * ab) * inv, 0.0f, 255.0f);
    e1[c] = std::clamp((bx[c] * aa - ax[c] * ab) * inv, 0.0f, 255.0f);
  }
  return true;
}

struct Candidate {
  uint16_t c0 = 0, c1 = 0;
  bool four = true;
  int idx[16] = {};
  float err = 1e30f;
};

inline void consider(const Pixels& px, uint16_t c0, uint16_t c1, bool four, Candidate& best) {
  Candidate c;
  c.c0 = c0;
  c.c1 = c1;
  c.four = four;
  c.err = select_indices(px, c0, c1, four, c.idx);
  if (c.err < best.err) best = c;
}

// Writes the block, ordering the endpoints so the decoder picks the intended mode.
void emit(const Candidate& c, uint8_t out[8]) {
  uint16_t c0 = c.c0, c1 = c.c1;
  int idx[16];
  std::memcpy(idx, c.idx, sizeof(idx));
  if (c.four) {
    if (c0 < c1) {
      std::swap(c0, c1);
      for (int& i : idx) i ^= 1;  // 0<->1 and 2<->3 name the same colours after the swap
    } else if (c0 == c1) {
      for (int& i : idx) i = 0;
    }
  } else if (c0 > c1) {
    std::swap(c0, c1);
    for (int& i : idx) i = i < 2 ? (i ^ 1) : i;  // the midpoint and black do not move
  }
  uint32_t bits = 0;
  for (int i = 0; i < 16; ++i) bits |= uint32_t(idx[i]) << (2 * i);
  out[0] = uint8_t(c0);
  out[1] = uint8_t(c0 >> 8);
  out[2] = uint8_t(c1);
  out[3] = uint8_t(c1 >> 8);
  out[4] = uint8_t(bits);
  out[5] = uint8_t(bits >> 8);
  out[6] = uint8_t(bits >> 16);
  out[7] = uint8_t(bits >> 24);
}

void encode_single_colour(int r, int g, int b, uint8_t out[8]) {
  const SingleColourTables& t = single_colour_tables();
  Candidate c;
  c.c0 = pack565(t.e5[r][0], t.e6[g][0], t.e5[b][0]);
  c.c1 = pack565(t.e5[r][1], t.e6[g][1], t.e5[b][1]);
  c.four = true;
  for (int& i : c.idx) i = 2;
  if (c.c0 == c.c1) {
    for (int& i : c.idx) i = 0;
  }
  emit(c, out);
}

// Principal axis of the colours by power iteration on the covariance matrix.
void principal_axis(const Pixels& px, const float mean[3], float axis[3]) {
  float cov[6] = {0, 0, 0, 0, 0, 0};
  for (int i = 0; i < 16; ++i) {
    const float r = px.r[i] - mean[0], g = px.g[i] - mean[1], b = px.b[i] - mean[2];
    cov[0] += r * r;
    cov[1] += r * g;
    cov[2] += r * b;
    cov[3] += g * g;
    cov[4] += g * b;
    cov[5] += b * b;
  }
  // Start from the covariance row of the widest channel: never orthogonal to the axis.
  float v[3];
  if (cov[0] >= cov[3] && cov[0] >= cov[5]) {
    v[0] = cov[0], v[1] = cov[1], v[2] = cov[2];
  } else if (cov[3] >= cov[5]) {
    v[0] = cov[1], v[1] = cov[3], v[2] = cov[4];
  } else {
    v[0] = cov[2], v[1] = cov[4], v[2] = cov[5];
  }
  for (int it = 0; it < 4; ++it) {
    const float x = cov[0] * v[0] + cov[1] * v[1] + cov[2] * v[2];
    const float y = cov[1] * v[0] + cov[3] * v[1] + cov[4] * v[2];
    const float z = cov[2] * v[0] + cov[4] * v[1] + cov[5] * v[2];
    const float m = std::max(std::fabs(x), std::max(std::fabs(y), std::fabs(z)));
    if (!(m > 1e-12f)) break;
    const float s = 1.0f / m;
    v[0] = x * s, v[1] = y * s, v[2] = z * s;
  }
  const float len2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
  if (!(len2 > 1e-12f)) {
    v[0] = v[1] = v[2] = 1.0f;
  }
  const float inv = 1.0f / std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  axis[0] = v[0] * inv, axis[1] = v[1] * inv, axis[2] = v[2] * inv;
}

// Greedy search: moves each endpoint component by +-1 quantisation step while it helps.
void refine_search(const Pixels& px, Candidate& best, int max_passes) {
  for (int pass = 0; pass < max_passes; ++pass) {
    bool improved = false;
    for (int e = 0; e < 2; ++e) {
      for (int ch = 0; ch < 3; ++ch) {
        static const int kShift[3] = {11, 5, 0};
        static const int kMax[3] = {31, 63, 31};
        for (int d = -1; d <= 1; d += 2) {
          uint16_t c[2] = {best.c0, best.c1};
          const int v = ((c[e] >> kShift[ch]) & kMax[ch]) + d;
          if (v < 0 || v > kMax[ch]) continue;
          c[e] = uint16_t((c[e] & ~(kMax[ch] << kShift[ch])) | (v << kShift[ch]));
          const float before = best.err;
          consider(px, c[0], c[1], best.four, best);
          improved |= best.err < before;
        }
      }
    }
    if (!improved) break;
  }
}

// ---- Real-time level: 16 blocks at a time ----
//
// The real-time encoder runs the same arithmetic on 16 blocks side by side (structure of arrays,
// innermost loops over the blocks), which compilers turn into SIMD. It is built twice, for
// AVX-512, AVX2 and the baseline, and picked at run time; both do the same IEEE operations in the
// same order per block (no FMA, no reassociation), so the bytes do not depend on the machine.
constexpr int kLanes = 16;
// All kLanes lanes as one GCC/Clang vector: element-wise IEEE operations, split into whatever
// registers each clone has.
using LaneVec = float __attribute__((vector_size(4 * kLanes)));
using LaneInt = int32_t __attribute__((vector_size(4 * kLanes)));
using LaneUint = uint32_t __attribute__((vector_size(4 * kLanes)));
template <class Vec, class T>
[[gnu::always_inline]] inline void load_lanes(Vec& x, const T (&v)[kLanes]) {
  std::memcpy(&x, v, sizeof x);
}

VT_TARGET_CLONES
void encode_realtime_lanes(const uint32_t (&texels)[16][kLanes], uint16_t c0_out[kLanes],
                           uint16_t c1_out[kLanes], uint32_t bits_out[kLanes],
                           bool constant_out[kLanes]) {
  float r[16][kLanes], g[16][kLanes], b[16][kLanes];
  int32_t xx[16][kLanes];  // |x|^2 - 3 * 255^2 (select's bias), exact
  for (int i = 0; i < 16; ++i) {
    for (int l = 0; l < kLanes; ++l) {
      const uint32_t w = texels[i][l];
      r[i][l] = float(int(w & 255u));
      g[i][l] = float(int((w >> 8) & 255u));
      b[i][l] = float(int((w >> 16) & 255u));
      const int32_t ri = int32_t(w & 255u), gi = int32_t((w >> 8) & 255u),
                    bi = int32_t((w >> 16) & 255u);
      xx[i][l] = ri * ri + gi * gi + bi * bi - 3 * 255 * 255;
    }
  }
  float mr[kLanes], mg[kLanes], mb[kLanes];
  for (int l = 0; l < kLanes; ++l) mr[l] = mg[l] = mb[l] = 0;
  for (int i = 0; i < 16; ++i) {
    for (int l = 0; l < kLanes; ++l) mr[l] += r[i][l], mg[l] += g[i][l], mb[l] += b[i][l];
  }
  for (int l = 0; l < kLanes; ++l) mr[l] *= 0.0625f, mg[l] *= 0.0625f, mb[l] *= 0.0625f;
  float crr[kLanes], crg[kLanes], crb[kLanes], cgg[kLanes], cgb[kLanes], cbb[kLanes];
  for (int l = 0; l < kLanes; ++l) crr[l] = crg[l] = crb[l] = cgg[l] = cgb[l] = cbb[l] = 0;
  for (int i = 0; i < 16; ++i) {
    for (int l = 0; l < kLanes; ++l) {
      const float dr = r[i][l] - mr[l], dg = g[i][l] - mg[l], db = b[i][l] - mb[l];
      crr[l] += dr * dr, crg[l] += dr * dg, crb[l] += dr * db;
      cgg[l] += dg * dg, cgb[l] += dg * db, cbb[l] += db * db;
    }
  }
  // Integer texels, a mean of 16 and their deviations are exact in float: zero spread is
  // exactly a one-colour block.
  for (int l = 0; l < kLanes; ++l) constant_out[l] = crr[l] + cgg[l] + cbb[l] == 0.0f;
  // Power iteration from the covariance row of the widest channel.
  float vr[kLanes], vg[kLanes], vb[kLanes];
  for (int l = 0; l < kLanes; ++l) {
    const bool rw = crr[l] >= cgg[l] && crr[l] >= cbb[l];
    const bool gw = !rw && cgg[l] >= cbb[l];
    vr[l] = rw ? crr[l] : gw ? crg[l] : crb[l];
    vg[l] = rw ? crg[l] : gw ? cgg[l] : cgb[l];
    vb[l] = rw ? crb[l] : gw ? cgb[l] : cbb[l];
  }
  for (int it = 0; it < 3; ++it) {
    for (int l = 0; l < kLanes; ++l) {
      const float x = crr[l] * vr[l] + crg[l] * vg[l] + crb[l] * vb[l];
      const float y = crg[l] * vr[l] + cgg[l] * vg[l] + cgb[l] * vb[l];
      const float z = crb[l] * vr[l] + cgb[l] * vg[l] + cbb[l] * vb[l];
      const float m = std::max(std::fabs(x), std::max(std::fabs(y), std::fabs(z)));
      const float inv = m > 1e-12f ? 1.0f / m : 0.0f;
      vr[l] = m > 1e-12f ? x * inv : vr[l];
      vg[l] = m > 1e-12f ? y * inv : vg[l];
      vb[l] = m > 1e-12f ? z * inv : vb[l];
    }
  }
  for (int l = 0; l < kLanes; ++l) {
    float len2 = vr[l] * vr[l] + vg[l] * vg[l] + vb[l] * vb[l];
    const bool degenerate = !(len2 > 1e-12f);
    vr[l] = degenerate ? 1.0f : vr[l];
    vg[l] = degenerate ? 1.0f : vg[l];
    vb[l] = degenerate ? 1.0f : vb[l];
    len2 = degenerate ? 3.0f : len2;
    const float inv = 1.0f / std::sqrt(len2);
    vr[l] *= inv, vg[l] *= inv, vb[l] *= inv;
  }
  float tmin[kLanes], tmax[kLanes];
  for (int l = 0; l < kLanes; ++l) tmin[l] = 1e30f, tmax[l] = -1e30f;
  for (int i = 0; i < 16; ++i) {
    for (int l = 0; l < kLanes; ++l) {
      const float t =
          (r[i][l] - mr[l]) * vr[l] + (g[i][l] - mg[l]) * vg[l] + (b[i][l] - mb[l]) * vb[l];
      tmin[l] = std::min(tmin[l], t);
      tmax[l] = std::max(tmax[l], t);
    }
  }
  // Endpoints as 565 levels (floats holding integers), decoded palette, indices, error. Every
  // value truncated below is non-negative, so int conversion is floor (and vectorises).
  float q0[3][kLanes], q1[3][kLanes];
  // The clamp as std::min(std::max(x, 0), 255) computes it (NaN passes through), on values so
  // that the loops if-convert into SIMD (with codec/CMakeLists.txt's flags for this file).
  auto quantise_lanes = [](float x, float levels) {
    const float lo = x < 0.0f ? 0.0f : x;
    const float c = 255.0f < lo ? 255.0f : lo;
    return float(int(c * (levels / 255.0f) + 0.5f));
  };
  for (int l = 0; l < kLanes; ++l) {
    const float inset = (tmax[l] - tmin[l]) * (1.0f / 16.0f);
    const float hi = tmax[l] - inset, lo = tmin[l] + inset;
    q0[0][l] = quantise_lanes(mr[l] + hi * vr[l], 31.0f);
    q0[1][l] = quantise_lanes(mg[l] + hi * vg[l], 63.0f);
    q0[2][l] = quantise_lanes(mb[l] + hi * vb[l], 31.0f);
    q1[0][l] = quantise_lanes(mr[l] + lo * vr[l], 31.0f);
    q1[1][l] = quantise_lanes(mg[l] + lo * vg[l], 63.0f);
    q1[2][l] = quantise_lanes(mb[l] + lo * vb[l], 31.0f);
  }

  uint32_t idx[kLanes];
  int32_t err[kLanes];  // exact integers: compared as such
  // Palette of 565 levels q0, q1 as the decoder builds it; nearest entry per texel, returned as
  // the block's packed 2-bit indices (texel i at bits 2i).
  auto select = [&](const float(&a)[3][kLanes], const float(&c)[3][kLanes], uint32_t(&out)[kLanes],
                    int32_t(&e)[kLanes]) {
    float p[4][3][kLanes];
    for (int ch = 0; ch < 3; ++ch) {
      const float mul = ch == 1 ? 4.0f : 8.0f, shift = ch == 1 ? 1.0f / 16.0f : 1.0f / 4.0f;
      for (int l = 0; l < kLanes; ++l) {
        // Bit replication: (q << 3) | (q >> 2) for 5 bits, (q << 2) | (q >> 4) for 6.
        const float x0 = a[ch][l] * mul + float(int(a[ch][l] * shift));
        const float x1 = c[ch][l] * mul + float(int(c[ch][l] * shift));
        p[0][ch][l] = x0;
        p[1][ch][l] = x1;
        p[2][ch][l] = float(int((2.0f * x0 + x1) / 3.0f));
        p[3][ch][l] = float(int((x0 + 2.0f * x1) / 3.0f));
      }
    }
    // |x - p|^2 = |x|^2 + (|p|^2 - 2 x.p): the palette half is shared by all texels. Scores
    // 4 * (|p|^2 - 2 x.p + kBias) + k are non-negative integers below 2^24, exact in float, so
    // one min per entry finds the nearest entry and its index (ties to the lower index, as a
    // strict compare would) and the error stays exact.
    constexpr float kBias = 3.0f * 255.0f * 255.0f;
    float pk[4][kLanes], m8[4][3][kLanes];
    for (int k = 0; k < 4; ++k) {
      for (int l = 0; l < kLanes; ++l) {
        const float pp =
            p[k][0][l] * p[k][0][l] + p[k][1][l] * p[k][1][l] + p[k][2][l] * p[k][2][l];
        pk[k][l] = (pp + kBias) * 4.0f + float(k);
        for (int ch = 0; ch < 3; ++ch) m8[k][ch][l] = -8.0f * p[k][ch][l];
      }
    }
    // Each texel's error |x - p|^2 is an integer and the block's sum stays below 2^24, so the
    // sum is exact in any order and type: it accumulates in int32 (one-cycle adds, no
    // conversion; a float chain here was the kernel's longest latency) and is compared as is.
    // Written on whole lane vectors: with plain loops GCC unrolls the 16-lane loops and
    // vectorises the texel loop instead, gathering every lane's texels with permutes and
    // reducing the indices and errors across vector elements (~40% of the kernel's time).
    LaneVec pk0, pk1, pk2, pk3, m[4][3];
    load_lanes(pk0, pk[0]), load_lanes(pk1, pk[1]), load_lanes(pk2, pk[2]), load_lanes(pk3, pk[3]);
    for (int k = 0; k < 4; ++k)
      for (int ch = 0; ch < 3; ++ch) load_lanes(m[k][ch], m8[k][ch]);
    LaneInt ei = {};
    LaneUint bits = {};
    for (int i = 0; i < 16; ++i) {
      LaneVec x, y, z;
      load_lanes(x, r[i]), load_lanes(y, g[i]), load_lanes(z, b[i]);
      LaneVec best = pk0 + x * m[0][0] + y * m[0][1] + z * m[0][2];
      LaneVec d = pk1 + x * m[1][0] + y * m[1][1] + z * m[1][2];
      best = d < best ? d : best;
      d = pk2 + x * m[2][0] + y * m[2][1] + z * m[2][2];
      best = d < best ? d : best;
      d = pk3 + x * m[3][0] + y * m[3][1] + z * m[3][2];
      best = d < best ? d : best;
      const LaneInt s = __builtin_convertvector(best, LaneInt);
      bits |= LaneUint(s & 3) << (2 * i);
      LaneInt sq;
      load_lanes(sq, xx[i]);
      ei += (s >> 2) + sq;
    }
    std::memcpy(out, &bits, sizeof bits);
    std::memcpy(e, &ei, sizeof ei);
  };
  select(q0, q1, idx, err);

  // One least-squares refinement on the chosen indices; kept where it lowers the error.
  float aa[kLanes], bb[kLanes], ab[kLanes], ax[3][kLanes], bx[3][kLanes];
  for (int l = 0; l < kLanes; ++l) {
    aa[l] = bb[l] = ab[l] = 0;
    for (int ch = 0; ch < 3; ++ch) ax[ch][l] = bx[ch][l] = 0;
  }
  for (int i = 0; i < 16; ++i) {
    for (int l = 0; l < kLanes; ++l) {
      const uint32_t k = (idx[l] >> (2 * i)) & 3u;
      const float wa = k == 0 ? 1.0f : k == 1 ? 0.0f : k == 2 ? 2.0f / 3.0f : 1.0f / 3.0f;
      const float wb = 1.0f - wa;
      aa[l] += wa * wa, bb[l] += wb * wb, ab[l] += wa * wb;
      ax[0][l] += wa * r[i][l], ax[1][l] += wa * g[i][l], ax[2][l] += wa * b[i][l];
      bx[0][l] += wb * r[i][l], bx[1][l] += wb * g[i][l], bx[2][l] += wb * b[i][l];
    }
  }
  float n0[3][kLanes], n1[3][kLanes];
  int32_t solvable[kLanes];  // 0 or 1, as wide as the lanes it masks
  for (int l = 0; l < kLanes; ++l) {
    const float det = aa[l] * bb[l] - ab[l] * ab[l];
    solvable[l] = std::fabs(det) > 1e-3f;
    const float inv = solvable[l] ? 1.0f / det : 0.0f;
    for (int ch = 0; ch < 3; ++ch) {
      const float levels = ch == 1 ? 63.0f : 31.0f;
      n0[ch][l] = quantise_lanes((ax[ch][l] * bb[l] - bx[ch][l] * ab[l]) * inv, levels);
      n1[ch][l] = quantise_lanes((bx[ch][l] * aa[l] - ax[ch][l] * ab[l]) * inv, levels);
    }
  }
  uint32_t idx2[kLanes];
  int32_t err2[kLanes];
  select(n0, n1, idx2, err2);

  // The choice as selects on values, the conversions after it: lane by lane with a branch
  // here (the compare mispredicts) this loop cost about a tenth of the kernel.
  int32_t take[kLanes], e0[3][kLanes], e1[3][kLanes];
  uint32_t chosen[kLanes];
  for (int l = 0; l < kLanes; ++l) take[l] = solvable[l] & int32_t(err2[l] < err[l]);
  for (int ch = 0; ch < 3; ++ch) {
    for (int l = 0; l < kLanes; ++l) {
      e0[ch][l] = take[l] ? int32_t(n0[ch][l]) : int32_t(q0[ch][l]);
      e1[ch][l] = take[l] ? int32_t(n1[ch][l]) : int32_t(q1[ch][l]);
    }
  }
  for (int l = 0; l < kLanes; ++l) chosen[l] = take[l] ? idx2[l] : idx[l];
  for (int l = 0; l < kLanes; ++l) {
    const int a = (e0[0][l] << 11) | (e0[1][l] << 5) | e0[2][l];
    const int c = (e1[0][l] << 11) | (e1[1][l] << 5) | e1[2][l];
    const uint32_t bits = chosen[l];
    // 4-colour mode needs c0 > c1: swapping the endpoints maps index 0<->1 and 2<->3.
    c0_out[l] = uint16_t(a < c ? c : a);
    c1_out[l] = uint16_t(a < c ? a : c);
    bits_out[l] = a < c ? bits ^ 0x55555555u : a == c ? 0u : bits;
  }
}

}  // namespace

void bc1_encode_block(const uint8_t rgba[64], BcQuality quality, uint8_t out[8],
                      bool four_colour_only) {
  if (quality == BcQuality::kRealtime) {
    bc1_encode_blocks_realtime(rgba, 1, out, 8);
    return;
  }
  Pixels px;
  int mn[3] = {255, 255, 255}, mx[3] = {0, 0, 0};
  for (int i = 0; i < 16; ++i) {
    const int r = rgba[4 * i], g = rgba[4 * i + 1], b = rgba[4 * i + 2];
    px.r[i] = float(r), px.g[i] = float(g), px.b[i] = float(b);
    mn[0] = std::min(mn[0], r), mx[0] = std::max(mx[0], r);
    mn[1] = std::min(mn[1], g), mx[1] = std::max(mx[1], g);
    mn[2] = std::min(mn[2], b), mx[2] = std::max(mx[2], b);
  }
  if (mn[0] == mx[0] && mn[1] == mx[1] && mn[2] == mx[2]) {
    encode_single_colour(mn[0], mn[1], mn[2], out);
    return;
  }

  float mean[3] = {0, 0, 0};
  for (int i = 0; i < 16; ++i) mean[0] += px.r[i], mean[1] += px.g[i], mean[2] += px.b[i];
  for (float& m : mean) m *= 1.0f / 16.0f;
  float axis[3];
  principal_axis(px, mean, axis);

  float tmin = 1e30f, tmax = -1e30f;
  for (int i = 0; i < 16; ++i) {
    const float t = (px.r[i] - mean[0]) * axis[0] + (px.g[i] - mean[1]) * axis[1] +
                    (px.b[i] - mean[2]) * axis[2];
    tmin = std::min(tmin, t);
    tmax = std::max(tmax, t);
  }
  // Inset by 1/16 of the range: the extreme texels are rarely worth an exact palette entry.
  const float inset = (tmax - tmin) / 16.0f;
  float e0[3], e1[3];
  for (int c = 0; c < 3; ++c) {
    e0[c] = std::clamp(mean[c] + (tmax - inset) * axis[c], 0.0f, 255.0f);
    e1[c] = std::clamp(mean[c] + (tmin + inset) * axis[c], 0.0f, 255.0f);
  }

  Candidate best;
  consider(px, quantise565(e0), quantise565(e1), true, best);

  const int ls_iterations = quality == BcQuality::kRealtime ? 1 : 4;
  for (int it = 0; it < ls_iterations; ++it) {
    const float before = best.err;
    if (!least_squares(px, best.idx, true, e0, e1)) break;
    consider(px, quantise565(e0), quantise565(e1), true, best);
    if (!(best.err < before)) break;
  }
  if (quality == BcQuality::kRealtime) {
    emit(best, out);
    return;
  }

  // The bounding extremes without inset: better for blocks of few distinct colours.
  for (int c = 0; c < 3; ++c) {
    e0[c] = std::clamp(mean[c] + tmax * axis[c], 0.0f, 255.0f);
    e1[c] = std::clamp(mean[c] + tmin * axis[c], 0.0f, 255.0f);
  }
  consider(px, quantise565(e0), quantise565(e1), true, best);

  if (quality == BcQuality::kHigh) {
    refine_search(px, best, 8);
    if (!four_colour_only) {
      // 3-colour mode: a true midpoint and black, fit by least squares from the 4-colour fit.
      Candidate three;
      consider(px, best.c0, best.c1, false, three);
      for (int it = 0; it < 3; ++it) {
        float a[3], b[3];
        if (!least_squares(px, three.idx, false, a, b)) break;
        const float before = three.err;
        consider(px, quantise565(a), quantise565(b), false, three);
        if (!(three.err < before)) break;
      }
      refine_search(px, three, 4);
      if (three.err < best.err) best = three;
    }
  }
  emit(best, out);
}

namespace {

// encode_single_colour's bytes without its Candidate: every index 2 (3 once the endpoints swap,
// 0 when they are equal), as emit() orders them.
inline void single_colour_block(int r, int g, int b, uint8_t* dst) {
  const SingleColourTables& t = single_colour_tables();
  uint16_t c0 = pack565(t.e5[r][0], t.e6[g][0], t.e5[b][0]);
  uint16_t c1 = pack565(t.e5[r][1], t.e6[g][1], t.e5[b][1]);
  uint32_t bits = c0 == c1 ? 0u : c0 < c1 ? 0xFFFFFFFFu : 0xAAAAAAAAu;
  if (c0 < c1) std::swap(c0, c1);
  dst[0] = uint8_t(c0), dst[1] = uint8_t(c0 >> 8);
  dst[2] = uint8_t(c1), dst[3] = uint8_t(c1 >> 8);
  for (int i = 0; i < 4; ++i) dst[4 + i] = uint8_t(bits >> (8 * i));
}

// Runs the kernel on lanes gathered by the caller and writes the first n blocks.
inline void finish_lanes(const uint32_t (&texels)[16][kLanes], size_t n, uint8_t* out,
                         size_t out_stride) {
  uint16_t c0[kLanes], c1[kLanes];
  uint32_t bits[kLanes];
  bool constant[kLanes];
  encode_realtime_lanes(texels, c0, c1, bits, constant);
  for (size_t l = 0; l < n; ++l) {
    uint8_t* dst = out + l * out_stride;
    if (constant[l]) {
      const uint32_t w = texels[0][l];
      single_colour_block(int(w & 255u), int((w >> 8) & 255u), int((w >> 16) & 255u), dst);
      continue;
    }
    dst[0] = uint8_t(c0[l]), dst[1] = uint8_t(c0[l] >> 8);
    dst[2] = uint8_t(c1[l]), dst[3] = uint8_t(c1[l] >> 8);
    for (int i = 0; i < 4; ++i) dst[4 + i] = uint8_t(bits[l] >> (8 * i));
  }
}

}  // namespace

namespace {

// Lanes of `n` (1..kLanes) blocks side by side from image rows (R in the low byte, missing colour
// channels 0); idle lanes repeat the last block. `last_in_row`: the last lane's block ends its
// image row, so its last texel may not be read as a 4-byte word (3 channels: the image may end
// there).
template <int kChannels>
inline void gather_lanes(const uint8_t* texels, size_t row_stride, size_t n, bool last_in_row,
                         uint32_t (&lanes)[16][kLanes]) {
  for (int y = 0; y < 4; ++y) {
    const uint8_t* row = texels + size_t(y) * row_stride;
    for (size_t l = 0; l < size_t(kLanes); ++l) {
      const size_t blk = std::min(l, n - 1);
      const uint8_t* src = row + blk * 4 * kChannels;
      if constexpr (kChannels == 3 && std::endian::native == std::endian::little) {
        // The block row's 12 bytes in two loads, split by shifts (the kernel reads the low
        // three bytes of each word): half the loads of one per texel and never past the row.
        uint64_t lo;
        uint32_t hi;
        std::memcpy(&lo, src, 8);
        std::memcpy(&hi, src + 8, 4);
        lanes[4 * y][l] = uint32_t(lo);
        lanes[4 * y + 1][l] = uint32_t(lo >> 24);
        lanes[4 * y + 2][l] = uint32_t(lo >> 48) | (hi << 16);
        lanes[4 * y + 3][l] = hi >> 8;
        continue;
      }
      for (int x = 0; x < 4; ++x) {
        const uint8_t* t = src + x * kChannels;
        uint32_t w;
        if constexpr (kChannels >= 3 && std::endian::native == std::endian::little) {
          if (kChannels == 4 || x < 3 || !last_in_row || blk + 1 < n) {
            std::memcpy(&w, t, 4);  // one load; the kernel reads only the low three bytes
          } else {
            w = uint32_t(t[0]) | (uint32_t(t[1]) << 8) | (uint32_t(t[2]) << 16);
          }
        } else {
          w = t[0];
          if constexpr (kChannels > 1) w |= uint32_t(t[1]) << 8;
          if constexpr (kChannels > 2) w |= uint32_t(t[2]) << 16;
        }
        lanes[4 * y + x][l] = w;
      }
    }
  }
}

}  // namespace

void bc1_encode_rows_realtime(const uint8_t* texels, size_t row_stride, int channels, size_t count,
                              uint8_t* out) {
  alignas(64) uint32_t lanes[16][kLanes];
  for (size_t first = 0; first < count; first += kLanes) {
    const size_t n = std::min<size_t>(kLanes, count - first);
    const bool last = first + n == count;
    const uint8_t* src = texels + first * 4 * size_t(channels);
    switch (channels) {
      case 1:
        gather_lanes<1>(src, row_stride, n, last, lanes);
        break;
      case 2:
        gather_lanes<2>(src, row_stride, n, last, lanes);
        break;
      case 3:
        gather_lanes<3>(src, row_stride, n, last, lanes);
        break;
      default:
        gather_lanes<4>(src, row_stride, n, last, lanes);
        break;
    }
    finish_lanes(lanes, n, out + first * 8, 8);
  }
}

void bc1_encode_blocks_realtime(const uint8_t* rgba, size_t count, uint8_t* out,
                                size_t out_stride) {
  uint32_t texels[16][kLanes];
  for (size_t first = 0; first < count; first += kLanes) {
    const size_t n = std::min<size_t>(kLanes, count - first);
    // Texel-major transpose, one 32-bit move per texel, so the kernel's loads are contiguous.
    // Idle lanes repeat the last block; their results are dropped.
    for (size_t l = 0; l < size_t(kLanes); ++l) {
      const uint8_t* src = rgba + (first + std::min(l, n - 1)) * 64;
      for (int i = 0; i < 16; ++i) {
        // R in the low byte on any host (the kernel unpacks by shifts).
        if constexpr (std::endian::native == std::endian::little) {
          std::memcpy(&texels[i][l], src + 4 * i, 4);
        } else {
          texels[i][l] = uint32_t(src[4 * i]) | (uint32_t(src[4 * i + 1]) << 8) |
                         (uint32_t(src[4 * i + 2]) << 16);
        }
      }
    }
    finish_lanes(texels, n, out + first * out_stride, out_stride);
  }
}

void bc1_decode_block(const uint8_t block[8], uint8_t rgba[64], bool force_four_colour) {
  const uint16_t c0 = uint16_t(block[0] | (block[1] << 8));
  const uint16_t c1 = uint16_t(block[2] | (block[3] << 8));
  int pal[4][3];
  decode_palette(c0, c1, force_four_colour || c0 > c1, pal);
  const uint32_t bits = uint32_t(block[4]) | (uint32_t(block[5]) << 8) |
                        (uint32_t(block[6]) << 16) | (uint32_t(block[7]) << 24);
  for (int i = 0; i < 16; ++i) {
    const int k = (bits >> (2 * i)) & 3;
    rgba[4 * i] = uint8_t(pal[k][0]);
    rgba[4 * i + 1] = uint8_t(pal[k][1]);
    rgba[4 * i + 2] = uint8_t(pal[k][2]);
    rgba[4 * i + 3] = 255;
  }
}

}  // namespace vt
