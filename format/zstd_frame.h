// zstd frames as page files store them (raw+zstd and bc+zstd pages): the one compressor and the
// one exact-size decompressor every stage uses.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/status.h"

namespace vt {

// Compresses `data` at `level` (ZSTD_compress: the same bytes for the same input and level)
// into `out`, replacing its contents.
Status zstd_compress(std::span<const uint8_t> data, int level, std::vector<uint8_t>& out);
// Decompresses one frame that must expand to exactly out.size() bytes; anything else, a frame
// saying it holds another size included, gives kCorrupt. Allocation-free after a thread's
// first call (one context per thread).
Status zstd_decompress_exact(std::span<const uint8_t> frame, std::span<uint8_t> out);

}  // namespace vt
