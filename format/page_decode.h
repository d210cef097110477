// Internal: decoding one stored page into texels, per codec. Kept apart from the reader so the
// codec dispatch (zstd, codec/dct.h, codec/bc.h) lives in one place.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "common/status.h"
#include "format/page_file.h"

namespace vt::pagefile {

// Per-layer decoding state (the layer's parsed codec tables), built once when a file opens.
class LayerDecoder {
 public:
  // Parses the layer's shared tables; malformed tables give kCorrupt.
  static Expected<std::unique_ptr<LayerDecoder>> create(const LayerSpec& spec, uint32_t page_size);
  virtual ~LayerDecoder() = default;
  // Decodes `data` (one page coded with `codec`) into `out`, exactly
  // page_size^2 * texel_bytes bytes. Never reads or writes out of bounds.
  virtual Status decode(PageCodec codec, std::span<const uint8_t> data,
                        std::span<uint8_t> out) const = 0;
};

// BC format of a runtime format, or false when it is not a BC format.
bool runtime_bc_format(RuntimeFormat format, uint8_t* bc_format);

}  // namespace vt::pagefile
