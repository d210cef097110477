// The page DCT codec: one page (width, height multiples of 8; 128x128 by default) of 1-4
// channels of 8-bit texels. RGB goes through a reversible-enough colour transform (YCoCg) with
// optional 4:2:0 chroma; alpha, normal XY and single-channel layers are independent planes.
// Quantisation and entropy tables are shared by every page of a layer (DctTables, stored once
// in the page file), so a coded page carries only a few bytes of header.
// Decoding is integer-exact: the same bytes give the same texels on every machine.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "common/status.h"

namespace vt {

enum class DctPlaneLayout : uint8_t {
  kPlanes = 0,    // every channel coded as its own full-resolution plane
  kYCoCg = 1,     // channels 0-2 through YCoCg, chroma at full resolution; channel 3 a plane
  kYCoCg420 = 2,  // as kYCoCg with 4:2:0 chroma
};

struct DctSettings {
  int quality = 75;  // 1..100, JPEG-like meaning
  int channels = 3;  // 1..4
  DctPlaneLayout layout = DctPlaneLayout::kYCoCg420;
};

// Tables shared by all pages of a layer. Opaque; serialise with dct_serialize_tables.
struct DctTables;
struct DctTablesDeleter {
  void operator()(DctTables* t) const;
};
using DctTablesPtr = std::unique_ptr<DctTables, DctTablesDeleter>;

// Builds tables for the settings. `training_pages` (optional, each width*height*channels
// bytes) lets the encoder fit its entropy tables to the content.
Expected<DctTablesPtr> dct_make_tables(
    const DctSettings& settings, int width, int height,
    std::span<const std::span<const uint8_t>> training_pages = {});
std::vector<uint8_t> dct_serialize_tables(const DctTables& tables);
// Parses tables from a page file; malformed bytes give kCorrupt, never a crash.
Expected<DctTablesPtr> dct_parse_tables(std::span<const uint8_t> bytes);

// Encodes one page of width*height texels, `channels` interleaved 8-bit channels, row-major.
Status dct_encode_page(const DctTables& tables, const uint8_t* texels, int width, int height,
                       std::vector<uint8_t>& out);
// Decodes one page into width*height*channels bytes. Never reads past `data` or writes past
// `texels`; corrupt data gives kCorrupt.
Status dct_decode_page(const DctTables& tables, std::span<const uint8_t> data, int width,
                       int height, uint8_t* texels);

}  // namespace vt
