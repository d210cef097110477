// The runtime-format table. BC rows take their sizes and channels from codec/bc.h, which owns
// the block formats.
#include "format/runtime_format.h"

#include <iterator>

namespace vt {

namespace {

constexpr RuntimeFormat kLastRuntimeFormat = RuntimeFormat::kBc6hSf16;

RuntimeFormatInfo bc_row(RuntimeFormat format, const char* name, BcFormat bc) {
  return {
      format,         name, uint32_t(bc_block_bytes(bc) * 8 / 16), uint32_t(bc_format_channels(bc)),
      bc_is_bc6h(bc), bc};
}

// Indexed by RuntimeFormat value.
const RuntimeFormatInfo* table() {
  static const RuntimeFormatInfo rows[] = {
      {RuntimeFormat::kRgba8, "rgba8", 32, 4, false, std::nullopt},
      bc_row(RuntimeFormat::kBc1, "bc1", BcFormat::kBc1),
      bc_row(RuntimeFormat::kBc3, "bc3", BcFormat::kBc3),
      bc_row(RuntimeFormat::kBc4, "bc4", BcFormat::kBc4),
      bc_row(RuntimeFormat::kBc5, "bc5", BcFormat::kBc5),
      bc_row(RuntimeFormat::kBc7, "bc7", BcFormat::kBc7),
      {RuntimeFormat::kR8, "r8", 8, 1, false, std::nullopt},
      {RuntimeFormat::kRg8, "rg8", 16, 2, false, std::nullopt},
      {RuntimeFormat::kRgba16f, "rgba16f", 64, 4, true, std::nullopt},
      {RuntimeFormat::kRgba32f, "rgba32f", 128, 4, true, std::nullopt},
      bc_row(RuntimeFormat::kBc6hUf16, "bc6h_uf16", BcFormat::kBc6hUf16),
      bc_row(RuntimeFormat::kBc6hSf16, "bc6h_sf16", BcFormat::kBc6hSf16),
  };
  static_assert(std::size(rows) == size_t(kLastRuntimeFormat) + 1);
  return rows;
}

}  // namespace

const RuntimeFormatInfo* runtime_format_info(RuntimeFormat format) {
  if (uint8_t(format) > uint8_t(kLastRuntimeFormat)) return nullptr;
  return &table()[uint8_t(format)];
}

size_t runtime_format_page_bytes(RuntimeFormat format, uint32_t page_size) {
  const RuntimeFormatInfo* info = runtime_format_info(format);
  return info ? size_t(page_size) * page_size * info->bits_per_texel / 8 : 0;
}

std::optional<BcFormat> runtime_bc_format(RuntimeFormat format) {
  const RuntimeFormatInfo* info = runtime_format_info(format);
  return info ? info->bc : std::nullopt;
}

RuntimeFormat runtime_format_of(BcFormat format) {
  for (uint8_t f = 0; f <= uint8_t(kLastRuntimeFormat); ++f)
    if (table()[f].bc == format) return RuntimeFormat(f);
  return RuntimeFormat::kRgba8;  // not reached: every BcFormat has a row
}

const char* to_string(RuntimeFormat format) {
  const RuntimeFormatInfo* info = runtime_format_info(format);
  return info ? info->name : "unknown";
}

}  // namespace vt
