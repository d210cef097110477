// Addressed bands of a level read strictly top to bottom: keeps a window of recent rows so that
// overlapping bands never re-read, and for wrap addressing pins the rows that the first and last
// bands read across the edge.
#pragma once

#include <cstdint>
#include <vector>

#include "bake/level_source.h"
#include "bake/pyramid.h"
#include "format/page_file.h"

namespace vt {

class RowWindow {
 public:
  RowWindow(LevelSource& level, AddressMode mode) : level_(level), mode_(mode) {}

  // Wrap: rows [0, top) and [height - bottom, height) are read once up front.
  Status pin(uint32_t top, uint32_t bottom);
  // Rows [y_begin, y_begin + rows) of the level, addressed (clamp or wrap). The band stays
  // valid until the next fetch.
  Expected<RowBand> fetch(int64_t y_begin, uint32_t rows);
  // Bytes held (window, band, pinned rows).
  uint64_t bytes() const;

 private:
  size_t row_floats() const { return level_.row_floats(); }
  LevelSource& level_;
  AddressMode mode_;
  int64_t lo_ = 0, hi_ = 0;
  std::vector<float> window_;
  std::vector<float> band_;
  int64_t pin_top_ = 0, pin_bottom_ = 0;
  std::vector<float> pinned_top_, pinned_bottom_;
};

}  // namespace vt
