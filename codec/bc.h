// Block-compressed GPU formats: BC1, BC3, BC4, BC5, BC6H and BC7 encoders (a real-time level for
// load-time transcode, a high-quality level for offline bakes) and decoders. Images are
// row-major texels, 8-bit for every format but BC6H, whose texels are half floats (2 bytes a
// channel, native byte order); width and height must be multiples of 4. Output blocks are in
// row-major block order (8 bytes per block for BC1/BC4, 16 for BC3/BC5/BC6H/BC7).
// Deterministic: same input and level, same bytes, on every machine (the SIMD paths do the same
// IEEE operations per block as the scalar ones).
//
// Decoders round as Mesa's lavapipe samples, so CPU decodes match its renders bit for bit:
// BC1 4-colour blocks truncate the in-between colours ((2*c0 + c1) / 3), 3-colour blocks round
// the midpoint up ((c0 + c1 + 1) / 2) and index 3 is black; BC3's colour half is always
// 4-colour; BC4/BC5 truncate their interpolated values; BC7 is exact by the format. Encoders pick
// indices against these palettes; BC6H is exact by the format too. Details per format:
// codec/bc1.h, bc3.h, bc4.h, bc6h.h, bc7.h.
#pragma once

#include <cstddef>
#include <cstdint>

#include "common/status.h"

namespace vt {

enum class BcFormat : uint8_t {
  kBc1 = 0,       // RGB (channels 0-2), 4 bits/texel
  kBc3 = 1,       // RGBA: BC1 colour + BC4 alpha, 8 bits/texel
  kBc4 = 2,       // one channel, 4 bits/texel
  kBc5 = 3,       // two channels (normal XY), 8 bits/texel
  kBc7 = 4,       // RGBA, 8 bits/texel
  kBc6hUf16 = 5,  // RGB half floats 0..65504 (HDR), 8 bits/texel
  kBc6hSf16 = 6,  // RGB half floats -65504..65504 (signed data), 8 bits/texel
};

inline bool bc_is_bc6h(BcFormat f) {
  return f == BcFormat::kBc6hUf16 || f == BcFormat::kBc6hSf16;
}
// Bytes of one channel of the texels a format codes: 2 (half) for BC6H, else 1.
inline int bc_channel_bytes(BcFormat f) {
  return bc_is_bc6h(f) ? 2 : 1;
}

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
// Number of channels each format stores (BC1: 3, BC3: 4, BC4: 1, BC5: 2, BC6H: 3, BC7: 4).
int bc_format_channels(BcFormat f);

// Encodes a width x height image of `channels` interleaved channels (1..4; 8-bit, or half floats
// for BC6H; missing channels read as 0 for colour and 255 for alpha, BC6H ignores a fourth) into
// `out` (bc_image_bytes bytes).
Status bc_encode_image(BcFormat format, BcQuality quality, const uint8_t* texels, int width,
                       int height, int channels, uint8_t* out);
// Decodes into width*height*channels values (bytes, or halves for BC6H), keeping the first
// `channels` channels of the decoded RGBA (BC4 decodes to R, BC5 to RG, BC6H to RGB with alpha
// 1.0). Blocks are read exactly; never out of bounds.
Status bc_decode_image(BcFormat format, const uint8_t* blocks, int width, int height, int channels,
                       uint8_t* texels);

}  // namespace vt
