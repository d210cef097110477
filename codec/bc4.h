// BC4 blocks (one channel, 8 bytes: two 8-bit endpoints and 3-bit indices) and BC5 (two BC4
// blocks, R then G: normal-map XY). Block-level entry points behind bc_encode_image.
//
// Decoding rounds as Mesa's lavapipe does (u_format_rgtc): in 8-value mode (e0 > e1) entry k of
// 2..7 is ((8 - k) * e0 + (k - 1) * e1) / 7; in 6-value mode (e0 <= e1) entry k of 2..5 is
// ((6 - k) * e0 + (k - 1) * e1) / 5, entry 6 is 0 and entry 7 is 255; the divisions truncate.
#pragma once

#include <cstdint>

#include "codec/bc.h"

namespace vt {

// Encodes the 16 values texels[i * stride], i = 0..15 (a 4x4 block, row-major).
void bc4_encode_block(const uint8_t* texels, int stride, BcQuality quality, uint8_t out[8]);
// Decodes one block into texels[i * stride].
void bc4_decode_block(const uint8_t block[8], uint8_t* texels, int stride);

// BC5: channel 0 and channel 1 of 16 RGBA texels (64 bytes) into a 16-byte block.
void bc5_encode_block(const uint8_t rgba[64], BcQuality quality, uint8_t out[16]);
// Writes channels 0 and 1 of 16 RGBA texels; channel 2 is 0 and channel 3 is 255.
void bc5_decode_block(const uint8_t block[16], uint8_t rgba[64]);

}  // namespace vt
