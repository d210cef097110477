// Whole-image BC encode/decode: gathers 4x4 blocks and calls the per-format block codecs.
#include <cstring>
#include <iterator>
#include <string>
#include <vector>

#include "codec/bc.h"
#include "codec/bc1.h"
#include "codec/bc3.h"
#include "codec/bc4.h"
#include "codec/bc6h.h"
#include "codec/bc7.h"

namespace vt {
namespace {

Status check_image(BcFormat format, const void* a, const void* b, int width, int height,
                   int channels) {
  if (int(format) > int(BcFormat::kBc6hSf16)) {
    return Error(ErrorCode::kInvalidArgument, "unknown BC format " + std::to_string(int(format)));
  }
  if (a == nullptr || b == nullptr) {
    return Error(ErrorCode::kInvalidArgument, "null image or block pointer");
  }
  if (width <= 0 || height <= 0 || width % 4 != 0 || height % 4 != 0) {
    return Error(ErrorCode::kInvalidArgument, "image size " + std::to_string(width) + "x" +
                                                  std::to_string(height) +
                                                  " is not a positive multiple of 4");
  }
  if (channels < 1 || channels > 4) {
    return Error(ErrorCode::kInvalidArgument,
                 "channel count " + std::to_string(channels) + " is not 1..4");
  }
  return Status::Ok();
}

// One block to RGBA; the channels a format does not store read 0 (colour) and 255 (alpha).
using BlockDecoder = void (*)(const uint8_t* block, uint8_t* rgba);

void bc1_decode_rgba(const uint8_t* block, uint8_t* rgba) {
  bc1_decode_block(block, rgba);
}

void bc4_decode_rgba(const uint8_t* block, uint8_t* rgba) {
  bc4_decode_block(block, rgba, 4);
  for (int i = 0; i < 16; ++i) rgba[4 * i + 1] = rgba[4 * i + 2] = 0, rgba[4 * i + 3] = 255;
}

// Indexed by BcFormat up to BC7 (BC6H texels are halves: codec/bc6h.cpp).
constexpr BlockDecoder kBlockDecoders[] = {bc1_decode_rgba, bc3_decode_block, bc4_decode_rgba,
                                           bc5_decode_block, bc7_decode_block};
static_assert(std::size(kBlockDecoders) == size_t(BcFormat::kBc7) + 1);

}  // namespace

int bc_format_channels(BcFormat f) {
  switch (f) {
    case BcFormat::kBc1:
      return 3;
    case BcFormat::kBc3:
    case BcFormat::kBc7:
      return 4;
    case BcFormat::kBc4:
      return 1;
    case BcFormat::kBc5:
      return 2;
    case BcFormat::kBc6hUf16:
    case BcFormat::kBc6hSf16:
      return 3;
  }
  return 0;
}

Status bc_encode_image(BcFormat format, BcQuality quality, const uint8_t* texels, int width,
                       int height, int channels, uint8_t* out) {
  VT_RETURN_IF_ERROR(check_image(format, texels, out, width, height, channels));
  if (bc_is_bc6h(format)) {
    return bc6h_encode_image(format == BcFormat::kBc6hSf16, quality, texels, width, height,
                             channels, out);
  }
  const size_t block_bytes = bc_block_bytes(format);
  const size_t row_stride = size_t(width) * size_t(channels);
  const int blocks_x = width / 4;
  if (quality == BcQuality::kRealtime && format == BcFormat::kBc1) {
    // The runtime transcode's hot path: the kernel gathers straight from the rows.
    for (int by = 0; by < height / 4; ++by) {
      bc1_encode_rows_realtime(texels + size_t(by) * 4 * row_stride, row_stride, channels,
                               size_t(blocks_x), out + size_t(by) * size_t(blocks_x) * block_bytes);
    }
    return Status::Ok();
  }
  std::vector<uint8_t> row(size_t(blocks_x) * 64);
  for (int by = 0; by < height / 4; ++by) {
    // Gather one row of blocks as RGBA.
    for (int bx = 0; bx < blocks_x; ++bx) {
      for (int y = 0; y < 4; ++y) {
        const uint8_t* src =
            texels + (size_t(by) * 4 + size_t(y)) * row_stride + size_t(bx) * 4 * size_t(channels);
        uint8_t* dst = row.data() + size_t(bx) * 64 + 16 * y;
        if (channels == 4) {
          std::memcpy(dst, src, 16);
        } else if (channels == 3) {
          for (int x = 0; x < 4; ++x) {
            dst[4 * x] = src[3 * x], dst[4 * x + 1] = src[3 * x + 1];
            dst[4 * x + 2] = src[3 * x + 2], dst[4 * x + 3] = 255;
          }
        } else {
          for (int x = 0; x < 4; ++x) {
            for (int c = 0; c < 4; ++c) {
              dst[4 * x + c] = c < channels ? src[x * channels + c] : (c == 3 ? 255 : 0);
            }
          }
        }
      }
    }
    uint8_t* out_row = out + size_t(by) * size_t(blocks_x) * block_bytes;
    const bool realtime = quality == BcQuality::kRealtime;
    if (realtime && format == BcFormat::kBc1) {
      bc1_encode_blocks_realtime(row.data(), size_t(blocks_x), out_row, 8);
      continue;
    }
    if (realtime && format == BcFormat::kBc7) {
      bc7_encode_blocks_realtime(row.data(), size_t(blocks_x), out_row,
                                 /*ignore_alpha=*/channels < 4);
      continue;
    }
    if (realtime && format == BcFormat::kBc3) {
      bc1_encode_blocks_realtime(row.data(), size_t(blocks_x), out_row + 8, 16);
      for (int bx = 0; bx < blocks_x; ++bx) {
        bc4_encode_block(row.data() + size_t(bx) * 64 + 3, 4, quality, out_row + size_t(bx) * 16);
      }
      continue;
    }
    for (int bx = 0; bx < blocks_x; ++bx) {
      const uint8_t* rgba = row.data() + size_t(bx) * 64;
      uint8_t* block = out_row + size_t(bx) * block_bytes;
      switch (format) {
        case BcFormat::kBc1:
          bc1_encode_block(rgba, quality, block);
          break;
        case BcFormat::kBc3:
          bc3_encode_block(rgba, quality, block);
          break;
        case BcFormat::kBc4:
          bc4_encode_block(rgba, 4, quality, block);
          break;
        case BcFormat::kBc5:
          bc5_encode_block(rgba, quality, block);
          break;
        case BcFormat::kBc7:
          bc7_encode_block(rgba, quality, block, /*ignore_alpha=*/channels < 4);
          break;
        case BcFormat::kBc6hUf16:
        case BcFormat::kBc6hSf16:
          break;  // handled above
      }
    }
  }
  return Status::Ok();
}

Status bc_decode_image(BcFormat format, const uint8_t* blocks, int width, int height, int channels,
                       uint8_t* texels) {
  VT_RETURN_IF_ERROR(check_image(format, blocks, texels, width, height, channels));
  if (bc_is_bc6h(format)) {
    return bc6h_decode_image(format == BcFormat::kBc6hSf16, blocks, width, height, channels,
                             texels);
  }
  const size_t block_bytes = bc_block_bytes(format);
  const size_t row_stride = size_t(width) * size_t(channels);
  const BlockDecoder decode_block = kBlockDecoders[int(format)];
  uint8_t rgba[64];
  for (int by = 0; by < height / 4; ++by) {
    for (int bx = 0; bx < width / 4; ++bx) {
      const uint8_t* block = blocks + (size_t(by) * size_t(width / 4) + size_t(bx)) * block_bytes;
      decode_block(block, rgba);
      for (int y = 0; y < 4; ++y) {
        uint8_t* dst =
            texels + (size_t(by) * 4 + size_t(y)) * row_stride + size_t(bx) * 4 * size_t(channels);
        for (int x = 0; x < 4; ++x) {
          for (int c = 0; c < channels; ++c) dst[x * channels + c] = rgba[16 * y + 4 * x + c];
        }
      }
    }
  }
  return Status::Ok();
}

}  // namespace vt
