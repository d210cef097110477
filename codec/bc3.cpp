// BC3 = BC4 alpha + 4-colour BC1 colour.
#include "codec/bc3.h"

#include "codec/bc1.h"
#include "codec/bc4.h"

namespace vt {

void bc3_encode_block(const uint8_t rgba[64], BcQuality quality, uint8_t out[16]) {
  bc4_encode_block(rgba + 3, 4, quality, out);
  bc1_encode_block(rgba, quality, out + 8, /*four_colour_only=*/true);
}

void bc3_decode_block(const uint8_t block[16], uint8_t rgba[64]) {
  bc1_decode_block(block + 8, rgba, /*force_four_colour=*/true);
  bc4_decode_block(block, rgba + 3, 4);
}

}  // namespace vt
