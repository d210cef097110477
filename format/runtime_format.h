// The GPU formats a layer is delivered in to the physical cache, and what each one is: one table
// that the reader, the runtime, the baker and the renderer all read (page bytes, BC format,
// channels, float or not), so no stage restates a format's facts in a switch of its own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>

#include "codec/bc.h"

namespace vt {

// The GPU format a layer is transcoded to for the physical cache (docs/FORMAT.md values).
enum class RuntimeFormat : uint8_t {
  kRgba8 = 0,
  kBc1 = 1,
  kBc3 = 2,
  kBc4 = 3,
  kBc5 = 4,
  kBc7 = 5,
  kR8 = 6,
  kRg8 = 7,
  kRgba16f = 8,
  kRgba32f = 9,
  kBc6hUf16 = 10,  // HDR RGB, 0..65504 (half-float layers)
  kBc6hSf16 = 11,  // signed HDR RGB (custom half-float data)
};

struct RuntimeFormatInfo {
  RuntimeFormat format;
  const char* name;            // as docs/FORMAT.md and `vtbake info --json` spell it
  uint32_t bits_per_texel;     // BC formats: block bytes * 8 / 16 texels
  uint32_t channels;           // channels a sampler reads (BC1: RGB, BC4: R, BC5: RG)
  bool is_float;               // float channels: 16 or 32 bits each, or BC6H's half floats
  std::optional<BcFormat> bc;  // the codec/bc.h format of a block-compressed format
};

// The row of `format`; nullptr for a value no RuntimeFormat has (a corrupt layer record).
const RuntimeFormatInfo* runtime_format_info(RuntimeFormat format);
// Bytes of one page_size x page_size page (page_size a multiple of 4; 0 for unknown formats).
size_t runtime_format_page_bytes(RuntimeFormat format, uint32_t page_size);
// The BC format of a block-compressed runtime format; nullopt for the others.
std::optional<BcFormat> runtime_bc_format(RuntimeFormat format);
// The runtime format whose blocks are `format`'s.
RuntimeFormat runtime_format_of(BcFormat format);
const char* to_string(RuntimeFormat format);

}  // namespace vt
