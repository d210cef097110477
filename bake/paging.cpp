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

namespace {

// Whether texels [x0, x1) of `rows` rows of `width` bytes from `band` has a covered one.
bool any_covered(const uint8_t* band, uint32_t width, uint32_t rows, uint32_t x0, uint32_t x1) {
  for (uint32_t r = 0; r < rows; ++r) {
    const uint8_t* row = band + size_t(r) * width;
    for (uint32_t x = x0; x < x1; ++x) {
      if (row[x]) return true;
    }
  }
  return false;
}

}  // namespace

bool page_has_coverage(const PageGeometry& g, const PageId& id, const uint8_t* coverage) {
  const uint32_t w = g.level_width(id.level), h = g.level_height(id.level);
  const uint32_t x0 = id.x * g.payload, y0 = id.y * g.payload;
  const uint32_t x1 = std::min(w, x0 + g.payload), y1 = std::min(h, y0 + g.payload);
  return any_covered(coverage + size_t(y0) * w, w, y1 - y0, x0, x1);
}

Expected<std::vector<uint8_t>> pages_with_coverage(const PageGeometry& g, uint32_t level,
                                                   uint32_t row, const CoverageMask& coverage) {
  const uint32_t w = g.level_width(level), h = g.level_height(level);
  const uint32_t y0 = row * g.payload, y1 = std::min(h, y0 + g.payload);
  std::vector<uint8_t> band;
  VT_RETURN_IF_ERROR(coverage.read_rows(y0, y1, band));
  std::vector<uint8_t> present(g.pages_x(level));
  for (uint32_t x = 0; x < present.size(); ++x) {
    const uint32_t x0 = x * g.payload, x1 = std::min(w, x0 + g.payload);
    present[x] = any_covered(band.data(), w, y1 - y0, x0, x1);
  }
  return present;
}

}  // namespace vt
