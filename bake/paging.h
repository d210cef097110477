// Cutting a level into pages (format/page_geometry.h): each page is payload + border texels per
// side, and every border texel is the true neighbouring texel of the same level, addressed by
// the layer's clamp/wrap rule at the level's edge; texels past a level whose size is not a
// multiple of the payload (padding) follow the same rule.
#pragma once

#include <cstdint>
#include <vector>

#include "bake/coverage_mask.h"
#include "bake/pyramid.h"
#include "format/page_geometry.h"

namespace vt {

// Level rows a page reads: [page_origin_y, page_origin_y + page_size) before addressing.
inline int64_t page_row_begin(const PageGeometry& g, uint32_t page_y) {
  return int64_t(page_y) * g.payload - g.border;
}
inline int64_t page_row_end(const PageGeometry& g, uint32_t page_y) {
  return page_row_begin(g, page_y) + g.page_size();
}

// Copies page `id` (page_size^2 texels of band.channels floats, row-major) out of `band`, which
// must hold the page's rows (page_row_begin..page_row_end) already addressed.
void cut_page(const PageGeometry& g, const PageId& id, AddressMode mode, const RowBand& band,
              float* out);

// Fills `out` with the addressed rows [y_begin, y_begin + rows) of a level held whole in memory
// and returns a RowBand over them.
RowBand make_band(const float* level, uint32_t width, uint32_t height, uint32_t channels,
                  AddressMode mode, int64_t y_begin, uint32_t rows, std::vector<float>& out);

// Copies a page out of a level held whole in memory (tests, small levels).
void cut_page_from_level(const PageGeometry& g, const PageId& id, AddressMode mode,
                         const float* level, uint32_t channels, float* out);

// True when some payload texel of the page that lies inside the level is covered
// (`coverage`: level_width x level_height bytes, non-zero = covered; a level held whole).
bool page_has_coverage(const PageGeometry& g, const PageId& id, const uint8_t* coverage);

// The same for every page of page row `row` of `level`, from the mask's payload rows of that row
// alone: one byte per page, 1 = some covered texel.
Expected<std::vector<uint8_t>> pages_with_coverage(const PageGeometry& g, uint32_t level,
                                                   uint32_t row, const CoverageMask& coverage);

}  // namespace vt
