// BC7's real-time level: mode 6 (one subset, 7-bit RGBA endpoints with a p-bit each, 4-bit
// indices) fitted to 16 blocks side by side, as bc1.cpp's real-time kernel does for BC1: every
// loop runs over the blocks (structure of arrays), so compilers turn it into SIMD, built for
// AVX-512, AVX2 and the baseline and picked at run time, with the same IEEE operations in the
// same order on every build (codec/CMakeLists.txt: no FMA contraction), hence the same bytes.
//
// Per block: endpoints along the principal axis (power iteration on the covariance), p-bits
// each chosen by which rounds its endpoint closer (unless the caller fixes them), indices
// chosen exhaustively against the palette the decoder builds (an integer score per entry, exact
// in float, so the error minimised is the error a GPU shows), then two least-squares
// refinements on the chosen indices and p-bits, each kept only where it lowers the error.
// Scoring every p-bit pair instead costs 2.4x the time for +0.1 dB on Kodak, choosing the
// p-bits again after each refinement 1.2x for +0.04 dB (docs/BENCHMARKS.md). Blocks whose alpha
// varies are fitted in RGBA; opaque blocks in RGB, with alpha decoding to exactly 255 (both
// p-bits set) unless the caller ignores alpha (RGB layers), where the p-bits are free for colour
// and alpha decodes to 254 or 255.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "codec/bc7.h"
#include "codec/bptc_tables.h"
#include "common/target_clones.h"

namespace vt {
namespace {

constexpr int kLanes = 16;

// What the kernel gives for each lane: mode 6's stored fields.
struct Mode6Lanes {
  int q[2][4][kLanes];  // 7-bit endpoint values (p-bit excluded), endpoint x channel
  int p[2][kLanes];
  int idx[16][kLanes];
};

// `texels[i][l]`: texel i of lane l as RGBA8 in a word (R in the low byte). NCH = 3 fits RGB
// (alpha stored as 127 with the p-bits), NCH = 4 fits RGBA. `pbit_pairs`: bit k set = try p-bits
// (k & 1, k >> 1).
template <int NCH>
VT_TARGET_CLONES void fit_mode6_lanes(const uint32_t (&texels)[16][kLanes], unsigned pbit_pairs,
                                      Mode6Lanes& out) {
  float x[NCH][16][kLanes];
  float xx[16][kLanes];  // |x|^2, an integer
  for (int i = 0; i < 16; ++i) {
    for (int l = 0; l < kLanes; ++l) {
      int s = 0;
      for (int c = 0; c < NCH; ++c) {
        const int v = int((texels[i][l] >> (8 * c)) & 255u);
        x[c][i][l] = float(v);
        s += v * v;
      }
      xx[i][l] = float(s);
    }
  }
  float mean[NCH][kLanes];
  for (int c = 0; c < NCH; ++c) {
    for (int l = 0; l < kLanes; ++l) mean[c][l] = 0;
    for (int i = 0; i < 16; ++i) {
      for (int l = 0; l < kLanes; ++l) mean[c][l] += x[c][i][l];
    }
    for (int l = 0; l < kLanes; ++l) mean[c][l] *= 0.0625f;
  }
  float cov[NCH][NCH][kLanes];
  for (int a = 0; a < NCH; ++a) {
    for (int b = a; b < NCH; ++b) {
      for (int l = 0; l < kLanes; ++l) cov[a][b][l] = 0;
      for (int i = 0; i < 16; ++i) {
        for (int l = 0; l < kLanes; ++l)
          cov[a][b][l] += (x[a][i][l] - mean[a][l]) * (x[b][i][l] - mean[b][l]);
      }
      for (int l = 0; l < kLanes; ++l) cov[b][a][l] = cov[a][b][l];
    }
  }
  // Power iteration from the covariance row of the widest channel.
  float v[NCH][kLanes];
  for (int l = 0; l < kLanes; ++l) {
    int widest = 0;
    for (int c = 1; c < NCH; ++c) widest = cov[c][c][l] > cov[widest][widest][l] ? c : widest;
    for (int c = 0; c < NCH; ++c) v[c][l] = cov[widest][c][l];
  }
  for (int it = 0; it < 4; ++it) {
    float nv[NCH][kLanes];
    for (int a = 0; a < NCH; ++a) {
      for (int l = 0; l < kLanes; ++l) {
        float s = 0;
        for (int b = 0; b < NCH; ++b) s += cov[a][b][l] * v[b][l];
        nv[a][l] = s;
      }
    }
    for (int l = 0; l < kLanes; ++l) {
      float m = 0;
      for (int c = 0; c < NCH; ++c) m = std::max(m, std::fabs(nv[c][l]));
      const bool ok = m > 1e-12f;
      const float inv = ok ? 1.0f / m : 0.0f;
      for (int c = 0; c < NCH; ++c) v[c][l] = ok ? nv[c][l] * inv : v[c][l];
    }
  }
  for (int l = 0; l < kLanes; ++l) {
    float len2 = 0;
    for (int c = 0; c < NCH; ++c) len2 += v[c][l] * v[c][l];
    const bool degenerate = !(len2 > 1e-12f);
    len2 = degenerate ? float(NCH) : len2;
    const float inv = 1.0f / std::sqrt(len2);
    for (int c = 0; c < NCH; ++c) v[c][l] = (degenerate ? 1.0f : v[c][l]) * inv;
  }
  float tmin[kLanes], tmax[kLanes];
  for (int l = 0; l < kLanes; ++l) tmin[l] = 0, tmax[l] = 0;
  for (int i = 0; i < 16; ++i) {
    for (int l = 0; l < kLanes; ++l) {
      float t = 0;
      for (int c = 0; c < NCH; ++c) t += (x[c][i][l] - mean[c][l]) * v[c][l];
      tmin[l] = std::min(tmin[l], t);
      tmax[l] = std::max(tmax[l], t);
    }
  }
  // The clamp as min(max(x, 0), 255) computes it, on values, so the loops if-convert.
  auto clamp255 = [](float e) {
    const float lo = e < 0.0f ? 0.0f : e;
    return 255.0f < lo ? 255.0f : lo;
  };
  float e[2][NCH][kLanes];
  for (int c = 0; c < NCH; ++c) {
    for (int l = 0; l < kLanes; ++l) {
      e[0][c][l] = clamp255(mean[c][l] + tmin[l] * v[c][l]);
      e[1][c][l] = clamp255(mean[c][l] + tmax[l] * v[c][l]);
    }
  }

  const int* w = bptc::weights(4);
  // Scores (|p|^2 + bias - 2 x.p) * 16 + k lie in [0, 2^24): integers exact in float, so one min
  // over the entries gives the nearest entry, its index (ties to the lower index) and, with
  // |x|^2 - bias added back, the exact error.
  constexpr float kBias = float(NCH) * 255.0f * 255.0f;
  float best_err[kLanes];
  for (int l = 0; l < kLanes; ++l) best_err[l] = 3.0e38f;
  float qe[2][NCH][kLanes];  // a candidate's 7-bit endpoints (as floats)
  float err[kLanes], idx[16][kLanes];
  // Quantises e with each lane's p-bits, picks indices; keeps the result in `out` where it beats
  // best_err.
  auto try_pbits = [&](const float(&pbits)[2][kLanes]) {
    float u[2][NCH][kLanes];
    for (int k = 0; k < 2; ++k) {
      for (int c = 0; c < NCH; ++c) {
        for (int l = 0; l < kLanes; ++l) {
          const float p = pbits[k][l];
          // Nearest 8-bit value with low bit p: q = round((e - p) / 2), clamped to 7 bits.
          const float r = (e[k][c][l] - p) * 0.5f + 0.5f;
          const float q0 = float(int(r < 0.0f ? 0.0f : r));
          const float q = q0 > 127.0f ? 127.0f : q0;
          qe[k][c][l] = q;
          u[k][c][l] = q * 2.0f + p;
        }
      }
    }
    for (int l = 0; l < kLanes; ++l) err[l] = 0;
    float pk[16][kLanes], m32[16][NCH][kLanes];
    for (int k = 0; k < 16; ++k) {
      const float a = float(64 - w[k]), b = float(w[k]);
      for (int l = 0; l < kLanes; ++l) {
        float pp = 0;
        for (int c = 0; c < NCH; ++c) {
          const float pal = float(int((a * u[0][c][l] + b * u[1][c][l] + 32.0f) * (1.0f / 64.0f)));
          pp += pal * pal;
          m32[k][c][l] = -32.0f * pal;
        }
        pk[k][l] = (pp + kBias) * 16.0f + float(k);
      }
    }
    for (int i = 0; i < 16; ++i) {
      float best[kLanes];
      for (int l = 0; l < kLanes; ++l) best[l] = 3.0e38f;
      for (int k = 0; k < 16; ++k) {
        for (int l = 0; l < kLanes; ++l) {
          float s = pk[k][l];
          for (int c = 0; c < NCH; ++c) s += m32[k][c][l] * x[c][i][l];
          best[l] = std::min(best[l], s);
        }
      }
      for (int l = 0; l < kLanes; ++l) {
        const float whole = float(int(best[l] * 0.0625f));
        idx[i][l] = best[l] - whole * 16.0f;
        err[l] += whole - kBias + xx[i][l];
      }
    }
    for (int l = 0; l < kLanes; ++l) {
      const bool better = err[l] < best_err[l];
      best_err[l] = better ? err[l] : best_err[l];
      for (int k = 0; k < 2; ++k) {
        out.p[k][l] = better ? int(pbits[k][l]) : out.p[k][l];
        for (int c = 0; c < NCH; ++c) out.q[k][c][l] = better ? int(qe[k][c][l]) : out.q[k][c][l];
      }
      for (int i = 0; i < 16; ++i) out.idx[i][l] = better ? int(idx[i][l]) : out.idx[i][l];
    }
  };
  float pbits[2][kLanes];
  if (pbit_pairs == 0xfu) {
    // Free p-bits: each endpoint takes the one that rounds it closer.
    for (int k = 0; k < 2; ++k) {
      for (int l = 0; l < kLanes; ++l) {
        float d[2] = {0, 0};
        for (int p = 0; p < 2; ++p) {
          for (int c = 0; c < NCH; ++c) {
            const float r = (e[k][c][l] - float(p)) * 0.5f + 0.5f;
            const float q0 = float(int(r < 0.0f ? 0.0f : r));
            const float q = q0 > 127.0f ? 127.0f : q0;
            const float diff = q * 2.0f + float(p) - e[k][c][l];
            d[p] += diff * diff;
          }
        }
        pbits[k][l] = d[1] < d[0] ? 1.0f : 0.0f;
      }
    }
    try_pbits(pbits);
  } else {
    for (int k = 0; k < 4; ++k) {
      if (!(pbit_pairs & (1u << k))) continue;
      for (int l = 0; l < kLanes; ++l) pbits[0][l] = float(k & 1), pbits[1][l] = float(k >> 1);
      try_pbits(pbits);
    }
  }

  // Least squares for the endpoints on the chosen indices; a refinement stands only where it
  // lowers the error (try_pbits compares), and a singular system keeps the previous endpoints.
  for (int it = 0; it < 2; ++it) {
    float aa[kLanes], bb[kLanes], ab[kLanes], ax[NCH][kLanes], bx[NCH][kLanes];
    for (int l = 0; l < kLanes; ++l) {
      aa[l] = bb[l] = ab[l] = 0;
      for (int c = 0; c < NCH; ++c) ax[c][l] = bx[c][l] = 0;
    }
    for (int i = 0; i < 16; ++i) {
      for (int l = 0; l < kLanes; ++l) {
        const float b = float(w[out.idx[i][l]]) * (1.0f / 64.0f), a = 1.0f - b;
        aa[l] += a * a, bb[l] += b * b, ab[l] += a * b;
        for (int c = 0; c < NCH; ++c) {
          ax[c][l] += a * x[c][i][l];
          bx[c][l] += b * x[c][i][l];
        }
      }
    }
    for (int l = 0; l < kLanes; ++l) {
      const float det = aa[l] * bb[l] - ab[l] * ab[l];
      const bool ok = std::fabs(det) > 1e-4f;
      const float inv = ok ? 1.0f / det : 0.0f;
      for (int c = 0; c < NCH; ++c) {
        const float e0 = clamp255((ax[c][l] * bb[l] - bx[c][l] * ab[l]) * inv);
        const float e1 = clamp255((bx[c][l] * aa[l] - ax[c][l] * ab[l]) * inv);
        e[0][c][l] = ok ? e0 : e[0][c][l];
        e[1][c][l] = ok ? e1 : e[1][c][l];
      }
    }
    // The refined endpoints keep the p-bits the block chose.
    for (int l = 0; l < kLanes; ++l)
      pbits[0][l] = float(out.p[0][l]), pbits[1][l] = float(out.p[1][l]);
    try_pbits(pbits);
  }
  if (NCH == 3) {
    for (int l = 0; l < kLanes; ++l) out.q[0][3][l] = out.q[1][3][l] = 127;
  }
}

// Writes lane l of `f` as a mode-6 block: the anchor texel (0) keeps its index's top bit 0 by
// swapping the endpoints where needed.
void pack_mode6(const Mode6Lanes& f, int l, uint8_t out[16]) {
  const bool swap = f.idx[0][l] > 7;
  const int a = swap ? 1 : 0, b = 1 - a;
  uint64_t lo = 1u << 6, hi = 0;
  int pos = 7;
  for (int c = 0; c < 4; ++c) {
    lo |= uint64_t(f.q[a][c][l]) << pos;
    lo |= uint64_t(f.q[b][c][l]) << (pos + 7);
    pos += 14;
  }
  lo |= uint64_t(f.p[a][l]) << 63;  // bit 63
  hi |= uint64_t(f.p[b][l]);        // bit 64
  hi |= uint64_t(swap ? 15 - f.idx[0][l] : f.idx[0][l]) << 1;
  for (int i = 1; i < 16; ++i) {
    hi |= uint64_t(swap ? 15 - f.idx[i][l] : f.idx[i][l]) << (4 + 4 * (i - 1));
  }
  for (int k = 0; k < 8; ++k) {
    out[k] = uint8_t(lo >> (8 * k));
    out[8 + k] = uint8_t(hi >> (8 * k));
  }
}

// Encodes the blocks listed in `which` (indices into rgba's blocks), kLanes at a time.
template <int NCH>
void encode_group(const uint8_t* rgba, const size_t* which, size_t n, unsigned pbit_pairs,
                  uint8_t* out) {
  static thread_local Mode6Lanes fit;
  for (size_t first = 0; first < n; first += kLanes) {
    const size_t lanes = std::min<size_t>(kLanes, n - first);
    uint32_t texels[16][kLanes];
    for (size_t l = 0; l < size_t(kLanes); ++l) {
      // Short batches repeat their last block: every lane computes something well defined.
      const uint8_t* block = rgba + which[first + std::min(l, lanes - 1)] * 64;
      for (int i = 0; i < 16; ++i) std::memcpy(&texels[i][l], block + 4 * i, 4);
    }
    fit_mode6_lanes<NCH>(texels, pbit_pairs, fit);
    for (size_t l = 0; l < lanes; ++l) pack_mode6(fit, int(l), out + which[first + l] * 16);
  }
}

}  // namespace

void bc7_encode_blocks_realtime(const uint8_t* rgba, size_t count, uint8_t* out,
                                bool ignore_alpha) {
  // Opaque blocks (or every block, when alpha is ignored) in RGB, the rest in RGBA.
  constexpr size_t kChunk = 256;
  size_t opaque[kChunk], translucent[kChunk];
  for (size_t first = 0; first < count; first += kChunk) {
    const size_t n = std::min(kChunk, count - first);
    size_t no = 0, nt = 0;
    for (size_t b = first; b < first + n; ++b) {
      bool has_alpha = false;
      for (int i = 0; i < 16 && !ignore_alpha; ++i) has_alpha |= rgba[b * 64 + 4 * i + 3] != 255;
      (has_alpha ? translucent[nt++] : opaque[no++]) = b;
    }
    encode_group<3>(rgba, opaque, no, ignore_alpha ? 0xfu : 0x8u, out);
    encode_group<4>(rgba, translucent, nt, 0xfu, out);
  }
}

}  // namespace vt
