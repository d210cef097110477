// BC6H blocks: 4x4 RGB half-float texels in 16 bytes (Khronos Data Format Specification, "BC6H";
// Direct3D 11 BC6H_UF16 / BC6H_SF16). Fourteen modes: one region with 4-bit indices (modes
// 11-14) or two regions over 32 partitions with 3-bit indices (modes 1-10); endpoints stored as
// a base and signed deltas ("transformed" modes) or as they are (modes 10 and 11), unquantized
// to 16 bits, interpolated, then scaled by 31/64 (unsigned) or 31/32 (signed magnitude) into
// half-float bits. Unsigned blocks hold 0..65504, signed ones -65504..65504; no alpha.
// Decoding follows the format exactly (bit for bit with Mesa's lavapipe); the four reserved
// mode values decode to 0.
//
// Encoders work on the half-float bit patterns as integers (sign and magnitude for SF16), which
// is where the format interpolates: roughly log2 space, so every exposure gets the same relative
// precision. They minimise the squared error of those integers.
//   kRealtime: one region; endpoints along the principal axis, one least-squares step, indices
//     by projection; the most precise of modes 11-14 that holds the endpoints. For load-time
//     transcoding: 16 blocks at a time in SIMD (bc6h_encode_image; one block alone costs a
//     whole batch).
//   kNormal: also two regions: the 4 partitions whose regions fit a line best, modes 1-10;
//     indices by exhaustive search; least-squares iterations on the quantized endpoints.
//   kHigh: the 12 best partitions, more iterations, then a search of +-1 steps of every
//     quantized endpoint channel of the best candidates. Offline.
// Inputs are sanitised as the GPU formats would hold them: NaN reads 0, infinities the largest
// finite half; an unsigned block reads negative values as 0.
#pragma once

#include <cstdint>

#include "codec/bc.h"

namespace vt {

// Encodes 16 texels of three half-float channels (48 values, row-major RGB) into one block.
void bc6h_encode_block(const uint16_t rgb[48], bool is_signed, BcQuality quality, uint8_t out[16]);
// A reference search for benchmarks (the yardstick for kHigh, issue 19), about 10x kHigh's
// time: every mode and all 32 partitions, 8 least-squares iterations each, then a search of
// +-1, +-2 and +-4 steps of every stored endpoint channel on the best candidate of every
// partition, up to 8 rounds. Not a runtime path.
void bc6h_encode_block_reference(const uint16_t rgb[48], bool is_signed, uint8_t out[16]);
// Decodes one block into 16 RGB half-float texels. Any 16 bytes are a valid input; the output
// is never NaN or infinite for unsigned blocks (signed mode 14 can encode -65536 as -infinity,
// which no encoder here writes).
void bc6h_decode_block(const uint8_t block[16], bool is_signed, uint16_t rgb[48]);
// The Direct3D mode number (1-14) of a block, 0 for the reserved mode values.
int bc6h_block_mode(const uint8_t block[16]);
// The partition (0-31) of a two-region block, -1 for one-region or reserved blocks.
int bc6h_block_partition(const uint8_t block[16]);

// What an encoder codes for half `h`: NaN as 0, infinities as +-65504, negatives as 0 when
// unsigned; the result as the integer BC6H interpolates (magnitude, negated for negatives).
int bc6h_half_to_int(uint16_t h, bool is_signed);

// Whole images (behind bc_encode_image/bc_decode_image for kBc6hUf16/kBc6hSf16): `texels` are
// width x height texels of `channels` half floats (native byte order); channels past the third
// are ignored on encode, a missing colour channel reads 0, and a decoded fourth channel is 1.0.
// Any alignment (the values are copied in and out, so byte buffers need no cast).
Status bc6h_encode_image(bool is_signed, BcQuality quality, const void* texels, int width,
                         int height, int channels, uint8_t* out);
Status bc6h_decode_image(bool is_signed, const uint8_t* blocks, int width, int height, int channels,
                         void* texels);

}  // namespace vt
