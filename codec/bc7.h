// BC7 blocks: 4x4 RGBA texels in 16 bytes, eight modes (1-3 subsets, partitions, p-bits,
// rotation). Decoding follows the format exactly (interpolation ((64 - w) * e0 + w * e1 + 32)
// >> 6 with the standard weights; the reserved mode 8 decodes to transparent black), so it is
// bit-exact with every conforming decoder, lavapipe included.
//
// Encoder levels: kRealtime fits mode 6 alone, many blocks at a time (bc7_realtime.cpp); kNormal
// fits mode 6 (plus mode 5 when the block has alpha) and adds
// the two-subset modes 1 and 3 (mode 7 with alpha) over the partitions that a quick line-fit
// estimate ranks best, and modes 4/5; kHigh adds the three-subset modes 0 and 2, searches more
// partitions, every p-bit combination, rotations and index selections, and iterates the
// least-squares refinement.
#pragma once

#include <cstddef>
#include <cstdint>

#include "codec/bc.h"

namespace vt {

// Encodes 16 RGBA texels (64 bytes, row-major) into one 16-byte block. With `ignore_alpha`
// (RGB content: bc_encode_image with fewer than 4 channels) alpha error is not counted, so
// mode 6 spends its p-bits on colour; decoded alpha is then 254 or 255.
void bc7_encode_block(const uint8_t rgba[64], BcQuality quality, uint8_t out[16],
                      bool ignore_alpha = false);
// The real-time level for many blocks at once (what bc_encode_image uses): `count` blocks of 16
// RGBA texels each, back to back in `rgba`; block i is written at out + 16 * i. Opaque blocks
// decode to alpha 255 exactly (254 or 255 with `ignore_alpha`). The same bytes as
// bc7_encode_block(..., kRealtime, ...) block by block, on every machine.
void bc7_encode_blocks_realtime(const uint8_t* rgba, size_t count, uint8_t* out, bool ignore_alpha);
// Decodes one block into 16 RGBA texels. Any 16 bytes are a valid input.
void bc7_decode_block(const uint8_t block[16], uint8_t rgba[64]);
// The mode (0-7) of an encoded block, 8 for the reserved pattern (first byte 0).
int bc7_block_mode(const uint8_t block[16]);

}  // namespace vt
