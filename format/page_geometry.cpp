// Page geometry arithmetic: level sizes, page grids, Morton order.
#include "format/page_geometry.h"

#include <string>

namespace vt {

namespace {

constexpr uint32_t kMaxSide = 1u << 24;
constexpr uint64_t kMaxPagesPerLevel = 1ull << 28;
// A page is decoded into one buffer; 4096^2 texels of 16 bytes (256 MiB) is the most a file
// may ask a reader to allocate for one page.
constexpr uint32_t kMaxPageSize = 4096;

uint32_t ceil_shift(uint32_t v, uint32_t shift) {
  if (shift >= 32) return v ? 1 : 0;
  return uint32_t((uint64_t(v) + (uint64_t(1) << shift) - 1) >> shift);
}

// Spreads the 32 bits of v to the even bits of a 64-bit word.
uint64_t spread_bits(uint32_t v) {
  uint64_t x = v;
  x = (x | (x << 16)) & 0x0000FFFF0000FFFFull;
  x = (x | (x << 8)) & 0x00FF00FF00FF00FFull;
  x = (x | (x << 4)) & 0x0F0F0F0F0F0F0F0Full;
  x = (x | (x << 2)) & 0x3333333333333333ull;
  x = (x | (x << 1)) & 0x5555555555555555ull;
  return x;
}

uint32_t compact_bits(uint64_t x) {
  x &= 0x5555555555555555ull;
  x = (x | (x >> 1)) & 0x3333333333333333ull;
  x = (x | (x >> 2)) & 0x0F0F0F0F0F0F0F0Full;
  x = (x | (x >> 4)) & 0x00FF00FF00FF00FFull;
  x = (x | (x >> 8)) & 0x0000FFFF0000FFFFull;
  x = (x | (x >> 16)) & 0x00000000FFFFFFFFull;
  return uint32_t(x);
}

}  // namespace

Status PageGeometry::validate() const {
  auto bad = [&](const std::string& what) {
    return Error(ErrorCode::kInvalidArgument, "page geometry " + std::to_string(width) + "x" +
                                                  std::to_string(height) + " payload " +
                                                  std::to_string(payload) + " border " +
                                                  std::to_string(border) + ": " + what);
  };
  if (width == 0 || height == 0) return bad("width and height must be at least 1");
  if (width > kMaxSide || height > kMaxSide) return bad("width and height must be at most 2^24");
  if (payload == 0) return bad("payload must be at least 1");
  if (payload > kMaxPageSize || border > kMaxPageSize) return bad("payload or border too large");
  uint64_t size = uint64_t(payload) + 2 * uint64_t(border);
  if (size > kMaxPageSize) return bad("page size (payload + 2 * border) must be at most 4096");
  if (size % 4 != 0) return bad("page size (payload + 2 * border) must be a multiple of 4");
  if (pages_in_level(0) > kMaxPagesPerLevel) return bad("more than 2^28 pages in level 0");
  return Status::Ok();
}

uint32_t PageGeometry::level_count() const {
  if (payload == 0) return 0;
  uint32_t px = pages_x(0), py = pages_y(0);
  uint32_t levels = 1;
  while (px > 1 || py > 1) {
    px = (px + 1) / 2;
    py = (py + 1) / 2;
    ++levels;
  }
  return levels;
}

uint32_t PageGeometry::level_width(uint32_t level) const {
  uint32_t w = ceil_shift(width, level);
  return w == 0 ? 1 : w;
}

uint32_t PageGeometry::level_height(uint32_t level) const {
  uint32_t h = ceil_shift(height, level);
  return h == 0 ? 1 : h;
}

uint32_t PageGeometry::pages_x(uint32_t level) const {
  if (payload == 0) return 0;
  uint32_t p0 = uint32_t((uint64_t(width) + payload - 1) / payload);
  uint32_t p = ceil_shift(p0, level);
  return p == 0 ? 1 : p;
}

uint32_t PageGeometry::pages_y(uint32_t level) const {
  if (payload == 0) return 0;
  uint32_t p0 = uint32_t((uint64_t(height) + payload - 1) / payload);
  uint32_t p = ceil_shift(p0, level);
  return p == 0 ? 1 : p;
}

uint64_t PageGeometry::total_pages() const {
  uint64_t total = 0;
  uint32_t levels = level_count();
  for (uint32_t l = 0; l < levels; ++l) total += pages_in_level(l);
  return total;
}

uint64_t morton_encode(uint32_t x, uint32_t y) {
  return spread_bits(x) | (spread_bits(y) << 1);
}

void morton_decode(uint64_t code, uint32_t* x, uint32_t* y) {
  *x = compact_bits(code);
  *y = compact_bits(code >> 1);
}

std::string page_name(const PageId& id) {
  return "page (" + std::to_string(id.level) + ", " + std::to_string(id.x) + ", " +
         std::to_string(id.y) + ")";
}

std::string page_name(const PageId& id, uint32_t layer) {
  return page_name(id) + " layer " + std::to_string(layer);
}

}  // namespace vt
