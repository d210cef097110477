// ColorConverter over an OpenColorIO CPU processor (see color.h). Curves (no channel crosstalk)
// get an 8-bit code table and exact 8-bit code boundaries, so that the build converts whole
// levels without a per-texel power; matrices go through the processor.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "bake/color_ocio.h"
#include "common/srgb.h"

namespace vt {
namespace {

inline uint8_t round_u8(float v) {
  if (!(v > 0)) return 0;
  if (v >= 1) return 255;
  return uint8_t(v * 255.0f + 0.5f);
}

// Ordered integer key of a float (monotonic for all non-NaN floats).
inline int32_t float_key(float f) {
  int32_t i;
  std::memcpy(&i, &f, 4);
  return i >= 0 ? i : int32_t(0x80000000u - uint32_t(i));
}
inline float key_float(int32_t k) {
  int32_t i = k >= 0 ? k : int32_t(0x80000000u - uint32_t(k));
  float f;
  std::memcpy(&f, &i, 4);
  return f;
}

class OcioConverter final : public ColorConverter {
 public:
  OcioConverter(OCIO::ConstProcessorRcPtr processor, bool srgb_decode) : srgb_decode_(srgb_decode) {
    if (processor) cpu_ = processor->getOptimizedCPUProcessor(OCIO::OPTIMIZATION_DEFAULT);
    if (srgb_decode_) {
      for (int i = 0; i <= kCurveSteps; ++i) curve_[i] = srgb_to_linear(float(i) / kCurveSteps);
    }
    if (is_identity()) return;
    per_channel_ = !cpu_->hasChannelCrosstalk();
    if (per_channel_) make_tables();
  }
  bool is_identity() const override { return !cpu_ || cpu_->isNoOp(); }

  void apply(float* texels, size_t count, int channels) const override {
    if (is_identity() || count == 0) return;
    const int colour = channels >= 3 ? 3 : 1;
    for (size_t i = 0; i < count; ++i) {
      float* t = texels + i * channels;
      bool coded = per_channel_;
      int code[3] = {0, 0, 0};
      for (int c = 0; c < colour && coded; ++c) {
        float v = t[c];
        int k = (v >= 0.0f && v <= 1.0f) ? int(v * 255.0f + 0.5f) : -1;
        code[c] = k;
        coded &= k >= 0 && std::abs(v * 255.0f - float(k)) <= 1e-4f;  // any k/255 rounding
      }
      if (coded) {
        for (int c = 0; c < colour; ++c) t[c] = lut_[code[c]];
      } else if (colour == 3) {
        cpu_->applyRGB(t);
      } else {
        t[0] = convert_one(t[0]);
      }
    }
  }

  void apply_to_u8(const float* texels, size_t count, int channels, uint8_t* out) const override {
    const int colour = is_identity() ? 0 : channels >= 3 ? 3 : 1;
    std::vector<float> converted;
    if (colour && !per_channel_) {
      converted.assign(texels, texels + count * channels);
      apply(converted.data(), count, channels);
      for (size_t i = 0; i < count * size_t(channels); ++i) out[i] = round_u8(converted[i]);
      return;
    }
    for (size_t i = 0; i < count; ++i) {
      const float* t = texels + i * channels;
      uint8_t* o = out + i * channels;
      for (int c = 0; c < colour; ++c) o[c] = encode_u8(t[c]);
      for (int c = colour; c < channels; ++c) o[c] = round_u8(t[c]);
    }
  }

  void apply_rgb(float rgb[3]) const override {
    if (srgb_decode_) {
      for (int c = 0; c < 3; ++c) {
        const float v = std::max(rgb[c], 0.0f);
        if (v < 1.0f) {  // the curve's table, linearly interpolated
          const float x = v * float(kCurveSteps);
          const int i = int(x);
          const float f = x - float(i);
          rgb[c] = curve_[i] + f * (curve_[i + 1] - curve_[i]);
        } else {
          rgb[c] = srgb_to_linear(v);
        }
      }
    } else if (!is_identity()) {
      cpu_->applyRGB(rgb);
    }
  }

 private:
  static constexpr int kBucketShift = 15;
  // apply_rgb's sRGB decode: srgb_to_linear at kCurveSteps + 1 points of [0, 1], interpolated
  // linearly (interpolation error below 1e-8: linear below the knee, curvature below 1.2
  // above it; float rounding up to 3e-7 near 1).
  static constexpr int kCurveSteps = 4096;
  float curve_[kCurveSteps + 1] = {};

  void make_tables() {
    for (int k = 0; k < 256; ++k) lut_[k] = convert_one(float(k) / 255.0f);
    // Boundary k (1..255): the smallest float whose converted, rounded code is >= k. The curves
    // vtbake converts with are increasing, so bisection over ordered floats finds it exactly.
    for (int k = 1; k < 256; ++k) {
      int64_t lo = float_key(-1.0f), hi = float_key(3.4e38f);
      while (hi - lo > 1) {
        int64_t mid = lo + (hi - lo) / 2;
        if (round_u8(convert_one(key_float(int32_t(mid)))) >= k) {
          hi = mid;
        } else {
          lo = mid;
        }
      }
      bounds_[k - 1] = key_float(int32_t(hi));
    }
    // Code of the first float of every bucket of 2^15 floats in [0, 1]; a bucket spans at most
    // a few codes, so encode_u8 steps up from there.
    bucket_code_.resize((0x3F800000u >> kBucketShift) + 1);
    for (size_t b = 0; b < bucket_code_.size(); ++b) {
      uint32_t bits = uint32_t(b) << kBucketShift;
      float v;
      std::memcpy(&v, &bits, 4);
      bucket_code_[b] = uint8_t(std::upper_bound(bounds_, bounds_ + 255, v) - bounds_);
    }
  }

  uint8_t encode_u8(float v) const {
    if (!(v > 0)) return 0;  // NaN too
    if (v >= 1.0f) return round_u8(convert_one(v));
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    int code = bucket_code_[bits >> kBucketShift];
    while (code < 255 && v >= bounds_[code]) ++code;
    return uint8_t(code);
  }

  float convert_one(float v) const {
    float rgb[3] = {v, v, v};
    cpu_->applyRGB(rgb);
    return rgb[0];
  }

  OCIO::ConstCPUProcessorRcPtr cpu_;
  bool srgb_decode_ = false;
  bool per_channel_ = true;
  float lut_[256] = {};
  float bounds_[255] = {};
  std::vector<uint8_t> bucket_code_;
};

}  // namespace

std::unique_ptr<ColorConverter> make_color_converter(OCIO::ConstProcessorRcPtr processor,
                                                     bool srgb_decode) {
  return std::make_unique<OcioConverter>(std::move(processor), srgb_decode);
}

}  // namespace vt
