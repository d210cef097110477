// Page geometry of a virtual texture: levels, page grids, page <-> texel addressing, borders and
// Morton order. Pure arithmetic, shared by the writer, the reader, the baker and the runtime.
#pragma once

#include <cstdint>
#include <string>

#include "common/status.h"

namespace vt {

// Addressing at the virtual texture's edge, per layer: what a border texel outside the level
// image reads.
enum class AddressMode : uint8_t { kClamp = 0, kWrap = 1 };

struct PageId {
  uint32_t level = 0;
  uint32_t x = 0;
  uint32_t y = 0;
  friend bool operator==(const PageId&, const PageId&) = default;
};

// A page's key in maps and sets: level, y and x packed into 64 bits (x, y < 2^24 by validate()).
inline uint64_t page_key(const PageId& id) {
  return (uint64_t(id.level) << 48) | (uint64_t(id.y) << 24) | id.x;
}
// How every message names a page: "page (level, x, y)", and with a layer "... layer N".
std::string page_name(const PageId& id);
std::string page_name(const PageId& id, uint32_t layer);

// Level 0 is width x height texels cut into pages of `payload` texels, each stored with
// `border` extra texels on every side (page_size = payload + 2 * border, a multiple of 4).
// Level L is max(1, ceil(width / 2^L)) x max(1, ceil(height / 2^L)) texels in
// ceil(pages_x(0) / 2^L) x ceil(pages_y(0) / 2^L) pages; the last level is a single page.
// Texels past the level image inside its last page row/column are padding: they read the
// texel the layer's address mode gives (clamp: nearest edge texel; wrap: modulo the level size).
struct PageGeometry {
  uint32_t width = 0;
  uint32_t height = 0;
  uint32_t payload = 120;
  uint32_t border = 4;

  // Checks the invariants above and bounds (width, height <= 2^24 texels per side, at most
  // 2^28 pages per level) so that no derived quantity overflows.
  Status validate() const;

  uint32_t page_size() const { return payload + 2 * border; }
  uint32_t level_count() const;
  uint32_t level_width(uint32_t level) const;
  uint32_t level_height(uint32_t level) const;
  uint32_t pages_x(uint32_t level) const;
  uint32_t pages_y(uint32_t level) const;
  uint64_t pages_in_level(uint32_t level) const {
    return uint64_t(pages_x(level)) * pages_y(level);
  }
  uint64_t total_pages() const;
  bool contains(const PageId& id) const {
    return id.level < level_count() && id.x < pages_x(id.level) && id.y < pages_y(id.level);
  }

  // Level texel coordinate of page texel (0, 0), i.e. the top-left border texel; may be
  // negative. Page texel (i, j) is level texel (origin_x + i, origin_y + j) before addressing.
  int64_t page_origin_x(const PageId& id) const { return int64_t(id.x) * payload - border; }
  int64_t page_origin_y(const PageId& id) const { return int64_t(id.y) * payload - border; }
};

// Applies the address mode to a level texel coordinate along an axis of `size` texels.
inline int64_t address_texel(int64_t coord, int64_t size, AddressMode mode) {
  if (mode == AddressMode::kWrap) {
    int64_t m = coord % size;
    return m < 0 ? m + size : m;
  }
  return coord < 0 ? 0 : (coord >= size ? size - 1 : coord);
}

// Morton (Z-order) index of a page inside its level: bits of x and y interleaved, x lowest.
uint64_t morton_encode(uint32_t x, uint32_t y);
void morton_decode(uint64_t code, uint32_t* x, uint32_t* y);

}  // namespace vt
