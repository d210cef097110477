#include "bake/color.h"

#include <OpenColorIO/OpenColorIO.h>

#include <algorithm>
#include <cctype>
#include <mutex>
#include <sstream>
#include <vector>

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
  // IEC 61966-2-1: linear segment below 0.04045, 2.4 power above; ExponentWithLinear is the
  // exact curve (not the 2.2 approximation).
  auto curve = OCIO::ExponentWithLinearTransform::Create();
  curve->setGamma({2.4, 2.4, 2.4, 1.0});
  curve->setOffset({0.055, 0.055, 0.055, 0.0});
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

class OcioConverter final : public ColorConverter {
 public:
  explicit OcioConverter(OCIO::ConstCPUProcessorRcPtr cpu) : cpu_(std::move(cpu)) {}
  bool is_identity() const override { return !cpu_ || cpu_->isNoOp(); }
  void apply(float* texels, size_t count, int channels) const override {
    if (is_identity() || count == 0) return;
    if (channels >= 3) {
      OCIO::PackedImageDesc desc(texels, long(count), 1, channels);
      cpu_->apply(desc);
      return;
    }
    // Grey (+alpha): convert the grey value as R=G=B.
    for (size_t i = 0; i < count; ++i) {
      float rgb[3] = {texels[i * channels], texels[i * channels], texels[i * channels]};
      cpu_->applyRGB(rgb);
      texels[i * channels] = rgb[0];
    }
  }

 private:
  OCIO::ConstCPUProcessorRcPtr cpu_;
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
