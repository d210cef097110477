// BC7 encoder and decoder. Every candidate encoding is fitted per subset along the principal
// axis of its texels (power iteration), quantised with the best p-bits, refined by least
// squares on the chosen indices, and scored by the exact error of its decoded palette; the
// block keeps the candidate with the smallest squared RGBA error.
// Tables: the partition, anchor and weight tables of the BC7 format (Khronos Data Format
// Specification, "BPTC"; identical to the Direct3D 11 BC7 tables).
#include "codec/bc7.h"

#include "codec/bptc_tables.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace vt {
namespace {

using bptc::kAnchor2;
using bptc::kPartition2;
using bptc::weights;

struct ModeInfo {
  int subsets, partition_bits, rotation_bits, index_sel_bits, colour_bits, alpha_bits;
  int endpoint_pbits, shared_pbits, index_bits, index2_bits;
};

constexpr ModeInfo kModes[8] = {
    {3, 4, 0, 0, 4, 0, 1, 0, 3, 0}, {2, 6, 0, 0, 6, 0, 0, 1, 3, 0}, {3, 6, 0, 0, 5, 0, 0, 0, 2, 0},
    {2, 6, 0, 0, 7, 0, 1, 0, 2, 0}, {1, 0, 2, 1, 5, 6, 0, 0, 2, 3}, {1, 0, 2, 0, 7, 8, 0, 0, 2, 2},
    {1, 0, 0, 0, 7, 7, 1, 0, 4, 0}, {2, 6, 0, 0, 5, 5, 1, 0, 2, 0},
};

// Three subsets: bits 2i..2i+1 give the subset of texel i.
constexpr uint32_t kPartition3[64] = {
    0xaa685050, 0x6a5a5040, 0x5a5a4200, 0x5450a0a8, 0xa5a50000, 0xa0a05050, 0x5555a0a0, 0x5a5a5050,
    0xaa550000, 0xaa555500, 0xaaaa5500, 0x90909090, 0x94949494, 0xa4a4a4a4, 0xa9a59450, 0x2a0a4250,
    0xa5945040, 0x0a425054, 0xa5a5a500, 0x55a0a0a0, 0xa8a85454, 0x6a6a4040, 0xa4a45000, 0x1a1a0500,
    0x0050a4a4, 0xaaa59090, 0x14696914, 0x69691400, 0xa08585a0, 0xaa821414, 0x50a4a450, 0x6a5a0200,
    0xa9a58000, 0x5090a0a8, 0xa8a09050, 0x24242424, 0x00aa5500, 0x24924924, 0x24499224, 0x50a50a50,
    0x500aa550, 0xaaaa4444, 0x66660000, 0xa5a0a5a0, 0x50a050a0, 0x69286928, 0x44aaaa44, 0x66666600,
    0xaa444444, 0x54a854a8, 0x95809580, 0x96969600, 0xa85454a8, 0x80959580, 0xaa141414, 0x96960000,
    0xaaaa1414, 0xa05050a0, 0xa0a5a5a0, 0x96000000, 0x40804080, 0xa9a8a9a8, 0xaaaaaa44, 0x2a4a5254};

// Anchor texels of subsets 1 and 2 (three subsets); two subsets: bptc::kAnchor2.
constexpr uint8_t kAnchor3a[64] = {3, 3,  15, 15, 8, 3,  15, 15, 8,  8,  6,  6,  6,  5,  3,  3,
                                   3, 3,  8,  15, 3, 3,  6,  10, 5,  8,  8,  6,  8,  5,  15, 15,
                                   8, 15, 3,  5,  6, 10, 8,  15, 15, 3,  15, 5,  15, 15, 15, 15,
                                   3, 15, 5,  5,  5, 8,  5,  10, 5,  10, 8,  13, 15, 12, 3,  3};
constexpr uint8_t kAnchor3b[64] = {15, 8, 8,  3,  15, 15, 3,  8,  15, 15, 15, 15, 15, 15, 15, 8,
                                   15, 8, 15, 3,  15, 8,  15, 8,  3,  15, 6,  10, 15, 15, 10, 8,
                                   15, 3, 15, 10, 10, 8,  9,  10, 6,  15, 8,  15, 3,  6,  6,  8,
                                   15, 3, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 3,  15, 15, 8};

inline int subset_of(int subsets, int partition, int texel) {
  if (subsets == 2) return (kPartition2[partition] >> texel) & 1;
  if (subsets == 3) return (kPartition3[partition] >> (2 * texel)) & 3;
  return 0;
}

inline int anchor_of(int subsets, int partition, int subset) {
  if (subset == 0) return 0;
  if (subsets == 2) return kAnchor2[partition];
  return subset == 1 ? kAnchor3a[partition] : kAnchor3b[partition];
}

// Expands a `bits`-bit endpoint value (p-bit included) to 8 bits by replication.
inline int expand(int v, int bits) {
  return bits >= 8 ? v : (v << (8 - bits)) | (v >> (2 * bits - 8));
}

struct BitReader {
  const uint8_t* data;
  int pos = 0;
  int read(int n) {
    int v = 0;
    for (int i = 0; i < n; ++i, ++pos) v |= ((data[pos >> 3] >> (pos & 7)) & 1) << i;
    return v;
  }
};

struct BitWriter {
  uint8_t* data;
  int pos = 0;
  void write(int v, int n) {
    for (int i = 0; i < n; ++i, ++pos) {
      if ((v >> i) & 1) data[pos >> 3] |= uint8_t(1 << (pos & 7));
    }
  }
};

// ---------------------------------------------------------------------------------------------
// Encoder

// One block's texels, channel-major, as floats.
struct Texels {
  float c[4][16];
};

enum class PbitMode { kNone, kPerEndpoint, kShared };

struct FitParams {
  int bits;  // stored bits per channel, p-bit excluded
  PbitMode pbits;
  int index_bits;
  int ch0, nch;    // fitted channels: [ch0, ch0 + nch)
  int refine;      // least-squares iterations
  bool all_pbits;  // score every p-bit combination instead of choosing them per endpoint
};

struct SubsetFit {
  int q[2][4] = {};      // stored endpoint values per channel (p-bit excluded)
  int p[2] = {0, 0};     // p-bits
  int u[2][4] = {};      // endpoints expanded to 8 bits
  uint8_t idx[16] = {};  // per member texel
  float err = 1e30f;
};

inline int quantise_channel(float x, int bits, int p) {
  const int maxq = (1 << bits) - 1;
  const int total = p < 0 ? bits : bits + 1;
  const int scale = (1 << total) - 1;
  int q = p < 0 ? int(x * float(scale) / 255.0f + 0.5f)
                : int((x * float(scale) / 255.0f - float(p)) * 0.5f + 0.5f);
  q = std::clamp(q, 0, maxq);
  // The rounding above ignores the replication of high bits; check the neighbours.
  int best = q;
  float best_d = 1e30f;
  for (int c = std::max(0, q - 1); c <= std::min(maxq, q + 1); ++c) {
    const int u = expand(p < 0 ? c : (c << 1) | p, total);
    const float d = std::fabs(float(u) - x);
    if (d < best_d) best_d = d, best = c;
  }
  return best;
}

inline int unquantise(int q, int bits, int p) {
  return p < 0 ? expand(q, bits) : expand((q << 1) | p, bits + 1);
}

// Quantises float endpoints e[2][4] with given p-bits (-1: none) into `fit`.
void quantise_endpoints(const float e[2][4], const int p[2], const FitParams& fp, SubsetFit& fit) {
  for (int k = 0; k < 2; ++k) {
    fit.p[k] = p[k] < 0 ? 0 : p[k];
    for (int c = fp.ch0; c < fp.ch0 + fp.nch; ++c) {
      fit.q[k][c] = quantise_channel(e[k][c], fp.bits, p[k]);
      fit.u[k][c] = unquantise(fit.q[k][c], fp.bits, p[k]);
    }
  }
}

// Squared error of quantising both endpoints with p-bits p.
float endpoint_error(const float e[2][4], int k, int p, const FitParams& fp) {
  float err = 0;
  for (int c = fp.ch0; c < fp.ch0 + fp.nch; ++c) {
    const float d = float(unquantise(quantise_channel(e[k][c], fp.bits, p), fp.bits, p)) - e[k][c];
    err += d * d;
  }
  return err;
}

// Nearest palette entry per member texel; returns the squared error over the fitted channels.
float select_indices(const Texels& t, const int* members, int n, const FitParams& fp,
                     SubsetFit& fit) {
  const int entries = 1 << fp.index_bits;
  const int* w = weights(fp.index_bits);
  float pal[16][4];
  for (int k = 0; k < entries; ++k) {
    for (int c = fp.ch0; c < fp.ch0 + fp.nch; ++c) {
      pal[k][c] = float(((64 - w[k]) * fit.u[0][c] + w[k] * fit.u[1][c] + 32) >> 6);
    }
  }
  // Project onto the endpoint line for a first guess, then test its neighbours exactly: the
  // weights are near-uniform, so the nearest entry is within one step of the guess.
  float dir[4] = {0, 0, 0, 0}, dd = 0;
  for (int c = fp.ch0; c < fp.ch0 + fp.nch; ++c) {
    dir[c] = float(fit.u[1][c] - fit.u[0][c]);
    dd += dir[c] * dir[c];
  }
  const float scale = dd > 0 ? float(entries - 1) / dd : 0.0f;
  float total = 0;
  for (int m = 0; m < n; ++m) {
    const int i = members[m];
    float proj = 0;
    for (int c = fp.ch0; c < fp.ch0 + fp.nch; ++c)
      proj += (t.c[c][i] - float(fit.u[0][c])) * dir[c];
    const int guess = std::clamp(int(proj * scale + 0.5f), 0, entries - 1);
    float best = 1e30f;
    int bk = 0;
    for (int k = std::max(0, guess - 1); k <= std::min(entries - 1, guess + 1); ++k) {
      float d = 0;
      for (int c = fp.ch0; c < fp.ch0 + fp.nch; ++c) {
        const float x = t.c[c][i] - pal[k][c];
        d += x * x;
      }
      if (d < best) best = d, bk = k;
    }
    fit.idx[m] = uint8_t(bk);
    total += best;
  }
  fit.err = total;
  return total;
}

// Quantises with the p-bits chosen (or all tried), then selects indices; keeps the best in fit.
void quantise_and_select(const Texels& t, const int* members, int n, const float e[2][4],
                         const FitParams& fp, SubsetFit& best) {
  auto try_pbits = [&](int p0, int p1) {
    SubsetFit f;
    const int p[2] = {p0, p1};
    quantise_endpoints(e, p, fp, f);
    select_indices(t, members, n, fp, f);
    if (f.err < best.err) best = f;
  };
  if (fp.pbits == PbitMode::kNone) {
    try_pbits(-1, -1);
  } else if (fp.all_pbits) {
    for (int p = 0; p < 4; ++p) {
      if (fp.pbits == PbitMode::kShared && (p & 1) != (p >> 1)) continue;
      try_pbits(p & 1, p >> 1);
    }
  } else if (fp.pbits == PbitMode::kShared) {
    const float e0 = endpoint_error(e, 0, 0, fp) + endpoint_error(e, 1, 0, fp);
    const float e1 = endpoint_error(e, 0, 1, fp) + endpoint_error(e, 1, 1, fp);
    const int p = e1 < e0 ? 1 : 0;
    try_pbits(p, p);
  } else {
    const int p0 = endpoint_error(e, 0, 1, fp) < endpoint_error(e, 0, 0, fp) ? 1 : 0;
    const int p1 = endpoint_error(e, 1, 1, fp) < endpoint_error(e, 1, 0, fp) ? 1 : 0;
    try_pbits(p0, p1);
  }
}

// Fits one subset's endpoints and indices.
SubsetFit fit_subset(const Texels& t, const int* members, int n, const FitParams& fp) {
  float mean[4] = {0, 0, 0, 0};
  for (int m = 0; m < n; ++m) {
    for (int c = fp.ch0; c < fp.ch0 + fp.nch; ++c) mean[c] += t.c[c][members[m]];
  }
  const float inv_n = 1.0f / float(std::max(n, 1));
  for (float& v : mean) v *= inv_n;

  float cov[4][4] = {};
  for (int m = 0; m < n; ++m) {
    float d[4] = {0, 0, 0, 0};
    for (int c = fp.ch0; c < fp.ch0 + fp.nch; ++c) d[c] = t.c[c][members[m]] - mean[c];
    for (int a = 0; a < 4; ++a) {
      for (int b = a; b < 4; ++b) cov[a][b] += d[a] * d[b];
    }
  }
  for (int a = 0; a < 4; ++a) {
    for (int b = 0; b < a; ++b) cov[a][b] = cov[b][a];
  }
  // Power iteration from the row of the widest channel.
  int widest = fp.ch0;
  for (int c = fp.ch0; c < fp.ch0 + fp.nch; ++c) {
    if (cov[c][c] > cov[widest][widest]) widest = c;
  }
  float v[4] = {cov[widest][0], cov[widest][1], cov[widest][2], cov[widest][3]};
  for (int it = 0; it < 6; ++it) {
    float nv[4] = {0, 0, 0, 0};
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) nv[a] += cov[a][b] * v[b];
    }
    float mx = 0;
    for (float x : nv) mx = std::max(mx, std::fabs(x));
    if (!(mx > 1e-12f)) break;
    for (int a = 0; a < 4; ++a) v[a] = nv[a] / mx;
  }
  float len2 = 0;
  for (float x : v) len2 += x * x;
  if (!(len2 > 1e-12f)) {
    for (int c = 0; c < 4; ++c) v[c] = (c >= fp.ch0 && c < fp.ch0 + fp.nch) ? 1.0f : 0.0f;
    len2 = float(fp.nch);
  }
  const float inv_len = 1.0f / std::sqrt(len2);
  for (float& x : v) x *= inv_len;

  float tmin = 0, tmax = 0;
  for (int m = 0; m < n; ++m) {
    float s = 0;
    for (int c = fp.ch0; c < fp.ch0 + fp.nch; ++c) s += (t.c[c][members[m]] - mean[c]) * v[c];
    tmin = std::min(tmin, s);
    tmax = std::max(tmax, s);
  }
  float e[2][4] = {};
  for (int c = fp.ch0; c < fp.ch0 + fp.nch; ++c) {
    e[0][c] = std::clamp(mean[c] + tmin * v[c], 0.0f, 255.0f);
    e[1][c] = std::clamp(mean[c] + tmax * v[c], 0.0f, 255.0f);
  }
  SubsetFit best;
  quantise_and_select(t, members, n, e, fp, best);

  const int* w = weights(fp.index_bits);
  for (int it = 0; it < fp.refine && best.err > 0; ++it) {
    float aa = 0, bb = 0, ab = 0, ax[4] = {0, 0, 0, 0}, bx[4] = {0, 0, 0, 0};
    for (int m = 0; m < n; ++m) {
      const float b = float(w[best.idx[m]]) / 64.0f, a = 1.0f - b;
      aa += a * a, bb += b * b, ab += a * b;
      for (int c = fp.ch0; c < fp.ch0 + fp.nch; ++c) {
        ax[c] += a * t.c[c][members[m]];
        bx[c] += b * t.c[c][members[m]];
      }
    }
    const float det = aa * bb - ab * ab;
    if (!(std::fabs(det) > 1e-4f)) break;
    const float inv = 1.0f / det;
    for (int c = fp.ch0; c < fp.ch0 + fp.nch; ++c) {
      e[0][c] = std::clamp((ax[c] * bb - bx[c] * ab) * inv, 0.0f, 255.0f);
      e[1][c] = std::clamp((bx[c] * aa - ax[c] * ab) * inv, 0.0f, 255.0f);
    }
    const float before = best.err;
    quantise_and_select(t, members, n, e, fp, best);
    if (!(best.err < before)) break;
  }
  return best;
}

struct Encoded {
  uint8_t bytes[16] = {};
  float err = 1e30f;
};

// Packs a mode with one index set (modes 0-3, 6, 7).
void pack_single_index(int mode, int partition, SubsetFit fits[3], uint8_t out[16]) {
  const ModeInfo& mi = kModes[mode];
  const int max_index = (1 << mi.index_bits) - 1;
  int idx[16];
  int cursor[3] = {0, 0, 0};
  for (int i = 0; i < 16; ++i) {
    const int s = subset_of(mi.subsets, partition, i);
    idx[i] = fits[s].idx[cursor[s]++];
  }
  // The anchor texel of every subset stores its index's top bit implicitly as 0.
  for (int s = 0; s < mi.subsets; ++s) {
    if (idx[anchor_of(mi.subsets, partition, s)] <= max_index / 2) continue;
    std::swap(fits[s].q[0], fits[s].q[1]);
    std::swap(fits[s].p[0], fits[s].p[1]);
    for (int i = 0; i < 16; ++i) {
      if (subset_of(mi.subsets, partition, i) == s) idx[i] = max_index - idx[i];
    }
  }
  std::memset(out, 0, 16);
  BitWriter w{out};
  w.write(1 << mode, mode + 1);
  w.write(partition, mi.partition_bits);
  const int channels = mi.alpha_bits ? 4 : 3;
  for (int c = 0; c < channels; ++c) {
    const int bits = c == 3 ? mi.alpha_bits : mi.colour_bits;
    for (int s = 0; s < mi.subsets; ++s) {
      w.write(fits[s].q[0][c], bits);
      w.write(fits[s].q[1][c], bits);
    }
  }
  for (int s = 0; s < mi.subsets; ++s) {
    if (mi.endpoint_pbits) {
      w.write(fits[s].p[0], 1);
      w.write(fits[s].p[1], 1);
    } else if (mi.shared_pbits) {
      w.write(fits[s].p[0], 1);
    }
  }
  for (int i = 0; i < 16; ++i) {
    const bool anchor = i == 0 || (mi.subsets >= 2 && i == anchor_of(mi.subsets, partition, 1)) ||
                        (mi.subsets == 3 && i == anchor_of(mi.subsets, partition, 2));
    w.write(idx[i], mi.index_bits - (anchor ? 1 : 0));
  }
}

float opaque_alpha_error(const Texels& t) {
  float err = 0;
  for (int i = 0; i < 16; ++i) {
    const float d = 255.0f - t.c[3][i];
    err += d * d;
  }
  return err;
}

// Modes 0-3, 6, 7 for one partition.
Encoded encode_partitioned(const Texels& t, int mode, int partition, int refine, bool all_pbits,
                           float alpha_err, bool ignore_alpha) {
  const ModeInfo& mi = kModes[mode];
  FitParams fp;
  fp.bits = mi.colour_bits;  // modes 6 and 7 have equal colour and alpha bits
  fp.pbits = mi.endpoint_pbits ? PbitMode::kPerEndpoint
             : mi.shared_pbits ? PbitMode::kShared
                               : PbitMode::kNone;
  fp.index_bits = mi.index_bits;
  fp.ch0 = 0;
  fp.nch = mi.alpha_bits && !ignore_alpha ? 4 : 3;
  fp.refine = refine;
  fp.all_pbits = all_pbits;
  int members[3][16], count[3] = {0, 0, 0};
  for (int i = 0; i < 16; ++i) {
    const int s = subset_of(mi.subsets, partition, i);
    members[s][count[s]++] = i;
  }
  SubsetFit fits[3];
  Encoded e;
  e.err = mi.alpha_bits ? 0.0f : alpha_err;
  for (int s = 0; s < mi.subsets; ++s) {
    fits[s] = fit_subset(t, members[s], count[s], fp);
    e.err += fits[s].err;
    if (fp.nch == 3 && mi.alpha_bits) {
      fits[s].q[0][3] = fits[s].q[1][3] = (1 << mi.alpha_bits) - 1;  // unused alpha: opaque-ish
    }
  }
  pack_single_index(mode, partition, fits, e.bytes);
  return e;
}

// Modes 4 and 5: colour and a scalar channel fitted apart, with a channel rotation.
Encoded encode_rotated(const Texels& src, int mode, int rotation, int index_sel, int refine) {
  const ModeInfo& mi = kModes[mode];
  Texels t = src;
  if (rotation) std::swap(t.c[rotation - 1], t.c[3]);
  const int colour_index_bits = index_sel ? mi.index2_bits : mi.index_bits;
  const int alpha_index_bits = index_sel ? mi.index_bits : mi.index2_bits;
  int all[16];
  for (int i = 0; i < 16; ++i) all[i] = i;
  FitParams fc{mi.colour_bits, PbitMode::kNone, colour_index_bits, 0, 3, refine, false};
  FitParams fa{mi.alpha_bits, PbitMode::kNone, alpha_index_bits, 3, 1, refine, false};
  SubsetFit colour = fit_subset(t, all, 16, fc);
  SubsetFit alpha = fit_subset(t, all, 16, fa);
  Encoded e;
  e.err = colour.err + alpha.err;

  // Anchor texel 0 of each index set stores its top bit implicitly as 0.
  const int cmax = (1 << colour_index_bits) - 1, amax = (1 << alpha_index_bits) - 1;
  if (colour.idx[0] > cmax / 2) {
    std::swap(colour.q[0], colour.q[1]);
    for (uint8_t& i : colour.idx) i = uint8_t(cmax - i);
  }
  if (alpha.idx[0] > amax / 2) {
    std::swap(alpha.q[0], alpha.q[1]);
    for (uint8_t& i : alpha.idx) i = uint8_t(amax - i);
  }
  std::memset(e.bytes, 0, 16);
  BitWriter w{e.bytes};
  w.write(1 << mode, mode + 1);
  w.write(rotation, 2);
  if (mi.index_sel_bits) w.write(index_sel, 1);
  for (int c = 0; c < 3; ++c) {
    w.write(colour.q[0][c], mi.colour_bits);
    w.write(colour.q[1][c], mi.colour_bits);
  }
  w.write(alpha.q[0][3], mi.alpha_bits);
  w.write(alpha.q[1][3], mi.alpha_bits);
  // The first index set has index_bits per texel, the second index2_bits.
  const uint8_t* first = index_sel ? alpha.idx : colour.idx;
  const uint8_t* second = index_sel ? colour.idx : alpha.idx;
  for (int i = 0; i < 16; ++i) w.write(first[i], mi.index_bits - (i == 0 ? 1 : 0));
  for (int i = 0; i < 16; ++i) w.write(second[i], mi.index2_bits - (i == 0 ? 1 : 0));
  return e;
}

// Ranks partitions by the residual of a straight-line fit per subset (the variance off each
// subset's principal axis): cheap, and close to what the quantised fit achieves.
void rank_partitions(const Texels& t, int subsets, int count, int nch, int* order, int keep) {
  float score[64];
  for (int p = 0; p < count; ++p) {
    float total = 0;
    for (int s = 0; s < subsets; ++s) {
      float sum[4] = {0, 0, 0, 0}, sq[4][4] = {};
      int n = 0;
      for (int i = 0; i < 16; ++i) {
        if (subset_of(subsets, p, i) != s) continue;
        ++n;
        for (int a = 0; a < nch; ++a) {
          sum[a] += t.c[a][i];
          for (int b = a; b < nch; ++b) sq[a][b] += t.c[a][i] * t.c[b][i];
        }
      }
      if (n < 2) continue;
      float cov[4][4] = {};
      float trace = 0;
      for (int a = 0; a < nch; ++a) {
        for (int b = a; b < nch; ++b) {
          cov[a][b] = cov[b][a] = sq[a][b] - sum[a] * sum[b] / float(n);
        }
        trace += cov[a][a];
      }
      float v[4] = {1, 1, 1, 1};
      float lambda = 0;
      for (int it = 0; it < 4; ++it) {
        float nv[4] = {0, 0, 0, 0};
        for (int a = 0; a < nch; ++a) {
          for (int b = 0; b < nch; ++b) nv[a] += cov[a][b] * v[b];
        }
        float mx = 0;
        for (int a = 0; a < nch; ++a) mx = std::max(mx, std::fabs(nv[a]));
        if (!(mx > 1e-9f)) break;
        for (int a = 0; a < nch; ++a) v[a] = nv[a] / mx;
        lambda = mx;
      }
      // Rayleigh quotient of the final vector: the variance along the axis.
      float num = 0, den = 0;
      for (int a = 0; a < nch; ++a) {
        float cv = 0;
        for (int b = 0; b < nch; ++b) cv += cov[a][b] * v[b];
        num += v[a] * cv;
        den += v[a] * v[a];
      }
      lambda = den > 0 ? num / den : 0;
      total += std::max(0.0f, trace - lambda);
    }
    score[p] = total;
  }
  int ids[64];
  for (int p = 0; p < count; ++p) ids[p] = p;
  std::partial_sort(ids, ids + keep, ids + count, [&](int a, int b) {
    return score[a] < score[b] || (score[a] == score[b] && a < b);
  });
  for (int k = 0; k < keep; ++k) order[k] = ids[k];
}

}  // namespace

void bc7_encode_block(const uint8_t rgba[64], BcQuality quality, uint8_t out[16],
                      bool ignore_alpha) {
  if (quality == BcQuality::kRealtime) {
    bc7_encode_blocks_realtime(rgba, 1, out, ignore_alpha);
    return;
  }
  Texels t;
  bool has_alpha = false;
  for (int i = 0; i < 16; ++i) {
    for (int c = 0; c < 4; ++c) t.c[c][i] = float(rgba[4 * i + c]);
    has_alpha |= rgba[4 * i + 3] != 255;
  }
  if (ignore_alpha) {
    has_alpha = false;
    for (int i = 0; i < 16; ++i) t.c[3][i] = 255.0f;
  }
  const bool high = quality == BcQuality::kHigh;
  const int refine = high ? 4 : 2;
  const float alpha_err = opaque_alpha_error(t);
  const bool ig = ignore_alpha;

  Encoded best = encode_partitioned(t, 6, 0, refine, true, alpha_err, ig);
  auto consider = [&](const Encoded& e) {
    if (e.err < best.err) best = e;
  };
  if (has_alpha) consider(encode_rotated(t, 5, 0, 0, refine));
  if (best.err > 0) {
    const int keep2 = high ? 16 : 3;
    int order[64];
    if (has_alpha) {
      rank_partitions(t, 2, 64, 4, order, keep2);
      for (int k = 0; k < keep2; ++k)
        consider(encode_partitioned(t, 7, order[k], refine, high, 0, false));
      consider(encode_rotated(t, 4, 0, 0, refine));
    } else {
      rank_partitions(t, 2, 64, 3, order, keep2);
      for (int k = 0; k < keep2; ++k) {
        consider(encode_partitioned(t, 1, order[k], refine, high, alpha_err, ig));
        consider(encode_partitioned(t, 3, order[k], refine, high, alpha_err, ig));
      }
    }
    if (high) {
      // Rotations put the least correlated channel on its own indices.
      for (int rot = has_alpha ? 0 : 1; rot < 4; ++rot) {
        consider(encode_rotated(t, 5, rot, 0, refine));
        for (int sel = 0; sel < 2; ++sel) consider(encode_rotated(t, 4, rot, sel, refine));
      }
      if (!has_alpha) {
        const int keep3 = 8;
        rank_partitions(t, 3, 64, 3, order, keep3);
        for (int k = 0; k < keep3; ++k) {
          consider(encode_partitioned(t, 2, order[k], refine, true, alpha_err, ig));
        }
        rank_partitions(t, 3, 16, 3, order, keep3);
        for (int k = 0; k < keep3; ++k) {
          consider(encode_partitioned(t, 0, order[k], refine, true, alpha_err, ig));
        }
      }
    }
  }
  std::memcpy(out, best.bytes, 16);
}

int bc7_block_mode(const uint8_t block[16]) {
  for (int m = 0; m < 8; ++m) {
    if (block[0] & (1 << m)) return m;
  }
  return 8;
}

void bc7_decode_block(const uint8_t block[16], uint8_t rgba[64]) {
  const int mode = bc7_block_mode(block);
  if (mode == 8) {
    std::memset(rgba, 0, 64);
    return;
  }
  const ModeInfo& mi = kModes[mode];
  BitReader r{block, mode + 1};
  const int partition = r.read(mi.partition_bits);
  const int rotation = r.read(mi.rotation_bits);
  const int index_sel = r.read(mi.index_sel_bits);
  int ep[6][4];
  const int n = mi.subsets * 2;
  for (int c = 0; c < 3; ++c) {
    for (int k = 0; k < n; ++k) ep[k][c] = r.read(mi.colour_bits);
  }
  for (int k = 0; k < n; ++k) ep[k][3] = mi.alpha_bits ? r.read(mi.alpha_bits) : 255;
  int cbits = mi.colour_bits, abits = mi.alpha_bits;
  if (mi.endpoint_pbits || mi.shared_pbits) {
    int p = 0;
    for (int k = 0; k < n; ++k) {
      // Shared p-bits: one per subset, for both of its endpoints.
      if (mi.endpoint_pbits || (k & 1) == 0) p = r.read(1);
      for (int c = 0; c < 3; ++c) ep[k][c] = (ep[k][c] << 1) | p;
      if (mi.alpha_bits) ep[k][3] = (ep[k][3] << 1) | p;
    }
    ++cbits;
    if (abits) ++abits;
  }
  for (int k = 0; k < n; ++k) {
    for (int c = 0; c < 3; ++c) ep[k][c] = expand(ep[k][c], cbits);
    if (abits) ep[k][3] = expand(ep[k][3], abits);
  }
  const int* cw = weights(mi.index_bits);
  int index1[16], index2[16];
  for (int i = 0; i < 16; ++i) {
    const bool anchor = i == 0 || (mi.subsets >= 2 && i == anchor_of(mi.subsets, partition, 1)) ||
                        (mi.subsets == 3 && i == anchor_of(mi.subsets, partition, 2));
    index1[i] = r.read(mi.index_bits - (anchor ? 1 : 0));
  }
  if (mi.index2_bits) {
    for (int i = 0; i < 16; ++i) index2[i] = r.read(mi.index2_bits - (i == 0 ? 1 : 0));
  }
  for (int i = 0; i < 16; ++i) {
    const int s = subset_of(mi.subsets, partition, i);
    const int* e0 = ep[2 * s];
    const int* e1 = ep[2 * s + 1];
    int wc, wa;
    if (mi.index2_bits) {
      const int* aw = weights(mi.index2_bits);
      wc = index_sel ? aw[index2[i]] : cw[index1[i]];
      wa = index_sel ? cw[index1[i]] : aw[index2[i]];
    } else {
      wc = wa = cw[index1[i]];
    }
    uint8_t px[4];
    for (int c = 0; c < 3; ++c) px[c] = uint8_t(((64 - wc) * e0[c] + wc * e1[c] + 32) >> 6);
    px[3] = uint8_t(((64 - wa) * e0[3] + wa * e1[3] + 32) >> 6);
    if (rotation) std::swap(px[rotation - 1], px[3]);
    std::memcpy(rgba + 4 * i, px, 4);
  }
}

}  // namespace vt
