#include "bake/paging.h"

#include <algorithm>
#include <cstring>

namespace vt {

void cut_page(const PageGeometry& g, const PageId& id, AddressMode mode, const RowBand& band,
              float* out) {
  const uint32_t size = g.page_size();
  const uint32_t ch = band.channels;
  const int64_t w = band.width;
  const int64_t ox = g.page_origin_x(id), oy = g.page_origin_y(id);
  // Columns inside the level copy as one run; the rest are addressed one by one.
  int64_t inner0 = std::clamp<int64_t>(-ox, 0, size);
  int64_t inner1 = std::clamp<int64_t>(w - ox, inner0, size);
  for (uint32_t j = 0; j < size; ++j) {
    const float* src = band.row(oy + j);
    float* dst = out + size_t(j) * size * ch;
    if (inner1 > inner0) {
      std::memcpy(dst + inner0 * ch, src + (ox + inner0) * ch,
                  size_t(inner1 - inner0) * ch * sizeof(float));
    }
    for (int64_t i = 0; i < int64_t(size); ++i) {
      if (i >= inner0 && i < inner1) continue;
      int64_t x = address_texel(ox + i, w, mode);
      std::memcpy(dst + i * ch, src + x * ch, ch * sizeof(float));
    }
  }
}

RowBand make_band(const float* level, uint32_t width, uint32_t height, uint32_t channels,
                  AddressMode mode, int64_t y_begin, uint32_t rows, std::vector<float>& out) {
  const size_t row = size_t(width) * channels;
  out.resize(row * rows);
  for (uint32_t k = 0; k < rows; ++k) {
    int64_t y = address_texel(y_begin + k, height, mode);
    std::memcpy(out.data() + k * row, level + size_t(y) * row, row * sizeof(float));
  }
  return RowBand{y_begin, rows, width, channels, out.data()};
}

void cut_page_from_level(const PageGeometry& g, const PageId& id, AddressMode mode,
                         const float* level, uint32_t channels, float* out) {
  std::vector<float> rows;
  RowBand band = make_band(level, g.level_width(id.level), g.level_height(id.level), channels, mode,
                           page_row_begin(g, id.y), g.page_size(), rows);
  cut_page(g, id, mode, band, out);
}

bool page_has_coverage(const PageGeometry& g, const PageId& id, const uint8_t* coverage) {
  const uint32_t w = g.level_width(id.level), h = g.level_height(id.level);
  const uint32_t x0 = id.x * g.payload, y0 = id.y * g.payload;
  const uint32_t x1 = std::min(w, x0 + g.payload), y1 = std::min(h, y0 + g.payload);
  for (uint32_t y = y0; y < y1; ++y) {
    const uint8_t* row = coverage + size_t(y) * w;
    for (uint32_t x = x0; x < x1; ++x) {
      if (row[x]) return true;
    }
  }
  return false;
}

}  // namespace vt
