// BC6H encoder and decoder (see bc6h.h). The bit layout of each mode is written below as the
// Khronos and Direct3D specifications list it, one field per token, and turned into a bit table
// once; decoder and encoder both read that one table.
//
// Names: endpoints w, x (region 0) and y, z (region 1), channels r, g, b; "gy[4]" is bit 4 of
// the green channel of endpoint y; "rw[9:0]" is bits 0..9, stored lowest first; "rw[10:15]" is
// bits 15 down to 10, stored highest first (modes 13 and 14 store their base's top bits
// reversed); "d" is the partition number.
#include "codec/bc6h.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "codec/bptc_tables.h"
#include "common/target_clones.h"

namespace vt {
namespace {

struct ModeDesc {
  uint8_t value;      // the mode bits as stored (low bits of the block)
  uint8_t mode_bits;  // 2 or 5
  uint8_t regions;    // 1 or 2
  bool transformed;   // x, y, z stored as deltas from w
  uint8_t endpoint_bits;
  uint8_t delta_bits[3];  // per channel; = endpoint_bits when not transformed
  const char* layout;
};

// Direct3D modes 1..14 in order (index = mode number - 1).
constexpr ModeDesc kModes[14] = {
    {0x00,
     2,
     2,
     true,
     10,
     {5, 5, 5},
     "gy[4] by[4] bz[4] rw[9:0] gw[9:0] bw[9:0] rx[4:0] gz[4] gy[3:0] gx[4:0] bz[0] gz[3:0] "
     "bx[4:0] bz[1] by[3:0] ry[4:0] bz[2] rz[4:0] bz[3] d[4:0]"},
    {0x01,
     2,
     2,
     true,
     7,
     {6, 6, 6},
     "gy[5] gz[4] gz[5] rw[6:0] bz[0] bz[1] by[4] gw[6:0] by[5] bz[2] gy[4] bw[6:0] bz[3] bz[5] "
     "bz[4] rx[5:0] gy[3:0] gx[5:0] gz[3:0] bx[5:0] by[3:0] ry[5:0] rz[5:0] d[4:0]"},
    {0x02,
     5,
     2,
     true,
     11,
     {5, 4, 4},
     "rw[9:0] gw[9:0] bw[9:0] rx[4:0] rw[10] gy[3:0] gx[3:0] gw[10] bz[0] gz[3:0] bx[3:0] bw[10] "
     "bz[1] by[3:0] ry[4:0] bz[2] rz[4:0] bz[3] d[4:0]"},
    {0x06,
     5,
     2,
     true,
     11,
     {4, 5, 4},
     "rw[9:0] gw[9:0] bw[9:0] rx[3:0] rw[10] gz[4] gy[3:0] gx[4:0] gw[10] gz[3:0] bx[3:0] bw[10] "
     "bz[1] by[3:0] ry[3:0] bz[0] bz[2] rz[3:0] gy[4] bz[3] d[4:0]"},
    {0x0a,
     5,
     2,
     true,
     11,
     {4, 4, 5},
     "rw[9:0] gw[9:0] bw[9:0] rx[3:0] rw[10] by[4] gy[3:0] gx[3:0] gw[10] bz[0] gz[3:0] bx[4:0] "
     "bw[10] by[3:0] ry[3:0] bz[1] bz[2] rz[3:0] bz[4] bz[3] d[4:0]"},
    {0x0e,
     5,
     2,
     true,
     9,
     {5, 5, 5},
     "rw[8:0] by[4] gw[8:0] gy[4] bw[8:0] bz[4] rx[4:0] gz[4] gy[3:0] gx[4:0] bz[0] gz[3:0] "
     "bx[4:0] bz[1] by[3:0] ry[4:0] bz[2] rz[4:0] bz[3] d[4:0]"},
    {0x12,
     5,
     2,
     true,
     8,
     {6, 5, 5},
     "rw[7:0] gz[4] by[4] gw[7:0] bz[2] gy[4] bw[7:0] bz[3] bz[4] rx[5:0] gy[3:0] gx[4:0] bz[0] "
     "gz[3:0] bx[4:0] bz[1] by[3:0] ry[5:0] rz[5:0] d[4:0]"},
    {0x16,
     5,
     2,
     true,
     8,
     {5, 6, 5},
     "rw[7:0] bz[0] by[4] gw[7:0] gy[5] gy[4] bw[7:0] gz[5] bz[4] rx[4:0] gz[4] gy[3:0] gx[5:0] "
     "gz[3:0] bx[4:0] bz[1] by[3:0] ry[4:0] bz[2] rz[4:0] bz[3] d[4:0]"},
    {0x1a,
     5,
     2,
     true,
     8,
     {5, 5, 6},
     "rw[7:0] bz[1] by[4] gw[7:0] by[5] gy[4] bw[7:0] bz[5] bz[4] rx[4:0] gz[4] gy[3:0] gx[4:0] "
     "bz[0] gz[3:0] bx[5:0] by[3:0] ry[4:0] bz[2] rz[4:0] bz[3] d[4:0]"},
    {0x1e,
     5,
     2,
     false,
     6,
     {6, 6, 6},
     "rw[5:0] gz[4] bz[0] bz[1] by[4] gw[5:0] gy[5] by[5] bz[2] gy[4] bw[5:0] gz[5] bz[3] bz[5] "
     "bz[4] rx[5:0] gy[3:0] gx[5:0] gz[3:0] bx[5:0] by[3:0] ry[5:0] rz[5:0] d[4:0]"},
    {0x03, 5, 1, false, 10, {10, 10, 10}, "rw[9:0] gw[9:0] bw[9:0] rx[9:0] gx[9:0] bx[9:0]"},
    {0x07,
     5,
     1,
     true,
     11,
     {9, 9, 9},
     "rw[9:0] gw[9:0] bw[9:0] rx[8:0] rw[10] gx[8:0] gw[10] bx[8:0] bw[10]"},
    {0x0b,
     5,
     1,
     true,
     12,
     {8, 8, 8},
     "rw[9:0] gw[9:0] bw[9:0] rx[7:0] rw[10:11] gx[7:0] gw[10:11] bx[7:0] bw[10:11]"},
    {0x0f,
     5,
     1,
     true,
     16,
     {4, 4, 4},
     "rw[9:0] gw[9:0] bw[9:0] rx[3:0] rw[10:15] gx[3:0] gw[10:15] bx[3:0] bw[10:15]"},
};

constexpr int kPartitionField = 12;  // field number of "d"; endpoint e channel c is e * 3 + c

// One mode's header bits after the mode bits: field and bit number of each, in stored order.
struct Run {
  uint8_t field, first, count;  // bits first, first +- 1, ... of the field
  bool ascending;
};
struct Layout {
  int count = 0;
  uint8_t field[82] = {};
  uint8_t bit[82] = {};
  int runs = 0;  // the same bits grouped into runs of one field, for the encoder
  Run run[82] = {};
};

std::array<Layout, 14> build_layouts() {
  std::array<Layout, 14> out{};
  for (int m = 0; m < 14; ++m) {
    Layout& l = out[size_t(m)];
    const std::string s = kModes[m].layout;
    size_t i = 0;
    while (i < s.size()) {
      if (s[i] == ' ') {
        ++i;
        continue;
      }
      int field;
      if (s[i] == 'd') {
        field = kPartitionField;
        i += 1;
      } else {
        const int c = s[i] == 'r' ? 0 : s[i] == 'g' ? 1 : 2;
        const int e = s[i + 1] - 'w';  // w x y z -> 0 1 2 3
        field = e * 3 + c;
        i += 2;
      }
      // "[a]" or "[a:b]": stored from b toward a.
      const size_t close = s.find(']', i);
      const std::string range = s.substr(i + 1, close - i - 1);
      i = close + 1;
      const size_t colon = range.find(':');
      const int a = std::stoi(range.substr(0, colon));
      const int b = colon == std::string::npos ? a : std::stoi(range.substr(colon + 1));
      const int step = a >= b ? 1 : -1;
      l.run[l.runs++] = Run{uint8_t(field), uint8_t(b), uint8_t(std::abs(a - b) + 1), step > 0};
      for (int bit = b;; bit += step) {
        l.field[l.count] = uint8_t(field);
        l.bit[l.count] = uint8_t(bit);
        ++l.count;
        if (bit == a) break;
      }
    }
  }
  return out;
}

const std::array<Layout, 14>& layouts() {
  static const std::array<Layout, 14> table = build_layouts();
  return table;
}

// Mode index (0..13) of a block, -1 for the reserved values.
int mode_index(const uint8_t* block) {
  if ((block[0] & 2) == 0) return block[0] & 1;
  const int v = block[0] & 0x1f;
  for (int m = 2; m < 14; ++m)
    if (kModes[m].value == v) return m;
  return -1;
}

struct Bits128 {
  uint64_t lo, hi;
  explicit Bits128(const uint8_t* b) {
    std::memcpy(&lo, b, 8);
    std::memcpy(&hi, b + 8, 8);
    if constexpr (std::endian::native == std::endian::big) {
      lo = __builtin_bswap64(lo);
      hi = __builtin_bswap64(hi);
    }
  }
  int bit(int i) const { return int((i < 64 ? lo >> i : hi >> (i - 64)) & 1); }
  int bits(int pos, int n) const {
    int v = 0;
    for (int k = 0; k < n; ++k) v |= bit(pos + k) << k;
    return v;
  }
};

inline int sign_extend(int v, int bits) {
  const int m = 1 << (bits - 1);
  v &= (1 << bits) - 1;
  return (v ^ m) - m;
}

// Endpoint value (stored bits) to the 16-bit interpolation domain.
inline int unquantize(int q, int bits, bool is_signed) {
  if (!is_signed) {
    if (bits >= 15) return q;
    if (q == 0) return 0;
    if (q == (1 << bits) - 1) return 0xffff;
    return ((q << 16) + 0x8000) >> bits;
  }
  if (bits >= 16) return q;
  if (q == 0) return 0;
  const bool neg = q < 0;
  int a = neg ? -q : q;
  a = a >= (1 << (bits - 1)) - 1 ? 0x7fff : ((a << 15) + 0x4000) >> (bits - 1);
  return neg ? -a : a;
}

// Interpolated value to the BC6H integer (half bits; sign and magnitude as a signed int).
inline int finish(int v, bool is_signed) {
  if (!is_signed) return (v * 31) >> 6;
  return v < 0 ? -((-v * 31) >> 5) : (v * 31) >> 5;
}

inline uint16_t int_to_half(int v) {
  return v < 0 ? uint16_t(0x8000 | uint16_t(-v)) : uint16_t(v);
}

inline int interpolate(int a, int b, int w) {
  return ((64 - w) * a + w * b + 32) >> 6;
}

inline int subset_of(int regions, int partition, int texel) {
  return regions == 2 ? (bptc::kPartition2[partition] >> texel) & 1 : 0;
}

inline bool is_anchor(int regions, int partition, int texel) {
  return texel == 0 || (regions == 2 && texel == bptc::kAnchor2[partition]);
}

// The decoded endpoints (interpolation domain) and indices of a block.
struct Decoded {
  int mode = -1, partition = 0;
  int e[4][3] = {};
  uint8_t idx[16] = {};
};

Decoded decode_fields(const uint8_t block[16], bool is_signed) {
  Decoded d;
  d.mode = mode_index(block);
  if (d.mode < 0) return d;
  const ModeDesc& md = kModes[d.mode];
  const Layout& l = layouts()[size_t(d.mode)];
  const Bits128 bits(block);
  int pos = md.mode_bits;
  int q[4][3] = {};
  for (int k = 0; k < l.count; ++k, ++pos) {
    const int v = bits.bit(pos) << l.bit[k];
    if (l.field[k] == kPartitionField) {
      d.partition |= v;
    } else {
      q[l.field[k] / 3][l.field[k] % 3] |= v;
    }
  }
  const int eb = md.endpoint_bits, n = md.regions * 2;
  for (int c = 0; c < 3; ++c) {
    if (is_signed) q[0][c] = sign_extend(q[0][c], eb);
    for (int i = 1; i < n; ++i) {
      if (md.transformed) {
        q[i][c] = (q[0][c] + sign_extend(q[i][c], md.delta_bits[c])) & ((1 << eb) - 1);
        if (is_signed) q[i][c] = sign_extend(q[i][c], eb);
      } else if (is_signed) {
        q[i][c] = sign_extend(q[i][c], eb);
      }
    }
    for (int i = 0; i < n; ++i) d.e[i][c] = unquantize(q[i][c], eb, is_signed);
  }
  const int ib = md.regions == 2 ? 3 : 4;
  pos = md.regions == 2 ? 82 : 65;
  for (int t = 0; t < 16; ++t) {
    const int nb = ib - (is_anchor(md.regions, d.partition, t) ? 1 : 0);
    d.idx[t] = uint8_t(bits.bits(pos, nb));
    pos += nb;
  }
  return d;
}

// ---------------------------------------------------------------------------------------------
// Encoder

struct Block {
  int v[16][3];    // the BC6H integers of the texels
  float f[3][16];  // the same as floats, channel-major (the loops over texels vectorise)
};

// A coded candidate: mode, partition, quantized endpoints (as decoded, before unquantize:
// w, x, y, z), indices and the squared error they give.
struct Candidate {
  int mode = 10, partition = 0;
  int q[4][3] = {};
  uint8_t idx[16] = {};
  int64_t err = INT64_MAX;
};

struct Range {
  int lo, hi;
};

// Stored endpoint values a mode allows (signed mode 14 leaves out -32768: it decodes to -inf).
inline Range endpoint_range(int bits, bool is_signed) {
  if (!is_signed) return {0, (1 << bits) - 1};
  return {bits >= 16 ? -32767 : -(1 << (bits - 1)), (1 << (bits - 1)) - 1};
}

inline int endpoint_value(int q, int bits, bool is_signed) {
  return finish(unquantize(q, bits, is_signed), is_signed);
}

// The stored value whose decoded endpoint is nearest `x` (a BC6H integer, continuous):
// unquantize maps q to about (q + 1/2) * 2^(16 - bits), so its inverse lands within one step;
// the decoded values are monotonic in q, so the neighbours decide.
int quantize(float x, int bits, bool is_signed) {
  const Range r = endpoint_range(bits, is_signed);
  const float u = is_signed ? x * (32.0f / 31.0f) : x * (64.0f / 31.0f);
  const int full = is_signed ? 16 : 15;  // at this many bits the value is stored as it is
  const float q = bits >= full ? u
                               : u * float(1 << (bits - (is_signed ? 1 : 0))) *
                                         (is_signed ? 1.0f / 32768.0f : 1.0f / 65536.0f) -
                                     0.5f;
  const int q0 = std::clamp(int(std::lrint(q)), r.lo, r.hi);
  int best = q0;
  float best_d = std::fabs(float(endpoint_value(q0, bits, is_signed)) - x);
  for (const int c : {q0 - 1, q0 + 1}) {
    if (c < r.lo || c > r.hi) continue;
    const float d = std::fabs(float(endpoint_value(c, bits, is_signed)) - x);
    if (d < best_d) best_d = d, best = c;
  }
  return best;
}

// Continuous endpoints (BC6H integers) of each region: ep[2r] and ep[2r + 1].
struct Endpoints {
  float e[4][3];
};

// Quantizes `ep` for mode m: the base first, the others clamped to the deltas the mode holds.
void quantize_endpoints(int m, bool is_signed, const Endpoints& ep, Candidate& c) {
  const ModeDesc& md = kModes[m];
  const int n = md.regions * 2, eb = md.endpoint_bits;
  c.mode = m;
  for (int ch = 0; ch < 3; ++ch) {
    c.q[0][ch] = quantize(ep.e[0][ch], eb, is_signed);
    for (int i = 1; i < n; ++i) {
      int q = quantize(ep.e[i][ch], eb, is_signed);
      if (md.transformed) {
        const int db = md.delta_bits[ch];
        q = c.q[0][ch] + std::clamp(q - c.q[0][ch], -(1 << (db - 1)), (1 << (db - 1)) - 1);
      }
      c.q[i][ch] = q;
    }
  }
}

struct Palette {
  int n;            // entries per region
  int v[2][16][3];  // decoded BC6H integers
};

void make_palette(const Candidate& c, bool is_signed, Palette& p) {
  const ModeDesc& md = kModes[c.mode];
  const int ib = md.regions == 2 ? 3 : 4;
  const int* w = bptc::weights(ib);
  p.n = 1 << ib;
  for (int r = 0; r < md.regions; ++r) {
    for (int ch = 0; ch < 3; ++ch) {
      const int a = unquantize(c.q[2 * r][ch], md.endpoint_bits, is_signed);
      const int b = unquantize(c.q[2 * r + 1][ch], md.endpoint_bits, is_signed);
      for (int k = 0; k < p.n; ++k) p.v[r][k][ch] = finish(interpolate(a, b, w[k]), is_signed);
    }
  }
}

inline int64_t texel_error(const int* a, const int* b) {
  const int64_t d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
  return d0 * d0 + d1 * d1 + d2 * d2;
}

// Nearest-weight lookup for a position 0..64 along the endpoint line.
struct WeightLut {
  uint8_t idx3[65], idx4[65];
  WeightLut() {
    for (int f = 0; f <= 64; ++f) {
      int b3 = 0, b4 = 0;
      for (int k = 0; k < 8; ++k)
        if (std::abs(bptc::kWeights3[k] - f) < std::abs(bptc::kWeights3[b3] - f)) b3 = k;
      for (int k = 0; k < 16; ++k)
        if (std::abs(bptc::kWeights4[k] - f) < std::abs(bptc::kWeights4[b4] - f)) b4 = k;
      idx3[f] = uint8_t(b3);
      idx4[f] = uint8_t(b4);
    }
  }
};
const WeightLut kLut;

// Chooses every texel's index and sets c.err: the projection onto the palette's line, and with
// `search` its neighbours too, scored exactly (the palette is near-uniform along the line, but
// finish() rounds). An anchor index must fit one bit less: it is kept to the lower half.
void choose_indices(const Block& b, bool is_signed, bool search, Candidate& c) {
  Palette p;
  make_palette(c, is_signed, p);
  const ModeDesc& md = kModes[c.mode];
  const int half = p.n / 2, last = p.n - 1;
  const uint8_t* lut = p.n == 8 ? kLut.idx3 : kLut.idx4;
  float dir[2][3], inv[2];
  for (int r = 0; r < md.regions; ++r) {
    float dd = 0;
    for (int ch = 0; ch < 3; ++ch) {
      dir[r][ch] = float(p.v[r][last][ch] - p.v[r][0][ch]);
      dd += dir[r][ch] * dir[r][ch];
    }
    inv[r] = dd > 0 ? 64.0f / dd : 0.0f;
  }
  int64_t total = 0;
  for (int t = 0; t < 16; ++t) {
    const int r = subset_of(md.regions, c.partition, t);
    float proj = 0;
    for (int ch = 0; ch < 3; ++ch) proj += (b.f[ch][t] - float(p.v[r][0][ch])) * dir[r][ch];
    const int top = is_anchor(md.regions, c.partition, t) ? half - 1 : last;
    int best = std::min(int(lut[std::clamp(int(proj * inv[r] + 0.5f), 0, 64)]), top);
    int64_t best_e = texel_error(b.v[t], p.v[r][best]);
    if (search) {
      const int centre = best;
      for (int k = std::max(0, centre - 1); k <= std::min(top, centre + 1); ++k) {
        if (k == centre) continue;
        const int64_t e = texel_error(b.v[t], p.v[r][k]);
        if (e < best_e) best_e = e, best = k;
      }
    }
    c.idx[t] = uint8_t(best);
    total += best_e;
  }
  c.err = total;
}

uint32_t region_mask(int regions, int partition, int r) {
  if (regions == 1) return 0xffff;
  const uint32_t m = bptc::kPartition2[partition];
  return r == 1 ? m : (~m & 0xffff);
}

// 1 for the texels of `mask`, 0 for the others: the region loops run over all 16 texels.
void mask_weights(uint32_t mask, float m[16]) {
  for (int t = 0; t < 16; ++t) m[t] = float((mask >> t) & 1);
}

// Principal-axis fit of the texels in `mask`: endpoints at the extremes of their projections.
void fit_line(const Block& b, uint32_t mask, float lo[3], float hi[3]) {
  float m[16];
  mask_weights(mask, m);
  const float n = float(std::popcount(mask & 0xffff));
  if (n == 0) {
    for (int ch = 0; ch < 3; ++ch) lo[ch] = hi[ch] = 0;
    return;
  }
  float mean[3];
  for (int ch = 0; ch < 3; ++ch) {
    float sum = 0;
    for (int t = 0; t < 16; ++t) sum += m[t] * b.f[ch][t];
    mean[ch] = sum / n;
  }
  float d[3][16];
  for (int ch = 0; ch < 3; ++ch)
    for (int t = 0; t < 16; ++t) d[ch][t] = m[t] * (b.f[ch][t] - mean[ch]);
  float cov[6] = {0, 0, 0, 0, 0, 0};  // xx xy xz yy yz zz
  for (int t = 0; t < 16; ++t) {
    cov[0] += d[0][t] * d[0][t], cov[1] += d[0][t] * d[1][t], cov[2] += d[0][t] * d[2][t];
    cov[3] += d[1][t] * d[1][t], cov[4] += d[1][t] * d[2][t], cov[5] += d[2][t] * d[2][t];
  }
  // Power iteration from the row of the largest diagonal entry (never orthogonal to the axis).
  float axis[3];
  if (cov[0] >= cov[3] && cov[0] >= cov[5]) {
    axis[0] = cov[0], axis[1] = cov[1], axis[2] = cov[2];
  } else if (cov[3] >= cov[5]) {
    axis[0] = cov[1], axis[1] = cov[3], axis[2] = cov[4];
  } else {
    axis[0] = cov[2], axis[1] = cov[4], axis[2] = cov[5];
  }
  for (int it = 0; it < 4; ++it) {
    const float x = cov[0] * axis[0] + cov[1] * axis[1] + cov[2] * axis[2];
    const float y = cov[1] * axis[0] + cov[3] * axis[1] + cov[4] * axis[2];
    const float z = cov[2] * axis[0] + cov[4] * axis[1] + cov[5] * axis[2];
    const float big = std::max({std::fabs(x), std::fabs(y), std::fabs(z)});
    if (big <= 0) break;
    axis[0] = x / big, axis[1] = y / big, axis[2] = z / big;
  }
  const float len2 = axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2];
  if (!(len2 > 0)) {
    for (int ch = 0; ch < 3; ++ch) lo[ch] = hi[ch] = mean[ch];
    return;
  }
  // Texels outside the mask project to 0, the mean's projection, which lies between the
  // extremes of the others.
  float tmin = 0, tmax = 0;
  for (int t = 0; t < 16; ++t) {
    const float p = d[0][t] * axis[0] + d[1][t] * axis[1] + d[2][t] * axis[2];
    tmin = std::min(tmin, p), tmax = std::max(tmax, p);
  }
  for (int ch = 0; ch < 3; ++ch) {
    lo[ch] = mean[ch] + axis[ch] * tmin / len2;
    hi[ch] = mean[ch] + axis[ch] * tmax / len2;
  }
}

// Least-squares endpoints of region r for the weights of the chosen indices.
void refine_region(const Block& b, const Candidate& c, int r, float lo[3], float hi[3]) {
  const ModeDesc& md = kModes[c.mode];
  const int* w = bptc::weights(md.regions == 2 ? 3 : 4);
  float m[16], wb[16], wa[16];
  mask_weights(region_mask(md.regions, c.partition, r), m);
  for (int t = 0; t < 16; ++t) {
    wb[t] = m[t] * float(w[c.idx[t]]) * (1.0f / 64.0f);
    wa[t] = m[t] - wb[t];
  }
  float aa = 0, ab = 0, bb = 0;
  for (int t = 0; t < 16; ++t) aa += wa[t] * wa[t], ab += wa[t] * wb[t], bb += wb[t] * wb[t];
  const float det = aa * bb - ab * ab;
  if (std::fabs(det) < 1e-6f) return;
  for (int ch = 0; ch < 3; ++ch) {
    float ax = 0, bx = 0;
    for (int t = 0; t < 16; ++t) ax += wa[t] * b.f[ch][t], bx += wb[t] * b.f[ch][t];
    lo[ch] = (bb * ax - ab * bx) / det;
    hi[ch] = (aa * bx - ab * ax) / det;
  }
}

constexpr float kLimit = 31743.0f;  // 65504 as half bits; signed magnitudes are limited alike

// Orders region r's endpoints so that its anchor texel lies in the first half of the line, and
// clamps them to the values a block can hold.
void orient(const Block& b, int partition, int r, float lo[3], float hi[3], bool is_signed) {
  const float top = kLimit, bottom = is_signed ? -top : 0.0f;
  for (int ch = 0; ch < 3; ++ch) {
    lo[ch] = std::clamp(lo[ch], bottom, top);
    hi[ch] = std::clamp(hi[ch], bottom, top);
  }
  const int anchor = r == 0 ? 0 : bptc::kAnchor2[partition];
  float proj = 0, dd = 0;
  for (int ch = 0; ch < 3; ++ch) {
    const float d = hi[ch] - lo[ch];
    proj += (b.f[ch][anchor] - lo[ch]) * d;
    dd += d * d;
  }
  if (proj * 2.0f > dd)
    for (int ch = 0; ch < 3; ++ch) std::swap(lo[ch], hi[ch]);
}

// Fits the candidate's partition, then alternates quantize -> indices -> least squares for
// `iterations` rounds over modes `modes`, keeping the best into `best`.
void try_modes(const Block& b, bool is_signed, int partition, const int* modes, int mode_count,
               int iterations, bool exhaustive, Candidate& best) {
  const int regions = kModes[modes[0]].regions;
  Endpoints fitted;
  for (int r = 0; r < regions; ++r) {
    fit_line(b, region_mask(regions, partition, r), fitted.e[2 * r], fitted.e[2 * r + 1]);
    orient(b, partition, r, fitted.e[2 * r], fitted.e[2 * r + 1], is_signed);
  }
  for (int mi = 0; mi < mode_count; ++mi) {
    Endpoints ep = fitted;
    for (int it = 0; it < iterations; ++it) {
      Candidate c;
      c.partition = partition;
      quantize_endpoints(modes[mi], is_signed, ep, c);
      choose_indices(b, is_signed, exhaustive, c);
      if (c.err < best.err) best = c;
      if (c.err == 0 || it + 1 == iterations) break;
      for (int r = 0; r < regions; ++r) {
        refine_region(b, c, r, ep.e[2 * r], ep.e[2 * r + 1]);
        orient(b, partition, r, ep.e[2 * r], ep.e[2 * r + 1], is_signed);
      }
    }
  }
}

// How well each partition's two regions fit a line: the squared distances off each region's
// principal axis (continuous, before quantization).
float partition_residual(const Block& b, int partition) {
  float total = 0;
  for (int r = 0; r < 2; ++r) {
    const uint32_t mask = region_mask(2, partition, r);
    float lo[3], hi[3];
    fit_line(b, mask, lo, hi);
    float d[3], dd = 0;
    for (int ch = 0; ch < 3; ++ch) d[ch] = hi[ch] - lo[ch], dd += d[ch] * d[ch];
    for (int t = 0; t < 16; ++t) {
      if (!((mask >> t) & 1)) continue;
      float off[3], proj = 0;
      for (int ch = 0; ch < 3; ++ch) off[ch] = b.f[ch][t] - lo[ch], proj += off[ch] * d[ch];
      const float s = dd > 0 ? proj / dd : 0.0f;
      for (int ch = 0; ch < 3; ++ch) {
        const float e = off[ch] - s * d[ch];
        total += e * e;
      }
    }
  }
  return total;
}

// Every +-1 step of every stored endpoint channel that lowers the error, until none does.
// (`widths` > 1: steps of +-1, +-2, +-4, ... up to 2^(widths - 1).)
void perturb(const Block& b, bool is_signed, Candidate& c, int rounds, int widths = 1) {
  const ModeDesc& md = kModes[c.mode];
  const int n = md.regions * 2;
  const Range r = endpoint_range(md.endpoint_bits, is_signed);
  for (int round = 0; round < rounds; ++round) {
    bool improved = false;
    for (int i = 0; i < n; ++i) {
      for (int ch = 0; ch < 3; ++ch) {
        for (int s = 0; s < 2 * widths; ++s) {
          const int step = (s % 2 ? 1 : -1) * (1 << (s / 2));
          Candidate t = c;
          t.q[i][ch] += step;
          if (t.q[i][ch] < r.lo || t.q[i][ch] > r.hi) continue;
          if (md.transformed) {
            // Deltas from w must stay in range; moving w moves nothing else.
            bool ok = true;
            for (int k = 1; k < n && ok; ++k) {
              const int db = md.delta_bits[ch], d = t.q[k][ch] - t.q[0][ch];
              ok = d >= -(1 << (db - 1)) && d <= (1 << (db - 1)) - 1;
            }
            if (!ok) continue;
          }
          choose_indices(b, is_signed, true, t);
          if (t.err < c.err) c = t, improved = true;
        }
      }
    }
    if (!improved || c.err == 0) break;
  }
}

// 128 bits written from the lowest.
struct Bits128Writer {
  uint64_t w[2] = {0, 0};
  int pos = 0;
  void write(uint64_t v, int n) {  // n <= 32, v < 2^n
    if (pos < 64) {
      w[0] |= v << pos;
      if (pos + n > 64) w[1] |= v >> (64 - pos);
    } else {
      w[1] |= v << (pos - 64);
    }
    pos += n;
  }
};

void pack(const Candidate& c, uint8_t out[16]) {
  const ModeDesc& md = kModes[c.mode];
  const Layout& l = layouts()[size_t(c.mode)];
  const int eb = md.endpoint_bits, n = md.regions * 2;
  int field[13] = {};
  for (int ch = 0; ch < 3; ++ch) {
    field[ch] = c.q[0][ch] & ((1 << eb) - 1);
    for (int i = 1; i < n; ++i) {
      field[i * 3 + ch] = md.transformed
                              ? (c.q[i][ch] - c.q[0][ch]) & ((1 << md.delta_bits[ch]) - 1)
                              : c.q[i][ch] & ((1 << eb) - 1);
    }
  }
  field[kPartitionField] = c.partition;
  Bits128Writer w;
  w.write(md.value, md.mode_bits);
  for (int k = 0; k < l.runs; ++k) {
    const Run& run = l.run[k];
    const uint32_t v = uint32_t(field[run.field]);
    if (run.ascending) {
      w.write((v >> run.first) & ((1u << run.count) - 1), run.count);
    } else {
      for (int i = 0; i < run.count; ++i) w.write((v >> (run.first - i)) & 1, 1);
    }
  }
  const int ib = md.regions == 2 ? 3 : 4;
  for (int t = 0; t < 16; ++t) w.write(c.idx[t], ib - (is_anchor(md.regions, c.partition, t)));
  for (int k = 0; k < 2; ++k) {
    uint64_t v = w.w[k];
    if constexpr (std::endian::native == std::endian::big) v = __builtin_bswap64(v);
    std::memcpy(out + 8 * k, &v, 8);
  }
}

// ---- Real-time level: 16 blocks at a time ----
//
// One region along the principal axis, one least-squares step on the continuous line, then the
// most precise one-region mode whose deltas hold the endpoints (14, 13, 12, else the
// untransformed 11), indices by projection. The kernel runs the same arithmetic on 16 blocks
// side by side (structure of arrays, innermost loops over the blocks), which compilers turn into
// SIMD, as bc1.cpp's real-time kernel does: built for AVX-512, AVX2 and the baseline, picked at
// run time, the same IEEE operations in the same order per block (no FMA, no reassociation,
// branches as selects), so the bytes do not depend on the machine, nor on which lanes a block
// shares. Only the two ends of the palette are needed (the indices come from the projection,
// unscored): weight 0 and 64 interpolate to the endpoints themselves.
constexpr int kLanes = 16;

struct RealtimeLanes {
  uint16_t h[48][kLanes];   // in: the blocks' half floats, texel-major RGB (3 * texel + channel)
  int32_t mode[kLanes];     // out: mode index (10-13)
  int32_t q[2][3][kLanes];  // out: the two stored endpoints (as decoded, before unquantize)
  int32_t idx[16][kLanes];  // out: indices
};

// The nearest 4-bit index to a position 0..64 along the line (kLut.idx4, ties to the lower
// index) and an index's weight (bptc::kWeights4), as arithmetic the kernel's loops vectorise.
constexpr int realtime_index(int position) {
  return (position * 15 + 26) >> 6;
}
constexpr int realtime_weight(int index) {
  return ((index * 64 + 7) * 2185) >> 15;  // (64 i + 7) / 15
}
constexpr bool realtime_tables_agree() {
  auto distance = [](int a, int b) { return a > b ? a - b : b - a; };  // std::abs: not constexpr
  for (int f = 0; f <= 64; ++f) {
    int best = 0;
    for (int k = 0; k < 16; ++k)
      if (distance(bptc::kWeights4[k], f) < distance(bptc::kWeights4[best], f)) best = k;
    if (realtime_index(f) != best || realtime_weight(best) != bptc::kWeights4[best]) return false;
  }
  return true;
}
static_assert(realtime_tables_agree());

// unquantize() and finish() for a lane's endpoint width (branches as selects; unsigned
// arithmetic where an unused branch would overflow).
template <bool kSigned>
inline int lane_unquantize(int q, int bits) {
  if constexpr (!kSigned) {
    const int mid = int((((uint32_t(q) << 16) + 0x8000u) >> uint32_t(bits)));
    const int v = q == 0 ? 0 : q == (1 << bits) - 1 ? 0xffff : mid;
    return bits >= 15 ? q : v;
  } else {
    const int a = q < 0 ? -q : q;
    const int mid = int((((uint32_t(a) << 15) + 0x4000u) >> uint32_t(bits - 1)));
    const int m = a >= (1 << (bits - 1)) - 1 ? 0x7fff : mid;
    const int v = q == 0 ? 0 : q < 0 ? -m : m;
    return bits >= 16 ? q : v;
  }
}

template <bool kSigned>
inline int lane_finish(int v) {
  if constexpr (!kSigned) {
    return (v * 31) >> 6;
  } else {
    const int a = ((v < 0 ? -v : v) * 31) >> 5;
    return v < 0 ? -a : a;
  }
}

// quantize() for a lane's endpoint width. lrint's round-to-nearest-even as an add and subtract
// of 1.5 * 2^23 (exact for |q| < 2^22; here |q| <= 65536).
template <bool kSigned>
inline int lane_quantize(float x, int bits) {
  const int lo = kSigned ? (bits >= 16 ? -32767 : -(1 << (bits - 1))) : 0;
  const int hi = kSigned ? (1 << (bits - 1)) - 1 : (1 << bits) - 1;
  const float u = kSigned ? x * (32.0f / 31.0f) : x * (64.0f / 31.0f);
  const int full = kSigned ? 16 : 15;
  const float scaled =
      u * float(1 << (bits - (kSigned ? 1 : 0))) * (kSigned ? 1.0f / 32768.0f : 1.0f / 65536.0f) -
      0.5f;
  const float q = bits >= full ? u : scaled;
  const float magic = 12582912.0f;
  const float big = q + magic;
  const float rounded = big - magic;
  int q0 = int(rounded);
  q0 = q0 < lo ? lo : hi < q0 ? hi : q0;
  int best = q0;
  float best_d = std::fabs(float(lane_finish<kSigned>(lane_unquantize<kSigned>(q0, bits))) - x);
  const int down = q0 - 1, up = q0 + 1;
  const float dd = std::fabs(float(lane_finish<kSigned>(lane_unquantize<kSigned>(down, bits))) - x);
  const bool take_down = down >= lo && dd < best_d;
  best = take_down ? down : best;
  best_d = take_down ? dd : best_d;
  const float du = std::fabs(float(lane_finish<kSigned>(lane_unquantize<kSigned>(up, bits))) - x);
  const bool take_up = up <= hi && du < best_d;
  return take_up ? up : best;
}

template <bool kSigned>
[[gnu::always_inline]] inline void realtime_lanes(RealtimeLanes& io) {
  constexpr int L = kLanes;
  float f[3][16][L];
  for (int t = 0; t < 16; ++t) {
    for (int ch = 0; ch < 3; ++ch) {
      for (int l = 0; l < L; ++l) {
        // bc6h_half_to_int without branches.
        const int h = io.h[3 * t + ch][l], mag = h & 0x7fff, neg = h >> 15;
        int v = mag > 0x7c00 ? 0 : mag < 0x7bff ? mag : 0x7bff;
        v = neg ? (kSigned ? -v : 0) : v;
        f[ch][t][l] = float(v);
      }
    }
  }
  // fit_line() over all 16 texels.
  float mean[3][L], d[3][16][L];
  for (int ch = 0; ch < 3; ++ch) {
    float sum[L];
    for (int l = 0; l < L; ++l) sum[l] = 0;
    for (int t = 0; t < 16; ++t)
      for (int l = 0; l < L; ++l) sum[l] += f[ch][t][l];
    for (int l = 0; l < L; ++l) mean[ch][l] = sum[l] / 16.0f;
    for (int t = 0; t < 16; ++t)
      for (int l = 0; l < L; ++l) d[ch][t][l] = f[ch][t][l] - mean[ch][l];
  }
  float cov[6][L];
  for (int k = 0; k < 6; ++k)
    for (int l = 0; l < L; ++l) cov[k][l] = 0;
  for (int t = 0; t < 16; ++t) {
    for (int l = 0; l < L; ++l) {
      const float x = d[0][t][l], y = d[1][t][l], z = d[2][t][l];
      cov[0][l] += x * x, cov[1][l] += x * y, cov[2][l] += x * z;
      cov[3][l] += y * y, cov[4][l] += y * z, cov[5][l] += z * z;
    }
  }
  float axis[3][L], len2[L];
  for (int l = 0; l < L; ++l) {
    const float c0 = cov[0][l], c1 = cov[1][l], c2 = cov[2][l], c3 = cov[3][l], c4 = cov[4][l],
                c5 = cov[5][l];
    // Power iteration from the row of the largest diagonal entry; a zero step keeps the axis.
    const bool first = c0 >= c3 && c0 >= c5, second = c3 >= c5;
    float a0 = first ? c0 : second ? c1 : c2;
    float a1 = first ? c1 : second ? c3 : c4;
    float a2 = first ? c2 : second ? c4 : c5;
#pragma GCC unroll 4
    for (int it = 0; it < 4; ++it) {
      const float x = c0 * a0 + c1 * a1 + c2 * a2;
      const float y = c1 * a0 + c3 * a1 + c4 * a2;
      const float z = c2 * a0 + c4 * a1 + c5 * a2;
      float big = std::fabs(x);
      big = big < std::fabs(y) ? std::fabs(y) : big;
      big = big < std::fabs(z) ? std::fabs(z) : big;
      const bool step = big > 0;
      a0 = step ? x / big : a0, a1 = step ? y / big : a1, a2 = step ? z / big : a2;
    }
    axis[0][l] = a0, axis[1][l] = a1, axis[2][l] = a2;
    len2[l] = a0 * a0 + a1 * a1 + a2 * a2;
  }
  float tmin[L], tmax[L];
  for (int l = 0; l < L; ++l) tmin[l] = tmax[l] = 0;
  for (int t = 0; t < 16; ++t) {
    for (int l = 0; l < L; ++l) {
      const float p = d[0][t][l] * axis[0][l] + d[1][t][l] * axis[1][l] + d[2][t][l] * axis[2][l];
      tmin[l] = p < tmin[l] ? p : tmin[l];
      tmax[l] = tmax[l] < p ? p : tmax[l];
    }
  }
  float lo[3][L], hi[3][L];
  for (int ch = 0; ch < 3; ++ch) {
    for (int l = 0; l < L; ++l) {
      const bool line = len2[l] > 0;
      lo[ch][l] = line ? mean[ch][l] + axis[ch][l] * tmin[l] / len2[l] : mean[ch][l];
      hi[ch][l] = line ? mean[ch][l] + axis[ch][l] * tmax[l] / len2[l] : mean[ch][l];
    }
  }
  // Indices for the texels' projections, then least squares for their weights (refine_region).
  float wb[16][L];
  {
    float dv[3][L], inv[L];
    for (int l = 0; l < L; ++l) {
      float dd = 0;
      for (int ch = 0; ch < 3; ++ch) {
        dv[ch][l] = hi[ch][l] - lo[ch][l];
        dd += dv[ch][l] * dv[ch][l];
      }
      inv[l] = dd > 0 ? 64.0f / dd : 0.0f;  // 0: no step (see below)
    }
    for (int t = 0; t < 16; ++t) {
      for (int l = 0; l < L; ++l) {
        float proj = 0;
        for (int ch = 0; ch < 3; ++ch) proj += (f[ch][t][l] - lo[ch][l]) * dv[ch][l];
        int k = int(proj * inv[l] + 0.5f);
        k = k < 0 ? 0 : k > 64 ? 64 : k;
        wb[t][l] = float(realtime_weight(realtime_index(k))) * (1.0f / 64.0f);
      }
    }
    float aa[L], ab[L], bb[L], ax[3][L], bx[3][L];
    for (int l = 0; l < L; ++l) {
      aa[l] = ab[l] = bb[l] = 0;
      for (int ch = 0; ch < 3; ++ch) ax[ch][l] = bx[ch][l] = 0;
    }
    for (int t = 0; t < 16; ++t) {
      for (int l = 0; l < L; ++l) {
        const float b = wb[t][l], a = 1.0f - b;
        aa[l] += a * a, ab[l] += a * b, bb[l] += b * b;
        for (int ch = 0; ch < 3; ++ch) ax[ch][l] += a * f[ch][t][l], bx[ch][l] += b * f[ch][t][l];
      }
    }
    for (int l = 0; l < L; ++l) {
      const float det = aa[l] * bb[l] - ab[l] * ab[l];
      // No step for a point (all texels equal) or a singular system.
      const bool step = inv[l] > 0 && !(std::fabs(det) < 1e-6f);
      for (int ch = 0; ch < 3; ++ch) {
        const float nlo = (bb[l] * ax[ch][l] - ab[l] * bx[ch][l]) / det;
        const float nhi = (aa[l] * bx[ch][l] - ab[l] * ax[ch][l]) / det;
        lo[ch][l] = step ? nlo : lo[ch][l];
        hi[ch][l] = step ? nhi : hi[ch][l];
      }
    }
  }
  // orient(): clamp to what a block holds, texel 0 in the first half of the line; then the mode
  // and quantize_endpoints().
  {
    const float top = kLimit, bottom = kSigned ? -top : 0.0f;
    float proj[L], dd[L], span[L];
    for (int l = 0; l < L; ++l) proj[l] = dd[l] = span[l] = 0;
    for (int ch = 0; ch < 3; ++ch) {
      for (int l = 0; l < L; ++l) {
        const float a = lo[ch][l], b = hi[ch][l];
        lo[ch][l] = a < bottom ? bottom : top < a ? top : a;
        hi[ch][l] = b < bottom ? bottom : top < b ? top : b;
        const float dv = hi[ch][l] - lo[ch][l];
        proj[l] += (f[ch][0][l] - lo[ch][l]) * dv;
        dd[l] += dv * dv;
      }
    }
    for (int ch = 0; ch < 3; ++ch) {
      for (int l = 0; l < L; ++l) {
        const bool swap = proj[l] * 2.0f > dd[l];
        const float a = lo[ch][l], b = hi[ch][l];
        lo[ch][l] = swap ? b : a;
        hi[ch][l] = swap ? a : b;
        const float s = std::fabs(hi[ch][l] - lo[ch][l]);
        span[l] = span[l] < s ? s : span[l];
      }
    }
    int eb[L], half_range[L];
    for (int l = 0; l < L; ++l) {
      const float sp = span[l] * (kSigned ? 32.0f / 31.0f / 32768.0f : 64.0f / 31.0f / 65536.0f);
      // Modes 14, 13, 12 (index 13, 12, 11) when their deltas hold the span with a step of
      // margin; the signed endpoints spend a bit on the sign.
      const float s = kSigned ? 0.5f : 1.0f;
      const bool m13 = sp * (65536.0f * s) + 1.0f <= 7.0f;
      const bool m12 = sp * (4096.0f * s) + 1.0f <= 127.0f;
      const bool m11 = sp * (2048.0f * s) + 1.0f <= 255.0f;
      io.mode[l] = m13 ? 13 : m12 ? 12 : m11 ? 11 : 10;
      eb[l] = m13 ? 16 : m12 ? 12 : m11 ? 11 : 10;
      half_range[l] = m13 ? 8 : m12 ? 128 : m11 ? 256 : 1 << 30;  // 2^(delta bits - 1)
    }
    for (int ch = 0; ch < 3; ++ch) {
      for (int l = 0; l < L; ++l) {
        const int q0 = lane_quantize<kSigned>(lo[ch][l], eb[l]);
        const int q1 = lane_quantize<kSigned>(hi[ch][l], eb[l]);
        const int delta = q1 - q0, r = half_range[l];  // mode 11 (untransformed): no clamp
        const int clamped = delta < -r ? -r : delta > r - 1 ? r - 1 : delta;
        io.q[0][ch][l] = q0;
        io.q[1][ch][l] = q0 + clamped;
      }
    }
  }
  // choose_indices() without the scoring: the projection onto the decoded endpoints' line.
  float p0[3][L], dir[3][L], inv[L];
  for (int l = 0; l < L; ++l) inv[l] = 0;
  for (int ch = 0; ch < 3; ++ch) {
    for (int l = 0; l < L; ++l) {
      const int mode = io.mode[l];
      const int eb = mode == 13 ? 16 : mode == 12 ? 12 : mode == 11 ? 11 : 10;
      const int a = lane_finish<kSigned>(lane_unquantize<kSigned>(io.q[0][ch][l], eb));
      const int b = lane_finish<kSigned>(lane_unquantize<kSigned>(io.q[1][ch][l], eb));
      p0[ch][l] = float(a);
      dir[ch][l] = float(b - a);
      inv[l] += dir[ch][l] * dir[ch][l];  // dd, first
    }
  }
  for (int l = 0; l < L; ++l) inv[l] = inv[l] > 0 ? 64.0f / inv[l] : 0.0f;
  for (int t = 0; t < 16; ++t) {
    const int top = t == 0 ? 7 : 15;  // the anchor's index has one bit less
    for (int l = 0; l < L; ++l) {
      float proj = 0;
      for (int ch = 0; ch < 3; ++ch) proj += (f[ch][t][l] - p0[ch][l]) * dir[ch][l];
      int k = int(proj * inv[l] + 0.5f);
      k = k < 0 ? 0 : k > 64 ? 64 : k;
      const int i = realtime_index(k);
      io.idx[t][l] = i < top ? i : top;
    }
  }
}

VT_TARGET_CLONES
void encode_realtime_lanes(RealtimeLanes& io, bool is_signed) {
  if (is_signed)
    realtime_lanes<true>(io);
  else
    realtime_lanes<false>(io);
}

// Packs the first n lanes' blocks, `out_stride` bytes apart.
void pack_lanes(const RealtimeLanes& io, int n, uint8_t* out, size_t out_stride) {
  for (int l = 0; l < n; ++l) {
    Candidate c;
    c.mode = io.mode[l];
    for (int ch = 0; ch < 3; ++ch) c.q[0][ch] = io.q[0][ch][l], c.q[1][ch] = io.q[1][ch][l];
    for (int t = 0; t < 16; ++t) c.idx[t] = uint8_t(io.idx[t][l]);
    pack(c, out + size_t(l) * out_stride);
  }
}

constexpr int kOneRegionModes[4] = {10, 11, 12, 13};  // modes 11-14
constexpr int kTwoRegionModes[10] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};

}  // namespace

int bc6h_half_to_int(uint16_t h, bool is_signed) {
  int mag = h & 0x7fff;
  const bool neg = (h & 0x8000) != 0;
  if (mag > 0x7c00) return 0;  // NaN
  mag = std::min(mag, 0x7bff);
  if (!is_signed) return neg ? 0 : mag;
  return neg ? -mag : mag;
}

int bc6h_block_mode(const uint8_t block[16]) {
  const int m = mode_index(block);
  return m < 0 ? 0 : m + 1;
}

int bc6h_block_partition(const uint8_t block[16]) {
  const int m = mode_index(block);
  if (m < 0 || kModes[m].regions == 1) return -1;
  return decode_fields(block, false).partition;
}

void bc6h_decode_block(const uint8_t block[16], bool is_signed, uint16_t rgb[48]) {
  const Decoded d = decode_fields(block, is_signed);
  if (d.mode < 0) {
    std::memset(rgb, 0, 48 * sizeof(uint16_t));
    return;
  }
  const ModeDesc& md = kModes[d.mode];
  const int* w = bptc::weights(md.regions == 2 ? 3 : 4);
  for (int t = 0; t < 16; ++t) {
    const int r = subset_of(md.regions, d.partition, t);
    for (int ch = 0; ch < 3; ++ch) {
      const int v = interpolate(d.e[2 * r][ch], d.e[2 * r + 1][ch], w[d.idx[t]]);
      rgb[3 * t + ch] = int_to_half(finish(v, is_signed));
    }
  }
}

namespace {

Block make_block(const uint16_t rgb[48], bool is_signed) {
  Block b;
  for (int i = 0; i < 48; ++i) {
    // bc6h_half_to_int without branches (the loop vectorises).
    const int h = rgb[i], mag = h & 0x7fff, neg = h >> 15;
    int v = mag > 0x7c00 ? 0 : std::min(mag, 0x7bff);
    v = neg ? (is_signed ? -v : 0) : v;
    (&b.v[0][0])[i] = v;
  }
  for (int t = 0; t < 16; ++t)
    for (int ch = 0; ch < 3; ++ch) b.f[ch][t] = float(b.v[t][ch]);
  return b;
}

}  // namespace

void bc6h_encode_block_reference(const uint16_t rgb[48], bool is_signed, uint8_t out[16]) {
  const Block b = make_block(rgb, is_signed);
  constexpr int kIterations = 8, kRounds = 8, kWidths = 3;
  Candidate best;
  try_modes(b, is_signed, 0, kOneRegionModes, 4, kIterations, true, best);
  if (best.err > 0) perturb(b, is_signed, best, kRounds, kWidths);
  for (int p = 0; p < 32 && best.err > 0; ++p) {
    Candidate c;
    try_modes(b, is_signed, p, kTwoRegionModes, 10, kIterations, true, c);
    if (c.err > 0) perturb(b, is_signed, c, kRounds, kWidths);
    if (c.err < best.err) best = c;
  }
  pack(best, out);
}

void bc6h_encode_block(const uint16_t rgb[48], bool is_signed, BcQuality quality, uint8_t out[16]) {
  if (quality == BcQuality::kRealtime) {
    RealtimeLanes io;  // the block in every lane
    for (int i = 0; i < 48; ++i)
      for (int l = 0; l < kLanes; ++l) io.h[i][l] = rgb[i];
    encode_realtime_lanes(io, is_signed);
    pack_lanes(io, 1, out, 16);
    return;
  }
  const Block b = make_block(rgb, is_signed);
  Candidate best;
  const bool high = quality == BcQuality::kHigh;
  const int iterations = high ? 4 : 3;
  try_modes(b, is_signed, 0, kOneRegionModes, 4, iterations, true, best);
  if (best.err > 0) {
    // Two regions over the partitions whose regions lie closest to a line.
    std::array<std::pair<float, int>, 32> ranked;
    for (int p = 0; p < 32; ++p) ranked[size_t(p)] = {partition_residual(b, p), p};
    const int keep = high ? 12 : 4;
    std::partial_sort(ranked.begin(), ranked.begin() + keep, ranked.end());
    for (int k = 0; k < keep && best.err > 0; ++k)
      try_modes(b, is_signed, ranked[size_t(k)].second, kTwoRegionModes, 10, iterations, true,
                best);
  }
  if (high && best.err > 0) perturb(b, is_signed, best, 4);
  pack(best, out);
}

namespace {

Status check_bc6h_image(const void* a, const void* b, int width, int height, int channels) {
  if (a == nullptr || b == nullptr)
    return Error(ErrorCode::kInvalidArgument, "null image or block pointer");
  if (width <= 0 || height <= 0 || width % 4 != 0 || height % 4 != 0)
    return Error(ErrorCode::kInvalidArgument, "image size " + std::to_string(width) + "x" +
                                                  std::to_string(height) +
                                                  " is not a positive multiple of 4");
  if (channels < 1 || channels > 4)
    return Error(ErrorCode::kInvalidArgument,
                 "channel count " + std::to_string(channels) + " is not 1..4");
  return Status::Ok();
}

}  // namespace

Status bc6h_encode_image(bool is_signed, BcQuality quality, const void* texels, int width,
                         int height, int channels, uint8_t* out) {
  VT_RETURN_IF_ERROR(check_bc6h_image(texels, out, width, height, channels));
  const int blocks_x = width / 4;
  const size_t nc = size_t(channels);
  if (quality == BcQuality::kRealtime) {
    // kLanes blocks of a block row at a time; idle lanes repeat the row's last block.
    RealtimeLanes io;
    std::vector<uint16_t> rows(size_t(width) * 4 * nc);
    for (int by = 0; by < height / 4; ++by) {
      std::memcpy(rows.data(),
                  static_cast<const uint8_t*>(texels) + size_t(by) * 4 * size_t(width) * nc * 2,
                  rows.size() * 2);
      for (int bx0 = 0; bx0 < blocks_x; bx0 += kLanes) {
        const int n = std::min(kLanes, blocks_x - bx0);
        for (int l = 0; l < kLanes; ++l) {
          const size_t x0 = size_t(bx0 + std::min(l, n - 1)) * 4;
          for (int y = 0; y < 4; ++y) {
            const uint16_t* src = rows.data() + (size_t(y) * size_t(width) + x0) * nc;
            for (int x = 0; x < 4; ++x)
              for (int ch = 0; ch < 3; ++ch)
                io.h[3 * (4 * y + x) + ch][l] =
                    ch < channels ? src[size_t(x) * nc + size_t(ch)] : 0;
          }
        }
        encode_realtime_lanes(io, is_signed);
        pack_lanes(io, n, out + (size_t(by) * size_t(blocks_x) + size_t(bx0)) * 16, 16);
      }
    }
    return Status::Ok();
  }
  uint16_t rgb[48], row[16];
  for (int by = 0; by < height / 4; ++by) {
    for (int bx = 0; bx < blocks_x; ++bx) {
      for (int y = 0; y < 4; ++y) {
        const size_t first = ((size_t(by) * 4 + size_t(y)) * size_t(width) + size_t(bx) * 4) * nc;
        std::memcpy(row, static_cast<const uint8_t*>(texels) + first * 2, 4 * nc * 2);
        for (int x = 0; x < 4; ++x)
          for (int ch = 0; ch < 3; ++ch)
            rgb[3 * (4 * y + x) + ch] = ch < channels ? row[size_t(x) * nc + size_t(ch)] : 0;
      }
      bc6h_encode_block(rgb, is_signed, quality,
                        out + (size_t(by) * size_t(blocks_x) + size_t(bx)) * 16);
    }
  }
  return Status::Ok();
}

Status bc6h_decode_image(bool is_signed, const uint8_t* blocks, int width, int height, int channels,
                         void* texels) {
  VT_RETURN_IF_ERROR(check_bc6h_image(blocks, texels, width, height, channels));
  const int blocks_x = width / 4;
  const size_t nc = size_t(channels);
  uint16_t rgb[48], row[16];
  for (int by = 0; by < height / 4; ++by) {
    for (int bx = 0; bx < blocks_x; ++bx) {
      bc6h_decode_block(blocks + (size_t(by) * size_t(blocks_x) + size_t(bx)) * 16, is_signed, rgb);
      for (int y = 0; y < 4; ++y) {
        const size_t first = ((size_t(by) * 4 + size_t(y)) * size_t(width) + size_t(bx) * 4) * nc;
        for (int x = 0; x < 4; ++x)
          for (int ch = 0; ch < channels; ++ch)
            row[size_t(x) * nc + size_t(ch)] = ch < 3 ? rgb[3 * (4 * y + x) + ch] : 0x3c00;
        std::memcpy(static_cast<uint8_t*>(texels) + first * 2, row, 4 * nc * 2);
      }
    }
  }
  return Status::Ok();
}

}  // namespace vt
