// The page table: for every virtual page of every level, where its best resident data lives.
//
// Layout (what the renderer uploads; fixed): one RGBA8 texel per virtual page, level by level.
// Level L is pages_x(L) x pages_y(L) texels, row-major, 4 bytes per texel:
//   R = physical slot x, G = physical slot y,
//   B = level of the page actually resident in that slot: L itself or the level of the nearest
//       resident ancestor (always >= L),
//   A = flags: bit 0 (kPageTableValid) set when the entry points at a resident page; an entry
//       with bit 0 clear must not be sampled (only before the last level's page is mapped).
// As one GPU image with a mip chain: give the base level next_pow2(pages_x(0)) x
// next_pow2(pages_y(0)) texels and copy level L into the top-left corner of mip L (it always
// fits); read it with texelFetch / a NEAREST sampler.
//
// The physical cache texture of a layer is slots_x x slots_y slots of page_size x page_size
// texels (page_size = payload + 2 * border), slot (sx, sy) at texel (sx, sy) * page_size.
//
// Shader mapping. Let the wanted level be L, uv in [0, 1] over the virtual texture (level k
// spans level_width(k) x level_height(k) texels, GPU convention: texel centres at i + 0.5):
//   vpage = floor(uv * level_size(L) / payload)          virtual page at level L (clamped)
//   e     = page_table[L][vpage]                          entry; d = e.B - L
//   rpage = vpage >> d                                    resident page at level e.B
//   t     = uv * level_size(e.B)                          texel coordinate in level e.B
//   physical texel = e.RG * page_size + border + (t - rpage * payload)
//   physical_uv    = physical texel / (slots_xy * page_size)
// i.e. physical_uv = uv * scale + bias with, per axis,
//   scale = level_size(e.B) / (slots * page_size)
//   bias  = (e.R * page_size + border - rpage * payload) / (slots * page_size).
// Bilinear taps near the page edge read the border, which holds the true neighbouring texels of
// level e.B, so the result equals sampling level e.B unpaged (see reference_sampler.h).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "format/page_geometry.h"

namespace vt {

inline constexpr uint8_t kPageTableValid = 1;

struct PageTableEntry {
  uint8_t slot_x = 0;
  uint8_t slot_y = 0;
  uint8_t level = 0;  // level of the resident page the entry points at
  uint8_t flags = 0;
  bool valid() const { return (flags & kPageTableValid) != 0; }
  friend bool operator==(const PageTableEntry&, const PageTableEntry&) = default;
};
static_assert(sizeof(PageTableEntry) == 4, "one RGBA8 texel");

// Rectangle of texels [x0, x1) x [y0, y1) of one level; empty when x0 >= x1.
struct TableRect {
  uint32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x0 >= x1 || y0 >= y1; }
};

// physical_uv = virtual_uv * scale + bias (per axis), for one entry read at one virtual page.
struct ScaleBias {
  float scale_u = 0, scale_v = 0, bias_u = 0, bias_v = 0;
};

// Builds and incrementally updates the table. map() and unmap() touch only the mapped page's
// footprint at its own and finer levels and record the changed rectangle per level.
// Not thread-safe; the Streamer owns one and serialises access.
class PageTable {
 public:
  explicit PageTable(const PageGeometry& geometry);

  const PageGeometry& geometry() const { return geometry_; }
  uint32_t level_count() const { return uint32_t(levels_.size()); }
  uint32_t width(uint32_t level) const { return geometry_.pages_x(level); }
  uint32_t height(uint32_t level) const { return geometry_.pages_y(level); }
  // RGBA8 texels of one level (width * height * 4 bytes).
  std::span<const uint8_t> level_data(uint32_t level) const;
  PageTableEntry entry(const PageId& id) const;

  // `page` is now resident in slot (slot_x, slot_y): every entry of its footprint at levels
  // <= page.level that points at a coarser level (or is invalid) now points at it.
  void map(const PageId& page, uint32_t slot_x, uint32_t slot_y);
  // `page` left its slot: every entry pointing at it falls back to what its parent's entry
  // points at (invalid for the last level).
  void unmap(const PageId& page);

  // Rectangles changed since the last clear_dirty(), one per level (for partial uploads).
  TableRect dirty(uint32_t level) const { return dirty_[level]; }
  void clear_dirty();

 private:
  PageTableEntry& at(uint32_t level, uint32_t x, uint32_t y) {
    return levels_[level][size_t(y) * width(level) + x];
  }
  void mark(uint32_t level, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1);

  PageGeometry geometry_;
  std::vector<std::vector<PageTableEntry>> levels_;
  std::vector<TableRect> dirty_;
};

// Scale/bias of `e` read at virtual page `vpage` (level = wanted level) for a physical cache of
// slots_x x slots_y slots. Invalid entries give all zeros.
ScaleBias page_table_scale_bias(const PageGeometry& geometry, const PageId& vpage, PageTableEntry e,
                                uint32_t slots_x, uint32_t slots_y);

}  // namespace vt
