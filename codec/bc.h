// Block-compressed GPU formats: BC1, BC3, BC4, BC5 and BC7 encoders (a real-time level for
// load-time transcode, a high-quality level for offline bakes) and decoders. Images are
// row-major 8-bit texels; width and height must be multiples of 4. Output blocks are in
// row-major block order (8 bytes per block for BC1/BC4, 16 for BC3/BC5/BC7).
// Deterministic: same input and level, same bytes, on every machine (the SIMD paths do the same
// IEEE operations per block as the scalar ones).
//
// Decoders round as Mesa's lavapipe samples, so CPU decodes match its renders bit for bit:
// BC1 4-colour blocks truncate the in-between colours ((2*c0 + c1) / 3), 3-colour blocks round
// the midpoint up ((c0 + c1 + 1) / 2) and index 3 is black; BC3's colour half is always
// 4-colour; BC4/BC5 truncate their interpolated values; BC7 is exact by the format. Encoders pick
// indices against these palettes. Details per format: codec/bc1.h, bc3.h, bc4.h, bc7.h.
#pragma once

#include <cstddef>
#include <cstdint>

#include "common/status.h"

namespace vt {

enum class BcFormat : uint8_t {
  kBc1 = 0,  // RGB (channels 0-2), 4 bits/texel
  kBc3 = 1,  // RGBA: BC1 colour + BC4 alpha, 8 bits/texel
  kBc4 = 2,  // one channel, 4 bits/texel
  kBc5 = 3,  // two channels (normal XY), 8 bits/texel
  kBc7 = 4,  // RGBA, 8 bits/texel
};

enum class BcQuality : uint8_t {
  kRealtime = 0,  // streaming transcode: fastest usable
  kNormal = 1,
  kHigh = 2,  // offline: slowest, best
};

// Bytes per 4x4 block.
inline size_t bc_block_bytes(BcFormat f) {
  return (f == BcFormat::kBc1 || f == BcFormat::kBc4) ? 8 : 16;
}
inline size_t bc_image_bytes(BcFormat f, int width, int height) {
  return bc_block_bytes(f) * size_t(width / 4) * size_t(height / 4);
}
// Number of channels each format stores (BC1: 3, BC3: 4, BC4: 1, BC5: 2, BC7: 4).
int bc_format_channels(BcFormat f);

// Encodes a width x height image of `channels` interleaved 8-bit channels (1..4; missing
// channels read as 0 for colour and 255 for alpha) into `out` (bc_image_bytes bytes).
Status bc_encode_image(BcFormat format, BcQuality quality, const uint8_t* texels, int width,
                       int height, int channels, uint8_t* out);
// Decodes into width*height*channels bytes, keeping the first `channels` channels of the
// decoded RGBA (BC4 decodes to R, BC5 to RG). Blocks are read exactly; never out of bounds.
Status bc_decode_image(BcFormat format, const uint8_t* blocks, int width, int height, int channels,
                       uint8_t* texels);

}  // namespace vt
