// HDR error metrics (see hdr_metrics.h).
#include "codec/hdr_metrics.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>

#include "common/half.h"
#include "common/srgb.h"

namespace vt {
namespace {

float sane(uint16_t h) {
  const float f = half_to_float(h);
  if (std::isnan(f)) return 0.0f;
  return std::clamp(f, -kHalfMax, kHalfMax);
}

}  // namespace

double hdr_log_value(float x) {
  const double a = std::log2(1.0 + std::fabs(double(x)));
  return x < 0 ? -a : a;
}

double hdr_tonemap(float x) {
  const float a = std::fabs(x);
  const double t = double(linear_to_srgb(a / (1.0f + a)));
  return x < 0 ? -t : t;
}

void HdrError::add(const HdrError& o) {
  samples += o.samples;
  log_abs_sum += o.log_abs_sum;
  log_abs_max = std::max(log_abs_max, o.log_abs_max);
  tonemapped_sse += o.tonemapped_sse;
  relative_max = std::max(relative_max, o.relative_max);
}

double HdrError::tonemapped_psnr_db() const {
  if (samples == 0 || tonemapped_sse <= 0) return INFINITY;
  return 10.0 * std::log10(double(samples) / tonemapped_sse);
}

namespace {

float sane_float(float f) {
  if (std::isnan(f)) return 0.0f;
  return std::clamp(f, -FLT_MAX, FLT_MAX);
}

void add_sample(float a, float b, HdrError& out) {
  const double dl = std::fabs(hdr_log_value(a) - hdr_log_value(b));
  out.log_abs_sum += dl;
  out.log_abs_max = std::max(out.log_abs_max, dl);
  const double dt = hdr_tonemap(a) - hdr_tonemap(b);
  out.tonemapped_sse += dt * dt;
  const double rel = std::fabs(double(a) - double(b)) / std::max(std::fabs(double(a)), 0x1p-14);
  out.relative_max = std::max(out.relative_max, rel);
}

uint16_t half_at(const uint8_t* p, size_t t, int channels, int c) {
  uint16_t h;
  std::memcpy(&h, p + (t * size_t(channels) + size_t(c)) * 2, 2);
  return h;
}

}  // namespace

void add_hdr_error(const void* reference, const void* test, size_t texels, int channels, int kept,
                   HdrError& out) {
  const auto* ra = static_cast<const uint8_t*>(reference);
  const auto* rb = static_cast<const uint8_t*>(test);
  kept = std::clamp(kept, 0, channels);
  for (size_t t = 0; t < texels; ++t) {
    for (int c = 0; c < kept; ++c) {
      const uint16_t ha = half_at(ra, t, channels, c), hb = half_at(rb, t, channels, c);
      ++out.samples;
      if (ha != hb) add_sample(sane(ha), sane(hb), out);
    }
  }
}

void add_hdr_error(const float* reference, const void* test, size_t texels, int channels, int kept,
                   HdrError& out) {
  const auto* rb = static_cast<const uint8_t*>(test);
  kept = std::clamp(kept, 0, channels);
  for (size_t t = 0; t < texels; ++t) {
    for (int c = 0; c < kept; ++c) {
      const float a = sane_float(reference[t * size_t(channels) + size_t(c)]);
      const float b = sane(half_at(rb, t, channels, c));
      ++out.samples;
      if (a != b) add_sample(a, b, out);
    }
  }
}

}  // namespace vt
