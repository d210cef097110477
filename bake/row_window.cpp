#include "bake/row_window.h"

#include <algorithm>
#include <cstring>
#include <string>

namespace vt {

Status RowWindow::pin(uint32_t top, uint32_t bottom) {
  const uint32_t h = level_.height();
  top = std::min(top, h);
  bottom = std::min(bottom, h - top);
  pin_top_ = top;
  pin_bottom_ = bottom;
  pinned_top_.resize(size_t(top) * row_floats());
  pinned_bottom_.resize(size_t(bottom) * row_floats());
  if (bottom > 0) VT_RETURN_IF_ERROR(level_.read(h - bottom, h, pinned_bottom_.data()));
  if (top > 0) VT_RETURN_IF_ERROR(level_.read(0, top, pinned_top_.data()));
  return Status::Ok();
}

Expected<RowBand> RowWindow::fetch(int64_t y_begin, uint32_t rows) {
  const int64_t h = level_.height();
  const int64_t a = std::clamp<int64_t>(y_begin, 0, h - 1);
  const int64_t b = std::clamp<int64_t>(y_begin + rows, a + 1, h);  // real rows [a, b) needed
  // Drop rows above a; read rows up to b.
  if (a > lo_) {
    const int64_t drop = std::min<int64_t>(a, hi_) - lo_;
    if (drop > 0) window_.erase(window_.begin(), window_.begin() + drop * row_floats());
    lo_ = a;
    hi_ = std::max(hi_, lo_);
  }
  if (b > hi_) {
    const int64_t from = std::max(hi_, a);
    const size_t old = window_.size();
    window_.resize(old + size_t(b - from) * row_floats());
    VT_RETURN_IF_ERROR(level_.read(uint32_t(from), uint32_t(b), window_.data() + old));
    hi_ = b;
  }
  band_.resize(size_t(rows) * row_floats());
  for (uint32_t k = 0; k < rows; ++k) {
    const int64_t y = address_texel(y_begin + k, uint32_t(h), mode_);
    const float* src = nullptr;
    if (y >= lo_ && y < hi_) {
      src = window_.data() + size_t(y - lo_) * row_floats();
    } else if (y < pin_top_) {
      src = pinned_top_.data() + size_t(y) * row_floats();
    } else if (y >= h - pin_bottom_) {
      src = pinned_bottom_.data() + size_t(y - (h - pin_bottom_)) * row_floats();
    } else {
      return Status(ErrorCode::kInternal, "row window: row " + std::to_string(y) + " missing");
    }
    std::memcpy(band_.data() + k * row_floats(), src, row_floats() * sizeof(float));
  }
  return RowBand{y_begin, rows, level_.width(), level_.channels(), band_.data()};
}

uint64_t RowWindow::bytes() const {
  return (window_.capacity() + band_.capacity() + pinned_top_.capacity() +
          pinned_bottom_.capacity()) *
         sizeof(float);
}

}  // namespace vt
