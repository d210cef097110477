// BC3 (DXT5) blocks: 16 bytes, a BC4 alpha block followed by a BC1 colour block that the
// decoder always reads in 4-colour mode (see bc1.h and bc4.h for the rounding rules).
#pragma once

#include <cstdint>

#include "codec/bc.h"

namespace vt {

// Encodes 16 RGBA texels (64 bytes, row-major) into one 16-byte block.
void bc3_encode_block(const uint8_t rgba[64], BcQuality quality, uint8_t out[16]);
// Decodes one block into 16 RGBA texels.
void bc3_decode_block(const uint8_t block[16], uint8_t rgba[64]);

}  // namespace vt
