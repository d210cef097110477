// Error metrics for HDR (half-float) texels, where 8-bit PSNR says nothing: the error in log
// space, |L(a) - L(b)| with L(x) = sign(x) * log2(1 + |x|) (about stops for bright values, linear
// near 0, so black noise does not dominate), its mean and maximum; and the PSNR after a tone map,
// T(x) = sign(x) * srgb(|x| / (1 + |x|)) (Reinhard, then the sRGB curve a display applies), peak
// 1. Inputs are half floats; NaN counts as 0 and infinities as +-65504, as BC6H holds them.
#pragma once

#include <cstddef>
#include <cstdint>

namespace vt {

struct HdrError {
  uint64_t samples = 0;       // channel values compared
  double log_abs_sum = 0;     // sum of |L(a) - L(b)|
  double log_abs_max = 0;     // largest |L(a) - L(b)|
  double tonemapped_sse = 0;  // sum of (T(a) - T(b))^2
  double relative_max = 0;    // largest |a - b| / max(|a|, 2^-14) (the smallest normal half)

  void add(const HdrError& other);
  double log_abs_mean() const { return samples ? log_abs_sum / double(samples) : 0; }
  // Infinite when nothing differs.
  double tonemapped_psnr_db() const;
};

// Compares `texels` texels of `channels` half floats each (native byte order; any alignment),
// over the first `kept` channels, adding into `out`.
void add_hdr_error(const void* reference, const void* test, size_t texels, int channels, int kept,
                   HdrError& out);
// The same against float values (what a half layer was made from: its storage rounds them to
// half, a relative error up to 2^-11, and clips beyond +-65504): NaN counts as 0 and
// infinities as +-FLT_MAX.
void add_hdr_error(const float* reference, const void* test, size_t texels, int channels, int kept,
                   HdrError& out);

// The metric's maps, for tests and tools.
double hdr_log_value(float x);
double hdr_tonemap(float x);

}  // namespace vt
