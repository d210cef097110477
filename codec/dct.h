// The page DCT codec: one page (width, height multiples of 8; 128x128 by default) of 1-4
// channels of 8-bit texels. RGB goes through a reversible-enough colour transform (YCoCg) with
// optional 4:2:0 chroma; alpha, normal XY and single-channel layers are independent planes.
// Quantisation and entropy tables are shared by every page of a layer (DctTables, stored once
// in the page file), so a coded page carries only a few bytes of header.
// Decoding is integer-exact: the same bytes give the same texels on every machine.
//
// Coded page: a kind byte (0 coded, 1 constant: the texel follows raw, 2 stored: every texel
// follows raw, used when coding would not make the page smaller; from tables version 4 also 3
// coded in another page mode: a mode byte, full chroma | finer << 1, then as kind 0; and 4
// lossless: a zstd frame of the raw texels, which format/layer_codec.h decodes, since this
// library has no zstd). A coded page holds the length
// of its rANS part (LEB128), the rANS part (two 32-bit states, then 16-bit words; 16-token
// alphabets at 14-bit precision, codec/dct_rans.h), then a raw bit stream (low bits and signs,
// least significant bit first). Tokens, per plane (Y, Co, Cg, alpha; or channels 0..3 for
// kPlanes) and 8x8 block in raster order: the AC nonzero count, the DC residual from a median
// predictor, then while nonzeros remain one token per pair of zigzag positions (the magnitude
// classes 0, 1, 2 and "3 or more" of both), each "3 or more" followed by an escape token for
// the rest. Token models are static when the tables were trained and adaptive (AV1-style CDF
// steps) when they were not. Planes hold texels centred on 0 (YCoCg: Y=(R+2G+B)/4, Co=(R-B)/2,
// Cg=(2G-R-B)/4); 4:2:0 chroma is the 2x2 mean and comes back through a 9-3-3-1 filter.
// Dequantised coefficients are clamped to +-2047 and inverted by a separable integer DCT with a
// fixed 12-bit basis and specified rounding and saturation (codec/dct_transform.h).
// Tables bytes (version 4; version 3, the same bytes without page kinds 3 and 4, still reads):
// "VTDC", 4, quality, channels, layout, width and height (u16 LE),
// mode (0 static, 1 adaptive), then per plane 64 quantiser steps (natural order) and per token
// model an observation count and 16 frequencies (codec/dct.cpp, dct_serialize_tables).
// Thread safety: tables are read-only once made; encode and decode may run on any number of
// threads at once. Encoding and decoding keep per-thread scratch buffers sized by the largest
// page.
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
  // Token models that adapt while a page is decoded even when the tables are trained: 1-9%
  // smaller pages (most where the training pages differ from the rest), about 1.2x the entropy
  // decoding time. Untrained tables always adapt.
  bool adaptive = false;
};

// A page's coding mode beside the tables' own (mode {} is the tables as made): the encoder picks
// one per page by rate and distortion (format/dct_page_modes.h).
struct DctPageMode {
  bool full_chroma = false;  // 4:4:4 chroma on tables made for 4:2:0
  uint8_t finer = 0;         // quantiser steps divided by 2^finer (at least 1), 0..kDctMaxFiner
};
inline constexpr int kDctMaxFiner = 3;
inline constexpr int kDctPageModes = 8;  // mode bytes 0..7
// The first byte of a lossless page (raw texels + zstd), stored by format/layer_codec.h.
inline constexpr uint8_t kDctPageLossless = 4;

// Tables shared by all pages of a layer. Opaque; serialise with dct_serialize_tables.
struct DctTables;
struct DctTablesDeleter {
  void operator()(DctTables* t) const;
};
using DctTablesPtr = std::unique_ptr<DctTables, DctTablesDeleter>;

// Builds tables for the settings. `training_pages` (optional, each width*height*channels
// bytes) fits static token models to the content: pages decode fastest and smallest with them
// (on photographs about 10% smaller than untrained tables, whose models adapt while a page is
// decoded, at about 1.2x the entropy decoding time). The texels decoded differ only where the
// encoder's rate estimates, taken from the models, tip a level. Width and height: multiples of 8 up
// to 4096; the YCoCg layouts need 3 or 4 channels. Bad settings give kInvalidArgument.
Expected<DctTablesPtr> dct_make_tables(
    const DctSettings& settings, int width, int height,
    std::span<const std::span<const uint8_t>> training_pages = {});
std::vector<uint8_t> dct_serialize_tables(const DctTables& tables);
// Parses tables from a page file; malformed bytes give kCorrupt, never a crash.
Expected<DctTablesPtr> dct_parse_tables(std::span<const uint8_t> bytes);
// The channel count and page size the tables code: a decoder writes width * height * channels
// bytes, so a reader checks them against the layer before trusting a file's tables.
struct DctTablesShape {
  int channels = 0, width = 0, height = 0;
};
DctTablesShape dct_tables_shape(const DctTables& tables);

// Encodes one page of width*height texels, `channels` interleaved 8-bit channels, row-major, in
// page mode `mode` (which must apply: dct_mode_applies). Replaces the contents of `out`.
// Below quality 100 the levels of ones are chosen by rate and distortion (fewer bytes and fewer
// tokens to decode at equal error; about 1.5x a page's encoding time). Deterministic: the same
// texels, tables and mode give the same bytes.
Status dct_encode_page(const DctTables& tables, const uint8_t* texels, int width, int height,
                       std::vector<uint8_t>& out, DctPageMode mode = {});
// Whether the tables code pages in `mode` (full chroma needs 4:2:0 tables).
bool dct_mode_applies(const DctTables& tables, DctPageMode mode);
// The luma DC quantiser step of mode {}.
int dct_base_step(const DctTables& tables);
// What a bit is worth at the tables' quantiser (mode {}), in texel SSE summed over channels: the
// slope of the layer's rate-distortion curve, for the encoder's decisions (the levels of each
// page, format/dct_page_modes.h's choice of mode).
double dct_layer_slope(const DctTables& tables);
// The tables' version (3 or 4): version 3 tables code only mode {} and no lossless pages.
int dct_tables_version(const DctTables& tables);
// Decodes one page into `texels`, which must be exactly width * height * channels bytes for the
// tables' channel count (dct_tables_shape), else kInvalidArgument before anything is written:
// whatever the tables say, the decoder writes only inside `texels`. Never reads past `data`;
// truncated, damaged or over-long data gives kCorrupt (texels may then be partly written).
// Time is bounded by the page size whatever the bytes.
Status dct_decode_page(const DctTables& tables, std::span<const uint8_t> data, int width,
                       int height, std::span<uint8_t> texels);
// As above for a caller that sized `texels` from the same tables (width * height * channels).
Status dct_decode_page(const DctTables& tables, std::span<const uint8_t> data, int width,
                       int height, uint8_t* texels);

}  // namespace vt
