// Internal: the byte layout of a version 1 page file (docs/FORMAT.md), shared by the writer and
// the reader. Every integer is little-endian whatever the host.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "common/status.h"
#include "common/utf8.h"
#include "format/page_file.h"

namespace vt::pagefile {

inline constexpr uint8_t kMagic[8] = {'V', 'T', 'P', 'F', 0x0D, 0x0A, 0x1A, 0x0A};
inline constexpr uint32_t kVersion = 1;
inline constexpr uint32_t kFixedHeaderBytes = 120;  // up to the level grid table
inline constexpr uint32_t kLevelRecordBytes = 8;
inline constexpr uint32_t kLayerRecordFixedBytes = 16;
inline constexpr uint32_t kEntryBytes = 32;
inline constexpr uint32_t kMaxLayers = 16;
inline constexpr uint32_t kMaxCodecTablesBytes = 16u << 20;
inline constexpr uint32_t kFlagAlign4k = 1;
inline constexpr uint64_t kPageAlignment = 4096;

// Field offsets inside the fixed header.
enum HeaderField : uint32_t {
  kOffMagic = 0,
  kOffVersion = 8,
  kOffHeaderSize = 12,
  kOffWidth = 16,
  kOffHeight = 20,
  kOffPayload = 24,
  kOffBorder = 28,
  kOffLevelCount = 32,
  kOffLayerCount = 36,
  kOffFlags = 40,
  kOffReserved = 44,
  kOffIndexOffset = 48,
  kOffIndexSize = 56,
  kOffDataOffset = 64,
  kOffDataSize = 72,
  kOffMetadataOffset = 80,
  kOffMetadataSize = 88,
  kOffFileSize = 96,
  kOffIndexChecksum = 104,
  kOffMetadataChecksum = 112,
};

inline uint64_t align_up(uint64_t v, uint64_t a) {
  return (v + a - 1) / a * a;
}

inline void put_u16(uint8_t* p, uint16_t v) {
  for (int i = 0; i < 2; ++i) p[i] = uint8_t(v >> (8 * i));
}
inline void put_u32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = uint8_t(v >> (8 * i));
}
inline void put_u64(uint8_t* p, uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = uint8_t(v >> (8 * i));
}
inline uint16_t get_u16(const uint8_t* p) {
  return uint16_t(p[0] | (p[1] << 8));
}
inline uint32_t get_u32(const uint8_t* p) {
  uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
inline uint64_t get_u64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

// Bytes of one layer record: fixed part, name and tables, padded to a multiple of 8.
inline uint64_t layer_record_bytes(uint64_t name_bytes, uint64_t table_bytes) {
  return kLayerRecordFixedBytes + align_up(name_bytes + table_bytes, 8);
}

// Index of the first entry of `level`: coarsest level first, then row-major pages, then layers.
inline uint64_t level_first_page(const PageGeometry& g, uint32_t level) {
  uint64_t first = 0;
  for (uint32_t l = g.level_count(); l-- > level + 1;) first += g.pages_in_level(l);
  return first;
}

// Pages of a level in Morton order (the data-area order). Sorting works for any grid shape.
inline std::vector<uint64_t> morton_order(const PageGeometry& g, uint32_t level) {
  std::vector<uint64_t> codes;
  codes.reserve(g.pages_in_level(level));
  for (uint32_t y = 0; y < g.pages_y(level); ++y)
    for (uint32_t x = 0; x < g.pages_x(level); ++x) codes.push_back(morton_encode(x, y));
  std::sort(codes.begin(), codes.end());
  return codes;
}

// Shared validation of a layer description (writer: kInvalidArgument; reader: kCorrupt).
inline std::string layer_problem(const LayerSpec& l) {
  if (uint8_t(l.semantic) > uint8_t(LayerSemantic::kLitAlbedo)) return "unknown semantic";
  if (l.channels < 1 || l.channels > 4) return "channels must be 1..4";
  if (uint8_t(l.texel_type) > uint8_t(TexelType::kF32)) return "unknown texel type";
  if (uint8_t(l.codec) > uint8_t(PageCodec::kBcZstd)) return "unknown codec";
  if (!runtime_format_info(l.runtime_format)) return "unknown runtime format";
  if (uint8_t(l.color_space) > uint8_t(ColorSpace::kSrgb)) return "unknown colour space";
  if (uint8_t(l.address_mode) > uint8_t(AddressMode::kWrap)) return "unknown address mode";
  if (l.name.size() > 255) return "name longer than 255 bytes";
  if (!valid_utf8(l.name)) return "name is not UTF-8";
  if (l.codec_tables.size() > kMaxCodecTablesBytes) return "codec tables larger than 16 MiB";
  if (l.codec == PageCodec::kDct && l.texel_type != TexelType::kU8) return "dct needs 8-bit texels";
  if (l.codec == PageCodec::kDct && l.codec_tables.empty()) return "dct layer without codec tables";
  if (l.codec == PageCodec::kBcZstd) {
    const std::optional<BcFormat> bc = runtime_bc_format(l.runtime_format);
    if (!bc) return "bc+zstd layer needs a BC runtime format";
    // BC6H blocks code half floats, every other BC format 8-bit texels.
    if (bc_is_bc6h(*bc) && l.texel_type != TexelType::kF16)
      return "bc+zstd with a BC6H runtime format needs half-float texels";
    if (!bc_is_bc6h(*bc) && l.texel_type != TexelType::kU8) return "bc+zstd needs 8-bit texels";
  }
  if (runtime_bc_format(l.runtime_format) && bc_is_bc6h(*runtime_bc_format(l.runtime_format)) &&
      l.texel_type != TexelType::kF16)
    return "a BC6H runtime format needs half-float texels";
  return {};
}

}  // namespace vt::pagefile
