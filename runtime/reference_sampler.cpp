// Both samplers share blend(): the paged and the unpaged path differ only in where the four
// taps are fetched from, so any difference in their results is a wrong page, slot or border.
#include "runtime/reference_sampler.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace vt {

namespace {

void blend(const uint8_t* t00, const uint8_t* t10, const uint8_t* t01, const uint8_t* t11, float ax,
           float ay, uint32_t channels, uint8_t* out) {
  const float w00 = (1 - ax) * (1 - ay), w10 = ax * (1 - ay), w01 = (1 - ax) * ay, w11 = ax * ay;
  for (uint32_t c = 0; c < channels; ++c) {
    const float v = w00 * t00[c] + w10 * t10[c] + w01 * t01[c] + w11 * t11[c];
    const float r = std::floor(v + 0.5f);
    out[c] = uint8_t(r < 0 ? 0 : (r > 255 ? 255 : r));
  }
}

}  // namespace

PhysicalImage make_physical_image(uint32_t slots_x, uint32_t slots_y, uint32_t page_size,
                                  uint32_t channels) {
  PhysicalImage img;
  img.slots_x = slots_x;
  img.slots_y = slots_y;
  img.page_size = page_size;
  img.channels = channels;
  img.texels.assign(size_t(img.width()) * img.height() * channels, 0);
  return img;
}

Status apply_uploads(PhysicalImage& image, std::span<const PageUpload> uploads, uint32_t layer) {
  const size_t row = size_t(image.page_size) * image.channels;
  for (const PageUpload& u : uploads) {
    if (layer >= u.layers.size() || u.layers[layer].size() != row * image.page_size)
      return Error(ErrorCode::kInvalidArgument,
                   "apply_uploads: upload size does not match an uncompressed slot");
    if (u.slot_x >= image.slots_x || u.slot_y >= image.slots_y)
      return Error(ErrorCode::kInvalidArgument, "apply_uploads: slot outside the image");
    for (uint32_t y = 0; y < image.page_size; ++y) {
      const size_t dst = (size_t(u.slot_y) * image.page_size + y) * image.width() +
                         size_t(u.slot_x) * image.page_size;
      std::memcpy(&image.texels[dst * image.channels], &u.layers[layer][y * row], row);
    }
  }
  return Status::Ok();
}

void sample_level_bilinear(const LevelImageView& level, AddressMode mode, float tx, float ty,
                           uint8_t* out) {
  const float fx = tx - 0.5f, fy = ty - 0.5f;
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  const int64_t x0 = int64_t(x0f), y0 = int64_t(y0f);
  const int64_t xa = address_texel(x0, level.width, mode);
  const int64_t xb = address_texel(x0 + 1, level.width, mode);
  const int64_t ya = address_texel(y0, level.height, mode);
  const int64_t yb = address_texel(y0 + 1, level.height, mode);
  auto at = [&](int64_t x, int64_t y) {
    return level.texels + (size_t(y) * level.width + size_t(x)) * level.channels;
  };
  blend(at(xa, ya), at(xb, ya), at(xa, yb), at(xb, yb), fx - x0f, fy - y0f, level.channels, out);
}

Expected<uint32_t> sample_virtual_bilinear(const PageTable& table, const PhysicalImage& image,
                                           AddressMode mode, uint32_t level, float u, float v,
                                           uint8_t* out) {
  const PageGeometry& g = table.geometry();
  if (level >= table.level_count())
    return Error(ErrorCode::kInvalidArgument, "reference sampler: no such level");
  if (mode == AddressMode::kWrap) {
    u -= std::floor(u);
    v -= std::floor(v);
  } else {
    u = std::fmin(std::fmax(u, 0.0f), 1.0f);
    v = std::fmin(std::fmax(v, 0.0f), 1.0f);
  }
  // Virtual page at the wanted level.
  const uint32_t px =
      std::min(uint32_t(u * float(g.level_width(level))) / g.payload, table.width(level) - 1);
  const uint32_t py =
      std::min(uint32_t(v * float(g.level_height(level))) / g.payload, table.height(level) - 1);
  const PageTableEntry e = table.entry(PageId{level, px, py});
  if (!e.valid() || e.level < level)
    return Error(ErrorCode::kInvalidArgument, "reference sampler: invalid page-table entry");
  if (e.slot_x >= image.slots_x || e.slot_y >= image.slots_y)
    return Error(ErrorCode::kInvalidArgument, "reference sampler: slot outside the image");
  const uint32_t d = e.level - level;
  const int64_t rx = px >> d, ry = py >> d;
  // Same arithmetic as sample_level_bilinear at level e.level, then the integer page mapping.
  const float fx = u * float(g.level_width(e.level)) - 0.5f;
  const float fy = v * float(g.level_height(e.level)) - 0.5f;
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  const int64_t lx = int64_t(x0f) - rx * g.payload + g.border;
  const int64_t ly = int64_t(y0f) - ry * g.payload + g.border;
  const int64_t ps = g.page_size();
  if (lx < 0 || ly < 0 || lx + 1 >= ps || ly + 1 >= ps)
    return Error(ErrorCode::kInvalidArgument,
                 "reference sampler: bilinear footprint leaves the page's border");
  const int64_t bx = int64_t(e.slot_x) * ps + lx, by = int64_t(e.slot_y) * ps + ly;
  auto at = [&](int64_t x, int64_t y) {
    return image.texels.data() + (size_t(y) * image.width() + size_t(x)) * image.channels;
  };
  blend(at(bx, by), at(bx + 1, by), at(bx, by + 1), at(bx + 1, by + 1), fx - x0f, fy - y0f,
        image.channels, out);
  return e.level;
}

}  // namespace vt
