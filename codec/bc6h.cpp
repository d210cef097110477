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
void choose_indices(const Block& b, bool is_signed, bool search, Candidate& c, bool score = true) {
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
    if (!score) {
      c.idx[t] = uint8_t(best);
      continue;
    }
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
void perturb(const Block& b, bool is_signed, Candidate& c, int rounds) {
  const ModeDesc& md = kModes[c.mode];
  const int n = md.regions * 2;
  const Range r = endpoint_range(md.endpoint_bits, is_signed);
  for (int round = 0; round < rounds; ++round) {
    bool improved = false;
    for (int i = 0; i < n; ++i) {
      for (int ch = 0; ch < 3; ++ch) {
        for (int step = -1; step <= 1; step += 2) {
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

// The real-time level: one region along the principal axis, one least-squares step on the
// continuous line, then the most precise one-region mode whose deltas hold the endpoints
// (14, 13, 12, else the untransformed 11), indices by projection.
void encode_realtime(const Block& b, bool is_signed, Candidate& c) {
  Endpoints ep;
  float* lo = ep.e[0];
  float* hi = ep.e[1];
  fit_line(b, 0xffff, lo, hi);
  // Least squares for the weights the texels' projections would take.
  float d[3], dd = 0;
  for (int ch = 0; ch < 3; ++ch) d[ch] = hi[ch] - lo[ch], dd += d[ch] * d[ch];
  if (dd > 0) {
    c.mode = 10;
    c.partition = 0;
    const float inv = 64.0f / dd;
    for (int t = 0; t < 16; ++t) {
      float proj = 0;
      for (int ch = 0; ch < 3; ++ch) proj += (b.f[ch][t] - lo[ch]) * d[ch];
      c.idx[t] = kLut.idx4[std::clamp(int(proj * inv + 0.5f), 0, 64)];
    }
    refine_region(b, c, 0, lo, hi);
  }
  orient(b, 0, 0, lo, hi, is_signed);
  // The delta each mode would store, from the continuous endpoints (one step of margin for
  // rounding; quantize_endpoints clamps what still does not fit).
  float span = 0;
  for (int ch = 0; ch < 3; ++ch) span = std::max(span, std::fabs(hi[ch] - lo[ch]));
  span *= is_signed ? 32.0f / 31.0f / 32768.0f : 64.0f / 31.0f / 65536.0f;
  int mode = 10;
  for (const int m : {13, 12, 11}) {
    const ModeDesc& md = kModes[m];
    const float steps = span * float(1 << (md.endpoint_bits - (is_signed ? 1 : 0)));
    if (steps + 1.0f <= float((1 << (md.delta_bits[0] - 1)) - 1)) {
      mode = m;
      break;
    }
  }
  quantize_endpoints(mode, is_signed, ep, c);
  choose_indices(b, is_signed, false, c, /*score=*/false);  // nothing to compare it with
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

void bc6h_encode_block(const uint16_t rgb[48], bool is_signed, BcQuality quality, uint8_t out[16]) {
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
  Candidate best;
  if (quality == BcQuality::kRealtime) {
    encode_realtime(b, is_signed, best);
    pack(best, out);
    return;
  }
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
