// A PNG's chunk structure checked before OpenImageIO decodes it. libpng prints its own
// "libpng error: ..." line on stderr for a corrupt file (OpenImageIO 2.4's error handler
// returns, so libpng's default one prints before it jumps out), beside vtbake's message naming
// the file. Catching the corruption first keeps that line away for the common cases: damaged or
// truncated files, whose chunk checksums or lengths no longer match.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "common/status.h"

namespace vt {

// Ok for a file that is not a PNG (no PNG signature: other readers decide) and for a PNG whose
// chunks are all inside the file, with correct CRCs for every critical chunk, IHDR first and
// an IEND. Otherwise kCorrupt naming the file, the chunk, its byte offset and the problem.
// What it cannot see: compressed data that is wrong under a correct CRC (a crafted file).
Status check_png_chunks(const std::string& path);
// The same for a PNG in memory (a glTF's embedded image); `name` stands for the file in messages.
Status check_png_chunks(std::span<const uint8_t> bytes, const std::string& name);

}  // namespace vt
