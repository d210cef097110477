// Colour conversion through OpenColorIO with a config generated in code (Debian's OCIO 2.1 has
// no built-in configs): "linear" (the working space: linear Rec.709/sRGB primaries), "sRGB"
// (the sRGB transfer curve) and "raw" (data, never converted). Common aliases are accepted.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "common/status.h"

namespace vt {

// Canonical name of a supported colour space ("linear", "sRGB", "raw"), or kNotFound naming
// the spaces vtbake knows.
Expected<std::string> canonical_color_space(const std::string& name);

// Converts RGB(A) float texels between two colour spaces; alpha is left alone. Thread-safe
// after creation. Channels 1 and 2 convert the first channel as grey.
class ColorConverter {
 public:
  static Expected<std::unique_ptr<ColorConverter>> create(const std::string& from,
                                                          const std::string& to);
  virtual ~ColorConverter() = default;
  virtual bool is_identity() const = 0;
  // Converts `count` texels of `channels` (1..4) interleaved floats in place. Values that are
  // 8-bit codes (k / 255, however rounded) go through a 256-entry table OpenColorIO filled.
  virtual void apply(float* texels, size_t count, int channels) const = 0;
  // apply() followed by rounding to 8 bits (clamped to [0, 1]), without a per-texel power:
  // the colour channels are compared against the 255 code boundaries, found exactly (by
  // bisection over floats) through OpenColorIO when the converter was made. Alpha (channel 3,
  // or 1 for grey+alpha) is rounded as it is.
  virtual void apply_to_u8(const float* texels, size_t count, int channels, uint8_t* out) const = 0;
};

// The generated config as OCIO YAML, for provenance and for users who want to reproduce it.
std::string color_config_yaml();

}  // namespace vt
