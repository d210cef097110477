// Internal to vt_runtime (not installed): every page of a geometry numbered densely, level after
// level and row by row. The page source's presence bit and the feedback resolver's page key are
// this number. The level sizes are kept: PageGeometry derives them on every call (contains()
// walks the level chain), and both ask once per distinct page a frame.
#pragma once

#include <cstdint>
#include <vector>

#include "format/page_geometry.h"

namespace vt {

struct PageIndex {
  std::vector<uint64_t> level_base;        // per level: its first page's number
  std::vector<uint32_t> pages_x, pages_y;  // per level
  uint64_t total = 0;                      // pages in every level

  explicit PageIndex(const PageGeometry& g) {
    for (uint32_t l = 0; l < g.level_count(); ++l) {
      level_base.push_back(total);
      pages_x.push_back(g.pages_x(l));
      pages_y.push_back(g.pages_y(l));
      total += uint64_t(pages_x.back()) * pages_y.back();
    }
  }
  uint32_t levels() const { return uint32_t(level_base.size()); }
  bool contains(const PageId& id) const {
    return id.level < levels() && id.x < pages_x[id.level] && id.y < pages_y[id.level];
  }
  // For a page the geometry contains.
  uint64_t number(const PageId& id) const {
    return level_base[id.level] + uint64_t(id.y) * pages_x[id.level] + id.x;
  }
};

}  // namespace vt
