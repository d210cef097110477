// BC4 and BC5 encoder and decoder. The encoder starts from the block's range in 8-value mode,
// refines the endpoints by least squares on the chosen indices (kNormal) and adds a greedy
// endpoint search and the 6-value mode, whose fixed 0 and 255 suit masks (kHigh). Indices are
// always chosen against the palette the decoder produces.
#include "codec/bc4.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace vt {
namespace {

void decode_palette(int e0, int e1, int pal[8]) {
  pal[0] = e0;
  pal[1] = e1;
  if (e0 > e1) {
    for (int k = 2; k < 8; ++k) pal[k] = ((8 - k) * e0 + (k - 1) * e1) / 7;
  } else {
    for (int k = 2; k < 6; ++k) pal[k] = ((6 - k) * e0 + (k - 1) * e1) / 5;
    pal[6] = 0;
    pal[7] = 255;
  }
}

struct Candidate {
  int e0 = 0, e1 = 0;
  int idx[16] = {};
  int err = 1 << 30;
};

// Nearest palette entry per value; the mode follows from the endpoint order.
void consider(const int v[16], int e0, int e1, Candidate& best) {
  if (e0 < 0 || e0 > 255 || e1 < 0 || e1 > 255) return;
  int pal[8];
  decode_palette(e0, e1, pal);
  Candidate c;
  c.e0 = e0;
  c.e1 = e1;
  c.err = 0;
  for (int i = 0; i < 16; ++i) {
    int bd = 1 << 30, bk = 0;
    for (int k = 0; k < 8; ++k) {
      const int d = std::abs(v[i] - pal[k]);
      if (d < bd) bd = d, bk = k;
    }
    c.idx[i] = bk;
    c.err += bd * bd;
    if (c.err >= best.err) return;
  }
  best = c;
}

// consider() for a block's first candidate (nothing to beat, so no early exit), written without
// branches so that it vectorises over the 16 values: the same indices (the lowest k of the
// nearest entries) and error. The real-time level's whole search.
void consider_first(const int v[16], int e0, int e1, Candidate& best) {
  int pal[8];
  decode_palette(e0, e1, pal);
  Candidate c;
  c.e0 = e0;
  c.e1 = e1;
  int bd[16], bk[16];
  for (int i = 0; i < 16; ++i) bd[i] = std::abs(v[i] - pal[0]), bk[i] = 0;
  for (int k = 1; k < 8; ++k) {
    for (int i = 0; i < 16; ++i) {
      const int d = std::abs(v[i] - pal[k]);
      const bool closer = d < bd[i];
      bd[i] = closer ? d : bd[i];
      bk[i] = closer ? k : bk[i];
    }
  }
  int err = 0;
  for (int i = 0; i < 16; ++i) c.idx[i] = bk[i], err += bd[i] * bd[i];
  c.err = err;
  best = c;
}

// Least-squares endpoints for fixed 8-value-mode indices; false when singular.
bool least_squares(const int v[16], const int idx[16], float& e0, float& e1) {
  float aa = 0, bb = 0, ab = 0, ax = 0, bx = 0;
  for (int i = 0; i < 16; ++i) {
    const float a = idx[i] == 0 ? 1.0f : idx[i] == 1 ? 0.0f : float(8 - idx[i]) / 7.0f;
    const float b = 1.0f - a;
    aa += a * a, bb += b * b, ab += a * b, ax += a * float(v[i]), bx += b * float(v[i]);
  }
  const float det = aa * bb - ab * ab;
  if (!(std::fabs(det) > 1e-3f)) return false;
  e0 = std::clamp((ax * bb - bx * ab) / det, 0.0f, 255.0f);
  e1 = std::clamp((bx * aa - ax * ab) / det, 0.0f, 255.0f);
  return true;
}

void search(const int v[16], Candidate& best, int passes) {
  for (int pass = 0; pass < passes; ++pass) {
    const int before = best.err;
    const int e0 = best.e0, e1 = best.e1;
    for (int d0 = -1; d0 <= 1; ++d0) {
      for (int d1 = -1; d1 <= 1; ++d1) {
        // Stay in the same mode: the order of the endpoints selects it.
        if ((e0 + d0 > e1 + d1) == (e0 > e1)) consider(v, e0 + d0, e1 + d1, best);
      }
    }
    if (best.err >= before) break;
  }
}

void emit(const Candidate& c, uint8_t out[8]) {
  out[0] = uint8_t(c.e0);
  out[1] = uint8_t(c.e1);
  uint64_t bits = 0;
  for (int i = 0; i < 16; ++i) bits |= uint64_t(c.idx[i]) << (3 * i);
  for (int i = 0; i < 6; ++i) out[2 + i] = uint8_t(bits >> (8 * i));
}

}  // namespace

void bc4_encode_block(const uint8_t* texels, int stride, BcQuality quality, uint8_t out[8]) {
  int v[16];
  int mn = 255, mx = 0;
  for (int i = 0; i < 16; ++i) {
    v[i] = texels[i * stride];
    mn = std::min(mn, v[i]);
    mx = std::max(mx, v[i]);
  }
  Candidate best;
  if (mn == mx) {
    consider(v, mn, mn, best);  // 6-value mode, every index 0: exact
    emit(best, out);
    return;
  }
  consider_first(v, mx, mn, best);  // mx > mn: in range, as consider() requires
  if (best.err == 0 || quality == BcQuality::kRealtime) {
    emit(best, out);
    return;
  }
  for (int it = 0; it < 3; ++it) {
    float f0, f1;
    if (!least_squares(v, best.idx, f0, f1)) break;
    const int e0 = int(std::lround(f0)), e1 = int(std::lround(f1));
    const int before = best.err;
    if (e0 > e1) consider(v, e0, e1, best);
    if (best.err >= before) break;
  }
  // 6-value mode spans the values other than 0 and 255, which it has for free.
  int mn6 = 255, mx6 = 0;
  for (int i = 0; i < 16; ++i) {
    if (v[i] != 0 && v[i] != 255) mn6 = std::min(mn6, v[i]), mx6 = std::max(mx6, v[i]);
  }
  if (mn6 > mx6) mn6 = mx6 = 0;  // only 0 and 255 present
  consider(v, mn6, mx6, best);
  if (quality == BcQuality::kHigh) search(v, best, 16);
  emit(best, out);
}

void bc4_decode_block(const uint8_t block[8], uint8_t* texels, int stride) {
  int pal[8];
  decode_palette(block[0], block[1], pal);
  uint64_t bits = 0;
  for (int i = 0; i < 6; ++i) bits |= uint64_t(block[2 + i]) << (8 * i);
  for (int i = 0; i < 16; ++i) texels[i * stride] = uint8_t(pal[(bits >> (3 * i)) & 7]);
}

void bc5_encode_block(const uint8_t rgba[64], BcQuality quality, uint8_t out[16]) {
  bc4_encode_block(rgba, 4, quality, out);
  bc4_encode_block(rgba + 1, 4, quality, out + 8);
}

void bc5_decode_block(const uint8_t block[16], uint8_t rgba[64]) {
  bc4_decode_block(block, rgba, 4);
  bc4_decode_block(block + 8, rgba + 1, 4);
  for (int i = 0; i < 16; ++i) rgba[4 * i + 2] = 0, rgba[4 * i + 3] = 255;
}

}  // namespace vt
