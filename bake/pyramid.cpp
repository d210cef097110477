#include "bake/pyramid.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>

namespace vt {
namespace {

double sinc(double x) {
  if (std::abs(x) < 1e-12) return 1.0;
  return std::sin(std::numbers::pi * x) / (std::numbers::pi * x);
}

// Modified Bessel function of the first kind, order 0 (series; converges fast for alpha <= 8).
double bessel_i0(double x) {
  double sum = 1.0, term = 1.0, q = x * x / 4.0;
  for (int k = 1; k < 50; ++k) {
    term *= q / (double(k) * k);
    sum += term;
    if (term < sum * 1e-17) break;
  }
  return sum;
}

// Filter value at x destination texels from the destination texel's centre.
double filter_value(MipFilter filter, double x) {
  double ax = std::abs(x);
  switch (filter) {
    case MipFilter::kBox:
      return ax < 0.5 ? 1.0 : 0.0;
    case MipFilter::kLanczos3:
      return ax < 3.0 ? sinc(x) * sinc(x / 3.0) : 0.0;
    case MipFilter::kKaiser: {
      // Kaiser-windowed sinc, width 3, alpha 4 (the setting NVTT uses for mipmaps).
      constexpr double kWidth = 3.0, kAlpha = 4.0;
      if (ax >= kWidth) return 0.0;
      double t = x / kWidth;
      return sinc(x) * bessel_i0(kAlpha * std::sqrt(1.0 - t * t)) / bessel_i0(kAlpha);
    }
  }
  return 0.0;
}

double support(MipFilter filter) {
  return filter == MipFilter::kBox ? 0.5 : 3.0;
}

// Maps a texel coordinate through the address mode (sizes here are <= 2^24).
inline int64_t addr(int64_t c, int64_t size, AddressMode mode) {
  if (c >= 0 && c < size) return c;
  return address_texel(c, size, mode);
}

// Horizontal pass of one row: (width + 1) / 2 texels of `ch` doubles.
void filter_row(const DownsampleKernel& k, AddressMode mode, const float* src, uint32_t width,
                uint32_t ch, double* dst) {
  const uint32_t dw = (width + 1) / 2;
  const int taps = k.taps();
  const double* w = k.weights.data();
  for (uint32_t i = 0; i < dw; ++i) {
    int64_t x0 = int64_t(2) * i + k.first;
    double acc[4] = {0, 0, 0, 0};
    if (x0 >= 0 && x0 + taps <= int64_t(width)) {
      const float* s = src + size_t(x0) * ch;
      for (int t = 0; t < taps; ++t, s += ch) {
        for (uint32_t c = 0; c < ch; ++c) acc[c] += w[t] * double(s[c]);
      }
    } else {
      for (int t = 0; t < taps; ++t) {
        const float* s = src + size_t(addr(x0 + t, width, mode)) * ch;
        for (uint32_t c = 0; c < ch; ++c) acc[c] += w[t] * double(s[c]);
      }
    }
    for (uint32_t c = 0; c < ch; ++c) dst[size_t(i) * ch + c] = acc[c];
  }
}

// Per output column of one source row: 1 when the column's taps (the horizontal pass's) reach a
// texel of `cov` that is not covered. `uncovered_before` is scratch (width + 1 counts).
void gap_row(const DownsampleKernel& k, AddressMode mode, const uint8_t* cov, uint32_t width,
             std::vector<uint32_t>& uncovered_before, uint8_t* dst) {
  const uint32_t dw = (width + 1) / 2;
  const int taps = k.taps();
  uncovered_before.resize(size_t(width) + 1);
  uncovered_before[0] = 0;
  for (uint32_t x = 0; x < width; ++x) uncovered_before[x + 1] = uncovered_before[x] + !cov[x];
  if (uncovered_before[width] == 0) {
    std::fill(dst, dst + dw, uint8_t(0));
    return;
  }
  for (uint32_t i = 0; i < dw; ++i) {
    const int64_t x0 = int64_t(2) * i + k.first;
    if (x0 >= 0 && x0 + taps <= int64_t(width)) {
      dst[i] = uncovered_before[size_t(x0 + taps)] != uncovered_before[size_t(x0)];
    } else {
      uint8_t gap = 0;
      for (int t = 0; t < taps && !gap; ++t) gap = !cov[addr(x0 + t, width, mode)];
      dst[i] = gap;
    }
  }
}

// The mean of the covered texels of output texel (i, j)'s 2x2 footprint (clamped at odd sizes,
// each texel once) into `a`; false when none is covered.
bool covered_box(const RowBand& src, const CoverageBand& cov, uint32_t i, uint32_t j, double* a) {
  const uint32_t ch = src.channels;
  const uint32_t xs[2] = {2 * i, std::min(2 * i + 1, src.width - 1)};
  const uint32_t ys[2] = {2 * j, std::min(2 * j + 1, cov.height - 1)};
  double sum[4] = {0, 0, 0, 0};
  int n = 0;
  for (int r = 0; r < (ys[1] != ys[0] ? 2 : 1); ++r) {
    const uint8_t* c = cov.row(ys[r]);
    const float* s = src.row(ys[r]);
    for (int q = 0; q < (xs[1] != xs[0] ? 2 : 1); ++q) {
      if (!c[xs[q]]) continue;
      ++n;
      for (uint32_t k = 0; k < ch; ++k) sum[k] += double(s[size_t(xs[q]) * ch + k]);
    }
  }
  if (n == 0) return false;
  for (uint32_t k = 0; k < ch; ++k) a[k] = sum[k] / n;
  return true;
}

// The filters' names, written once for to_string and parse_mip_filter.
struct MipFilterName {
  MipFilter filter;
  const char* name;
};
constexpr MipFilterName kMipFilterNames[] = {
    {MipFilter::kBox, "box"},
    {MipFilter::kKaiser, "kaiser"},
    {MipFilter::kLanczos3, "lanczos3"},
};

}  // namespace

const char* to_string(MipFilter f) {
  for (const MipFilterName& n : kMipFilterNames)
    if (n.filter == f) return n.name;
  return "?";
}

Expected<MipFilter> parse_mip_filter(const char* name) {
  std::string n = name ? name : "";
  if (n == "lanczos") return MipFilter::kLanczos3;  // the alias users write
  for (const MipFilterName& f : kMipFilterNames)
    if (n == f.name) return f.filter;
  return Status(ErrorCode::kInvalidArgument,
                "unknown filter '" + n + "' (expected box, kaiser or lanczos3)");
}

DownsampleKernel make_downsample_kernel(MipFilter filter) {
  // Source texel 2i + t has its centre at (t - 0.5) / 2 destination texels from texel i's.
  int half = int(std::ceil(2.0 * support(filter) + 0.5)) - 1;  // box 1, 3-lobe filters 6
  DownsampleKernel k;
  k.first = 1 - half;
  double sum = 0.0;
  for (int t = k.first; t <= half; ++t) {
    double v = filter_value(filter, (t - 0.5) / 2.0);
    k.weights.push_back(v);
    sum += v;
  }
  for (double& v : k.weights) v /= sum;
  return k;
}

DownsampleRules downsample_rules_for(const LayerSpec& spec, uint32_t work_channels) {
  DownsampleRules rules;
  rules.address = spec.address_mode;
  if (spec.semantic == LayerSemantic::kNormal) {
    rules.renormalize_xyz = true;
    for (int c = 0; c < 3; ++c) rules.min_value[c] = -1, rules.max_value[c] = 1;
    return rules;
  }
  const bool u8 = spec.texel_type == TexelType::kU8, colour = is_colour(spec.semantic);
  for (uint32_t c = 0; c < work_channels && c < 4; ++c) {
    if (u8 || colour) rules.min_value[c] = 0;
    if (u8 && !colour) rules.max_value[c] = 1;
  }
  if (colour && work_channels == 4) rules.max_value[3] = 1, rules.premultiplied_alpha = 3;
  return rules;
}

void downsample_rows(const DownsampleKernel& kernel, const DownsampleRules& rules,
                     const RowBand& src, uint32_t y0, uint32_t y1, float* out,
                     const CoverageBand* coverage) {
  const uint32_t ch = src.channels;
  const uint32_t dw = (src.width + 1) / 2;
  const int taps = kernel.taps();
  const size_t drow = size_t(dw) * ch;
  // Output rows are made in chunks so the horizontal pass' double rows stay small.
  constexpr uint32_t kChunk = 8;
  std::vector<double> hrows;
  std::vector<double> acc(drow);
  std::vector<uint8_t> hgaps, gaps(coverage ? dw : 0);  // gap_row's, per source row; per output
  std::vector<uint32_t> uncovered_before;
  for (uint32_t c0 = y0; c0 < y1; c0 += kChunk) {
    uint32_t c1 = std::min(y1, c0 + kChunk);
    int64_t s0 = int64_t(2) * c0 + kernel.first;
    int64_t s1 = int64_t(2) * (c1 - 1) + kernel.first + taps;
    hrows.resize(size_t(s1 - s0) * drow);
    for (int64_t y = s0; y < s1; ++y) {
      filter_row(kernel, rules.address, src.row(y), src.width, ch,
                 hrows.data() + size_t(y - s0) * drow);
    }
    if (coverage) {
      hgaps.resize(size_t(s1 - s0) * dw);
      for (int64_t y = s0; y < s1; ++y) {
        gap_row(kernel, rules.address, coverage->row(y), src.width, uncovered_before,
                hgaps.data() + size_t(y - s0) * dw);
      }
    }
    for (uint32_t j = c0; j < c1; ++j) {
      std::fill(acc.begin(), acc.end(), 0.0);
      int64_t first_row = int64_t(2) * j + kernel.first - s0;
      for (int t = 0; t < taps; ++t) {
        const double* h = hrows.data() + size_t(first_row + t) * drow;
        double w = kernel.weights[t];
        for (size_t i = 0; i < drow; ++i) acc[i] += w * h[i];
      }
      if (coverage) {
        std::fill(gaps.begin(), gaps.end(), uint8_t(0));
        for (int t = 0; t < taps; ++t) {
          const uint8_t* g = hgaps.data() + size_t(first_row + t) * dw;
          for (uint32_t i = 0; i < dw; ++i) gaps[i] |= g[i];
        }
      }
      float* o = out + size_t(j - y0) * drow;
      for (uint32_t i = 0; i < dw; ++i) {
        double* a = acc.data() + size_t(i) * ch;
        if (coverage && gaps[i]) covered_box(src, *coverage, i, j, a);
        if (rules.renormalize_xyz && ch >= 3) {
          double len = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
          if (len > 1e-30 && std::isfinite(len)) {
            a[0] /= len, a[1] /= len, a[2] /= len;
          } else {
            a[0] = 0, a[1] = 0, a[2] = 1;
          }
        }
        if (const int pa = rules.premultiplied_alpha; pa >= 0 && a[pa] > rules.max_value[pa]) {
          const double scale = rules.max_value[pa] / a[pa];
          for (uint32_t c = 0; c < ch; ++c) a[c] *= scale;
        }
        for (uint32_t c = 0; c < ch; ++c) {
          double v = std::clamp(a[c], double(rules.min_value[c]), double(rules.max_value[c]));
          o[size_t(i) * ch + c] = float(v);
        }
      }
    }
  }
}

std::vector<float> downsample_level(const DownsampleKernel& kernel, const DownsampleRules& rules,
                                    const float* texels, uint32_t width, uint32_t height,
                                    uint32_t channels, const uint8_t* coverage) {
  // Build an addressed band covering every tap of every output row.
  const uint32_t dh = (height + 1) / 2, dw = (width + 1) / 2;
  int64_t b0 = kernel.first;
  int64_t b1 = int64_t(2) * (dh - 1) + kernel.first + kernel.taps();
  const size_t row = size_t(width) * channels;
  std::vector<float> band(size_t(b1 - b0) * row);
  std::vector<uint8_t> cov_band(coverage ? size_t(b1 - b0) * width : 0);
  for (int64_t y = b0; y < b1; ++y) {
    int64_t sy = addr(y, height, rules.address);
    std::memcpy(band.data() + size_t(y - b0) * row, texels + size_t(sy) * row, row * sizeof(float));
    if (coverage) {
      std::memcpy(cov_band.data() + size_t(y - b0) * width, coverage + size_t(sy) * width, width);
    }
  }
  RowBand src{b0, uint32_t(b1 - b0), width, channels, band.data()};
  const CoverageBand cov{b0, uint32_t(b1 - b0), width, height, cov_band.data()};
  std::vector<float> out(size_t(dw) * dh * channels);
  downsample_rows(kernel, rules, src, 0, dh, out.data(), coverage ? &cov : nullptr);
  return out;
}

void renormalize_normals(float* texels, size_t count, uint32_t channels) {
  if (channels < 3) return;
  for (size_t i = 0; i < count; ++i) {
    float* n = texels + i * channels;
    double x = n[0], y = n[1], z = n[2];
    double len = std::sqrt(x * x + y * y + z * z);
    if (len > 1e-30 && std::isfinite(len)) {
      n[0] = float(x / len), n[1] = float(y / len), n[2] = float(z / len);
    } else {
      n[0] = 0, n[1] = 0, n[2] = 1;
    }
  }
}

std::vector<uint8_t> downsample_coverage(const uint8_t* coverage, uint32_t width, uint32_t height) {
  const uint32_t dw = (width + 1) / 2, dh = (height + 1) / 2;
  std::vector<uint8_t> out(size_t(dw) * dh);
  for (uint32_t j = 0; j < dh; ++j) {
    uint32_t ya = 2 * j, yb = std::min(2 * j + 1, height - 1);
    for (uint32_t i = 0; i < dw; ++i) {
      uint32_t xa = 2 * i, xb = std::min(2 * i + 1, width - 1);
      bool any = coverage[size_t(ya) * width + xa] || coverage[size_t(ya) * width + xb] ||
                 coverage[size_t(yb) * width + xa] || coverage[size_t(yb) * width + xb];
      out[size_t(j) * dw + i] = any ? 1 : 0;
    }
  }
  return out;
}

uint64_t pull_push(float* texels, const uint8_t* coverage, uint32_t width, uint32_t height,
                   uint32_t channels) {
  const size_t n = size_t(width) * height;
  uint64_t uncovered = 0;
  for (size_t i = 0; i < n; ++i) uncovered += !coverage[i];
  if (uncovered == 0 || uncovered == n) return 0;
  // Pull: coverage-weighted 2x2 averages down to 1x1, weights and weighted sums in double.
  // Level 0 is never copied to double: its covered texels are added straight into level 1 (an
  // uncovered texel's zero sum and weight would change no sum, which starts at +0 and so is
  // never -0), and its uncovered texels take level 1's averages below. The same bytes as
  // pulling a double copy of level 0, in less than a fifth of the memory.
  struct Level {
    uint32_t w, h;
    std::vector<double> sum;     // weighted sums, channels per texel
    std::vector<double> weight;  // covered-texel counts
  };
  std::vector<Level> levels;
  {
    Level d{(width + 1) / 2, (height + 1) / 2, {}, {}};
    d.sum.assign(size_t(d.w) * d.h * channels, 0.0);
    d.weight.assign(size_t(d.w) * d.h, 0.0);
    for (uint32_t y = 0; y < height; ++y) {
      for (uint32_t x = 0; x < width; ++x) {
        const size_t si = size_t(y) * width + x, di = size_t(y / 2) * d.w + x / 2;
        if (!coverage[si]) continue;
        d.weight[di] += 1.0;
        for (uint32_t c = 0; c < channels; ++c)
          d.sum[di * channels + c] += texels[si * channels + c];
      }
    }
    levels.push_back(std::move(d));
  }
  while (levels.back().w > 1 || levels.back().h > 1) {
    const Level& s = levels.back();
    Level d{(s.w + 1) / 2, (s.h + 1) / 2, {}, {}};
    d.sum.assign(size_t(d.w) * d.h * channels, 0.0);
    d.weight.assign(size_t(d.w) * d.h, 0.0);
    for (uint32_t y = 0; y < s.h; ++y) {
      for (uint32_t x = 0; x < s.w; ++x) {
        size_t si = size_t(y) * s.w + x, di = size_t(y / 2) * d.w + x / 2;
        d.weight[di] += s.weight[si];
        for (uint32_t c = 0; c < channels; ++c) {
          d.sum[di * channels + c] += s.sum[si * channels + c];
        }
      }
    }
    levels.push_back(std::move(d));
  }
  // Push: a texel with no covered texel under it takes its parent's average, coarse to fine,
  // each level then filled in normalised form so that its children divide by 1.
  for (size_t li = levels.size() - 1; li-- > 0;) {
    Level& f = levels[li];
    const Level& p = levels[li + 1];
    for (uint32_t y = 0; y < f.h; ++y) {
      for (uint32_t x = 0; x < f.w; ++x) {
        size_t fi = size_t(y) * f.w + x;
        if (f.weight[fi] > 0.0) continue;
        size_t pi = size_t(y / 2) * p.w + x / 2;
        double pw = p.weight[pi];  // > 0 after the parent's own push
        f.weight[fi] = 1.0;
        for (uint32_t c = 0; c < channels; ++c) {
          f.sum[fi * channels + c] = p.sum[pi * channels + c] / pw;
        }
      }
    }
    for (size_t i = 0; i < size_t(f.w) * f.h; ++i) {
      double w = f.weight[i];
      if (w == 1.0) continue;
      for (uint32_t c = 0; c < channels; ++c) f.sum[i * channels + c] /= w;
      f.weight[i] = 1.0;
    }
  }
  // Level 0's uncovered texels: level 1's average (its weights are 1 now).
  const Level& p = levels[0];
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      const size_t i = size_t(y) * width + x;
      if (coverage[i]) continue;
      const size_t pi = size_t(y / 2) * p.w + x / 2;
      const double pw = p.weight[pi];
      for (uint32_t c = 0; c < channels; ++c)
        texels[i * channels + c] = float(p.sum[pi * channels + c] / pw);
    }
  }
  return uncovered;
}

void unpremultiply_page(float* texels, uint32_t side, uint32_t channels, int alpha) {
  const size_t count = size_t(side) * side;
  thread_local std::vector<uint8_t> has_alpha;
  has_alpha.resize(count);
  for (size_t i = 0; i < count; ++i) has_alpha[i] = texels[i * channels + alpha] > 0;
  const bool bled = pull_push(texels, has_alpha.data(), side, side, channels) > 0;
  constexpr float kFloatMax = std::numeric_limits<float>::max();
  for (size_t i = 0; i < count; ++i) {
    float* t = texels + i * channels;
    // A bled texel divides by its pulled alpha: the weighted mean of its neighbours' colour.
    const float a = t[alpha];
    for (int c = 0; c < 3; ++c) t[c] = a > 0 ? std::min(t[c] / a, kFloatMax) : 0.0f;
    if (bled && !has_alpha[i]) t[alpha] = 0.0f;
  }
}

}  // namespace vt
