// Mip pyramid filtering: 2x downsampling of float texels (box, Kaiser, Lanczos-3) computed in
// double so that HDR values up to float max never overflow, and pull-push dilation of texels
// that no chart covers. Works on bands of rows so that a level never has to be in memory whole.
// Callers store colour in linear light, alpha-premultiplied; normals as unit xyz vectors.
#pragma once

#include <cstdint>
#include <vector>

#include "common/status.h"
#include "format/page_file.h"
#include "format/page_geometry.h"

namespace vt {

enum class MipFilter : uint8_t { kBox = 0, kKaiser = 1, kLanczos3 = 2 };
const char* to_string(MipFilter f);
// "box", "kaiser", "lanczos3"; kInvalidArgument otherwise.
Expected<MipFilter> parse_mip_filter(const char* name);

// Destination texel i of a 2x reduction is sum_k weights[k] * src[2i + first + k].
// Weights are symmetric about src coordinate 2i + 0.5 and sum to 1; taps is even.
struct DownsampleKernel {
  int first = 0;
  std::vector<double> weights;
  int taps() const { return int(weights.size()); }
  // Rows (or columns) a band of the source needs beyond the rows it reduces, on either side.
  int reach() const { return -first > first + taps() - 2 ? -first : first + taps() - 2; }
};
DownsampleKernel make_downsample_kernel(MipFilter filter);

// Rows of one level held in memory: row k of `data` is the level row address_texel(y_begin + k)
// (rows past the level's edge already resolved by the address mode), `width` texels of
// `channels` floats each.
struct RowBand {
  int64_t y_begin = 0;
  uint32_t rows = 0;
  uint32_t width = 0;
  uint32_t channels = 0;
  const float* data = nullptr;
  bool has(int64_t y) const { return y >= y_begin && y < y_begin + int64_t(rows); }
  const float* row(int64_t y) const { return data + size_t(y - y_begin) * width * channels; }
};

// Which texels of a RowBand's rows some chart covers: one byte per texel (non-zero = covered),
// the same rows as the band (past the level's edge resolved by the same address mode). `height`
// is the level's: the 2x2 footprint is clamped at odd sizes as downsample_coverage clamps it.
struct CoverageBand {
  int64_t y_begin = 0;
  uint32_t rows = 0;
  uint32_t width = 0;
  uint32_t height = 0;
  const uint8_t* data = nullptr;
  const uint8_t* row(int64_t y) const { return data + size_t(y - y_begin) * width; }
};

// Post-filter treatment of each output texel.
struct DownsampleRules {
  AddressMode address = AddressMode::kClamp;  // for columns past the row's edge
  bool renormalize_xyz = false;               // channels 0-2 are a normal: rescale to unit length
  float min_value[4] = {-3.4028235e38f, -3.4028235e38f, -3.4028235e38f, -3.4028235e38f};
  float max_value[4] = {3.4028235e38f, 3.4028235e38f, 3.4028235e38f, 3.4028235e38f};
  // The alpha channel colour is premultiplied by, or -1: where a filter's overshoot takes alpha
  // past its max_value, colour is scaled down with it (clamping alpha alone brightened the
  // straight colour at alpha edges by the overshoot, up to a few percent with Kaiser).
  int premultiplied_alpha = -1;
};

// The rules of a layer's levels from its spec and working channels (3 for a normal map, 4 for
// colour with alpha): normals renormalised in [-1, 1], colour non-negative with alpha at most 1
// (colour scaled with its overshoot), 8-bit data in [0, 1], float data as filtered. The build's
// plan and the validator's reference pyramid both take them from here.
DownsampleRules downsample_rules_for(const LayerSpec& spec, uint32_t work_channels);

// Computes rows [y0, y1) of the half-size level (width (src.width + 1) / 2) into `out`. `src`
// must hold rows 2*y0 + first .. 2*(y1-1) + first + taps - 1. Each output row depends only on
// its inputs, so any split of [y0, y1) over threads gives the same bytes.
//
// With `coverage` (the source's, same rows as `src`), a covered output texel (some texel of its
// 2x2 footprint covered) whose filter taps reach an uncovered texel is instead the mean of the
// covered texels of its 2x2 footprint: the filter never reads the dilated gutter, nor across
// it a neighbouring chart. Charts `padding` texels apart at level 0 then share no texel through
// level log2(padding) (levels 1-3 at padding 8); past it the gutter is under one texel and
// charts meet. Without it every texel is filtered alike (a plain image).
void downsample_rows(const DownsampleKernel& kernel, const DownsampleRules& rules,
                     const RowBand& src, uint32_t y0, uint32_t y1, float* out,
                     const CoverageBand* coverage = nullptr);

// Whole-level convenience for small images: returns the (w+1)/2 x (h+1)/2 level; `coverage`
// (width x height bytes, or null) as downsample_rows'.
std::vector<float> downsample_level(const DownsampleKernel& kernel, const DownsampleRules& rules,
                                    const float* texels, uint32_t width, uint32_t height,
                                    uint32_t channels, const uint8_t* coverage = nullptr);

// Rescales xyz vectors to unit length; a zero or non-finite vector becomes (0, 0, 1).
void renormalize_normals(float* texels, size_t count, uint32_t channels);

// Coverage of the half-size level: a texel is covered when any texel of its 2x2 footprint is
// (the footprint's second row/column is clamped at odd sizes).
std::vector<uint8_t> downsample_coverage(const uint8_t* coverage, uint32_t width, uint32_t height);

// Pull-push dilation: every texel whose coverage is 0 gets the coverage-weighted average of the
// covered texels around it, taken from the coarsest averaging level that reaches one, so that a
// filter reading across a chart's edge reads chart-like colour, never the background. Covered
// texels are unchanged. A level with no covered texel is left as it is. Returns the number of
// texels filled.
uint64_t pull_push(float* texels, const uint8_t* coverage, uint32_t width, uint32_t height,
                   uint32_t channels);

// A side x side page of premultiplied colour (alpha channel `alpha`) to straight colour, as
// pages are stored. Colour under zero alpha, lost in premultiplied form, takes the
// alpha-weighted colour of the nearest texels with alpha (pull-push over the page) rather than
// black: the run time filters straight colour, and black there would fringe every alpha edge.
// A page's border holds every texel a filter reads beside its payload, so the page alone decides.
void unpremultiply_page(float* texels, uint32_t side, uint32_t channels, int alpha);

}  // namespace vt
