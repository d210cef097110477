#include "bake/color.h"

#include <OpenColorIO/OpenColorIO.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <mutex>
#include <sstream>
#include <vector>

#include "common/srgb.h"

namespace vt {
namespace {

namespace OCIO = OCIO_NAMESPACE;

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Built once: Config objects are immutable after setup and safe to share.
OCIO::ConstConfigRcPtr make_config() {
  OCIO::ConfigRcPtr config = OCIO::Config::Create();
  config->setName("vtbake");
  auto linear = OCIO::ColorSpace::Create();
  linear->setName("linear");
  linear->setFamily("vtbake");
  config->addColorSpace(linear);

  auto srgb = OCIO::ColorSpace::Create();
  srgb->setName("sRGB");
  srgb->setFamily("vtbake");
  // common/srgb.h's curve: ExponentWithLinear is the exact one (not the 2.2 approximation).
  auto curve = OCIO::ExponentWithLinearTransform::Create();
  curve->setGamma({kSrgbGamma, kSrgbGamma, kSrgbGamma, 1.0});
  curve->setOffset({kSrgbOffset, kSrgbOffset, kSrgbOffset, 0.0});
  curve->setDirection(OCIO::TRANSFORM_DIR_FORWARD);
  srgb->setTransform(curve, OCIO::COLORSPACE_DIR_TO_REFERENCE);
  config->addColorSpace(srgb);

  auto raw = OCIO::ColorSpace::Create();
  raw->setName("raw");
  raw->setFamily("vtbake");
  raw->setIsData(true);
  config->addColorSpace(raw);

  config->setRole(OCIO::ROLE_SCENE_LINEAR, "linear");
  config->setRole(OCIO::ROLE_DEFAULT, "linear");
  config->setRole(OCIO::ROLE_DATA, "raw");
  return config;
}

const OCIO::ConstConfigRcPtr& config() {
  static const OCIO::ConstConfigRcPtr c = make_config();
  return c;
}

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
  explicit OcioConverter(OCIO::ConstCPUProcessorRcPtr cpu) : cpu_(std::move(cpu)) {
    if (is_identity()) return;
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
  bool is_identity() const override { return !cpu_ || cpu_->isNoOp(); }

  void apply(float* texels, size_t count, int channels) const override {
    if (is_identity() || count == 0) return;
    const int colour = channels >= 3 ? 3 : 1;
    for (size_t i = 0; i < count; ++i) {
      float* t = texels + i * channels;
      bool coded = true;
      int code[3];
      for (int c = 0; c < colour; ++c) {
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
    for (size_t i = 0; i < count; ++i) {
      const float* t = texels + i * channels;
      uint8_t* o = out + i * channels;
      for (int c = 0; c < colour; ++c) o[c] = encode_u8(t[c]);
      for (int c = colour; c < channels; ++c) o[c] = round_u8(t[c]);
    }
  }

 private:
  static constexpr int kBucketShift = 15;

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
  float lut_[256] = {};
  float bounds_[255] = {};
  std::vector<uint8_t> bucket_code_;
};

}  // namespace

Expected<std::string> canonical_color_space(const std::string& name) {
  std::string n = lower(name);
  static const char* kLinear[] = {"linear",      "scene_linear",          "lin_srgb",
                                  "lin_rec709",  "linear rec.709 (srgb)", "srgb linear",
                                  "linear srgb", "rec709 linear",         "acescg"};
  static const char* kSrgb[] = {"srgb",    "srgb_texture", "srgb - texture",
                                "srgb_tx", "srgb texture", "srgb gamma"};
  static const char* kRaw[] = {"raw", "data", "non-color", "utility - raw", "none"};
  for (const char* s : kSrgb)
    if (n == s) return std::string("sRGB");
  for (const char* s : kLinear)
    if (n == s) return std::string("linear");
  for (const char* s : kRaw)
    if (n == s) return std::string("raw");
  return Status(ErrorCode::kNotFound,
                "unknown colour space '" + name + "' (known: linear, sRGB, raw and aliases)");
}

Expected<std::unique_ptr<ColorConverter>> ColorConverter::create(const std::string& from,
                                                                 const std::string& to) {
  VT_ASSIGN_OR_RETURN(std::string src, canonical_color_space(from));
  VT_ASSIGN_OR_RETURN(std::string dst, canonical_color_space(to));
  if (src == dst || src == "raw" || dst == "raw") {
    return std::unique_ptr<ColorConverter>(new OcioConverter(nullptr));
  }
  try {
    auto processor = config()->getProcessor(src.c_str(), dst.c_str());
    return std::unique_ptr<ColorConverter>(
        new OcioConverter(processor->getOptimizedCPUProcessor(OCIO::OPTIMIZATION_DEFAULT)));
  } catch (const OCIO::Exception& e) {
    return Status(ErrorCode::kInternal, std::string("OpenColorIO: ") + e.what());
  }
}

std::string color_config_yaml() {
  std::ostringstream s;
  config()->serialize(s);
  return s.str();
}

}  // namespace vt
