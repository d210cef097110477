// Page-table updates walk the mapped page's quadtree footprint and stop wherever an entry
// already points at its own level or finer: entries are monotone (a child never points coarser
// than its parent), so such a subtree needs no change. Mapping a fine leaf costs O(1).
#include "runtime/page_table.h"

#include <algorithm>

namespace vt {

PageTable::PageTable(const PageGeometry& geometry) : geometry_(geometry) {
  const uint32_t levels = geometry_.level_count();
  levels_.resize(levels);
  dirty_.resize(levels);
  for (uint32_t l = 0; l < levels; ++l) levels_[l].assign(geometry_.pages_in_level(l), {});
}

std::span<const uint8_t> PageTable::level_data(uint32_t level) const {
  const auto& v = levels_[level];
  return {reinterpret_cast<const uint8_t*>(v.data()), v.size() * sizeof(PageTableEntry)};
}

PageTableEntry PageTable::entry(const PageId& id) const {
  if (!geometry_.contains(id)) return {};
  return levels_[id.level][size_t(id.y) * width(id.level) + id.x];
}

void PageTable::mark(uint32_t level, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1) {
  TableRect& r = dirty_[level];
  if (r.empty()) {
    r = {x0, y0, x1, y1};
    return;
  }
  r.x0 = std::min(r.x0, x0);
  r.y0 = std::min(r.y0, y0);
  r.x1 = std::max(r.x1, x1);
  r.y1 = std::max(r.y1, y1);
}

void PageTable::clear_dirty() {
  for (auto& r : dirty_) r = {};
}

namespace {

// Depth-first over the footprint: `fix` returns true when it changed the entry (then the four
// children at the next finer level are visited too).
template <typename Fix, typename Mark>
void walk(PageTable& table, uint32_t level, uint32_t x, uint32_t y, Fix&& fix, Mark&& mark) {
  if (!fix(level, x, y)) return;
  mark(level, x, y);
  if (level == 0) return;
  const uint32_t cl = level - 1;
  const uint32_t cx0 = x * 2, cy0 = y * 2;
  const uint32_t cx1 = std::min(cx0 + 2, table.width(cl));
  const uint32_t cy1 = std::min(cy0 + 2, table.height(cl));
  for (uint32_t cy = cy0; cy < cy1; ++cy)
    for (uint32_t cx = cx0; cx < cx1; ++cx) walk(table, cl, cx, cy, fix, mark);
}

}  // namespace

void PageTable::map(const PageId& page, uint32_t slot_x, uint32_t slot_y) {
  if (!geometry_.contains(page)) return;
  const PageTableEntry mapped{uint8_t(slot_x), uint8_t(slot_y), uint8_t(page.level),
                              kPageTableValid};
  walk(
      *this, page.level, page.x, page.y,
      [&](uint32_t l, uint32_t x, uint32_t y) {
        PageTableEntry& e = at(l, x, y);
        if (e == mapped) return false;
        // A finer resident page owns this subtree already.
        if (l != page.level && e.valid() && e.level < page.level) return false;
        e = mapped;
        return true;
      },
      [&](uint32_t l, uint32_t x, uint32_t y) { mark(l, x, y, x + 1, y + 1); });
}

void PageTable::unmap(const PageId& page) {
  if (!geometry_.contains(page)) return;
  const PageTableEntry old = at(page.level, page.x, page.y);
  if (!old.valid() || old.level != page.level) return;  // not mapped
  PageTableEntry fallback{};
  if (page.level + 1 < level_count()) fallback = at(page.level + 1, page.x / 2, page.y / 2);
  walk(
      *this, page.level, page.x, page.y,
      [&](uint32_t l, uint32_t x, uint32_t y) {
        PageTableEntry& e = at(l, x, y);
        if (!(e == old)) return false;
        e = fallback;
        return true;
      },
      [&](uint32_t l, uint32_t x, uint32_t y) { mark(l, x, y, x + 1, y + 1); });
}

ScaleBias page_table_scale_bias(const PageGeometry& g, const PageId& vpage, PageTableEntry e,
                                uint32_t slots_x, uint32_t slots_y) {
  if (!e.valid() || e.level < vpage.level) return {};
  const uint32_t d = e.level - vpage.level;
  const double ps = g.page_size();
  const double phys_w = double(slots_x) * ps, phys_h = double(slots_y) * ps;
  const double rx = double(vpage.x >> d), ry = double(vpage.y >> d);
  ScaleBias sb;
  sb.scale_u = float(g.level_width(e.level) / phys_w);
  sb.scale_v = float(g.level_height(e.level) / phys_h);
  sb.bias_u = float((e.slot_x * ps + g.border - rx * g.payload) / phys_w);
  sb.bias_v = float((e.slot_y * ps + g.border - ry * g.payload) / phys_h);
  return sb;
}

}  // namespace vt
