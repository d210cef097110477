// Procedural images the project makes itself (no downloads): the bundled sample, test inputs and
// benchmark inputs of any size, generated row by row so that even a 64K x 64K source costs no
// memory.
#pragma once

#include <cstdint>

#include "bake/image_source.h"

namespace vt {

enum class ProceduralPattern : uint8_t {
  kAlbedo = 0,  // sRGB colour: gradient, hashed cells, fine lines and noise, a flat region
  kNormal = 1,  // tangent-space normal map (n * 0.5 + 0.5) of bumps and ridges
};

// Deterministic for (pattern, width, height, channels, seed). Albedo with 4 channels has an
// alpha ramp; 8-bit-like values (multiples of 1/255).
class ProceduralImageSource final : public ImageSource {
 public:
  ProceduralImageSource(ProceduralPattern pattern, uint32_t width, uint32_t height,
                        uint32_t channels = 3, uint32_t seed = 1);
  const ImageInfo& info() const override { return info_; }
  Status read_rows(uint32_t y0, uint32_t y1, float* out) override;
  // The generator's parameters decide every texel.
  Expected<uint64_t> content_hash() override;

 private:
  ProceduralPattern pattern_;
  ImageInfo info_;
  uint32_t seed_;
};

}  // namespace vt
