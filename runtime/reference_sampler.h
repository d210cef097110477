// CPU reference sampler: reads a virtual texel through the page table and a physical cache
// image exactly as the renderer's shader does, with bilinear filtering. For raw (uncompressed)
// pages the result equals bilinear sampling of the unpaged level image bit for bit, borders
// included: this is what proves the border rule and the page-table math, and what the GLSL
// mirrors.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "format/page_geometry.h"
#include "runtime/page_table.h"
#include "runtime/streamer.h"

namespace vt {

// An uncompressed physical cache texture of one layer: slots_x x slots_y slots of page_size^2
// texels of `channels` 8-bit channels, row-major.
struct PhysicalImage {
  uint32_t slots_x = 0, slots_y = 0, page_size = 0, channels = 4;
  std::vector<uint8_t> texels;
  uint32_t width() const { return slots_x * page_size; }
  uint32_t height() const { return slots_y * page_size; }
};

PhysicalImage make_physical_image(uint32_t slots_x, uint32_t slots_y, uint32_t page_size,
                                  uint32_t channels);
// Copies a frame's uploads of `layer` (uncompressed 8-bit: RGBA8, RG8, R8) into the image.
Status apply_uploads(PhysicalImage& image, std::span<const PageUpload> uploads, uint32_t layer);

// A level image, unpaged: width x height texels of `channels` 8-bit channels.
struct LevelImageView {
  const uint8_t* texels = nullptr;
  uint32_t width = 0, height = 0, channels = 4;
};

// Bilinear filter at level texel coordinate (tx, ty) (texel centres at i + 0.5), the address
// mode applied per tap, results rounded to 8 bits. The unpaged reference.
void sample_level_bilinear(const LevelImageView& level, AddressMode mode, float tx, float ty,
                           uint8_t* out);

// Samples virtual uv (wrapped for kWrap, clamped to [0, 1] for kClamp) at wanted level `level`
// through `table` and `image`, with the same weights and rounding as sample_level_bilinear.
// Writes image.channels bytes and returns the level actually sampled (entry's B), or an error
// for an invalid entry or a slot outside the image.
Expected<uint32_t> sample_virtual_bilinear(const PageTable& table, const PhysicalImage& image,
                                           AddressMode mode, uint32_t level, float u, float v,
                                           uint8_t* out);

}  // namespace vt
