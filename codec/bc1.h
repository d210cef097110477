// BC1 (DXT1) blocks: 4x4 RGB texels in 8 bytes, two RGB565 endpoints and 2-bit indices.
// Block-level entry points behind bc_encode_image/bc_decode_image (codec/bc.h), for callers that
// gather their own blocks (the runtime transcoder, BC3's colour half).
//
// Decoding rounds as Mesa's lavapipe samples (bit-exact with it): endpoints expand 565 -> 888 by
// bit replication; in 4-colour mode (c0 > c1 as 16-bit words) the in-between colours are
// (2*c0 + c1) / 3 and (c0 + 2*c1) / 3 with the division truncating; in 3-colour mode
// (c0 <= c1) the midpoint is (c0 + c1 + 1) / 2, rounding up, and index 3 is black. BC1 here is
// the RGB format: decoded alpha is always 255.
#pragma once

#include <cstddef>
#include <cstdint>

#include "codec/bc.h"

namespace vt {

// Encodes 16 RGBA texels (64 bytes, row-major; alpha ignored) into one 8-byte block. Always
// emits a 4-colour block when `four_colour_only` (BC3/DXT5 colour halves decode every block as
// 4-colour); otherwise kHigh may choose the 3-colour mode where it is closer.
void bc1_encode_block(const uint8_t rgba[64], BcQuality quality, uint8_t out[8],
                      bool four_colour_only = false);

// The real-time level for many blocks at once (what bc_encode_image uses): `count` blocks of 16
// RGBA texels each, back to back in `rgba`; block i is written at out + i * out_stride (8 for
// BC1, 16 with offset 8 for BC3 colour halves). Always 4-colour; the same bytes as
// bc1_encode_block(..., kRealtime, ...) block by block, on every machine.
void bc1_encode_blocks_realtime(const uint8_t* rgba, size_t count, uint8_t* out, size_t out_stride);
// The same for `count` blocks side by side in an image row of blocks: `texels` points at the
// first block's top-left texel, rows `row_stride` bytes apart, `channels` (1..4) interleaved 8-bit
// channels (missing colour channels read as 0); block i goes to out + 8 * i. The same bytes as
// gathering the blocks as RGBA for bc1_encode_blocks_realtime, without the copy.
void bc1_encode_rows_realtime(const uint8_t* texels, size_t row_stride, int channels, size_t count,
                              uint8_t* out);

// Decodes one block into 16 RGBA texels. `force_four_colour` decodes as the colour half of a
// BC3 block does (always 4-colour, whatever the endpoint order).
void bc1_decode_block(const uint8_t block[8], uint8_t rgba[64], bool force_four_colour = false);

}  // namespace vt
