// The one whole-image reader of a scene's images (OpenImageIO, files or embedded bytes), with the
// transfer's channel rules (bake/transfer.cpp sample_texture): grey -> (g, g, g, 1), grey + alpha
// -> (g, g, g, a), RGB -> alpha 1. The validator's reference and lit reference passes and the
// lighting baker's alpha-masked shadows (bake/lighting.cpp) build on it.
#pragma once

#include <cstdint>
#include <vector>

#include "common/status.h"
#include "scene/scene.h"

namespace vt::scene {

struct FloatImage {
  uint32_t width = 0, height = 0;
  uint32_t channels = 0;  // in the file
  bool is_float = false;  // a float file: linear values; otherwise the file's encoding (sRGB)
  std::vector<float> rgba;
  const float* at(uint32_t x, uint32_t y) const { return &rgba[(size_t(y) * width + x) * 4]; }
};

// Errors name the image: kNotFound when it cannot be opened, kCorrupt when it cannot be read or
// has a size of 0 or over 65536 per side.
Expected<FloatImage> load_float_image(const scene::Image& image);

}  // namespace vt::scene
