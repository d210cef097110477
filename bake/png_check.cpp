#include "bake/png_check.h"

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <vector>

namespace vt {
namespace {

// The CRC-32 of the PNG specification (ISO 3309, reflected polynomial 0xEDB88320).
uint32_t crc_update(uint32_t crc, const uint8_t* data, size_t n) {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  for (size_t i = 0; i < n; ++i) crc = table[(crc ^ data[i]) & 0xFF] ^ (crc >> 8);
  return crc;
}

uint32_t be32(const uint8_t* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3];
}

std::string hex(uint32_t v) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08x", v);
  return text;
}

// The chunk walk over `size` bytes read in order through `read`; `name` starts the messages.
Status check_chunks(uint64_t size, const std::function<bool(uint8_t*, size_t)>& read,
                    const std::string& name) {
  static constexpr uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  uint8_t head[8] = {};
  if (size < 8 || !read(head, 8) || std::memcmp(head, kSignature, 8) != 0) return Status::Ok();
  auto corrupt = [&](const std::string& what) {
    return Error(ErrorCode::kCorrupt, name + ": corrupt PNG: " + what);
  };
  std::vector<uint8_t> data(size_t(1) << 16);
  uint64_t at = 8;
  for (bool first = true;; first = false) {
    uint8_t h[8];
    if (size - at < 12 || !read(h, 8))
      return corrupt("truncated at byte " + std::to_string(at) + " (no IEND chunk)");
    const uint32_t length = be32(h);
    const std::string type(reinterpret_cast<const char*>(h + 4), 4);
    const std::string chunk = "chunk '" + type + "' at byte " + std::to_string(at);
    if (length > 0x7FFFFFFFu || size - at - 12 < length)
      return corrupt(chunk + " claims " + std::to_string(length) + " bytes, the file has " +
                     std::to_string(size - at - 12) + " after its header (truncated?)");
    if (first && type != "IHDR") return corrupt(chunk + ": the first chunk is not IHDR");
    uint32_t crc = crc_update(0xFFFFFFFFu, h + 4, 4);
    for (uint32_t left = length; left > 0;) {
      const uint32_t n = std::min<uint32_t>(left, uint32_t(data.size()));
      if (!read(data.data(), n)) return corrupt(chunk + ": read error");
      crc = crc_update(crc, data.data(), n);
      left -= n;
    }
    uint8_t stored[4];
    if (!read(stored, 4)) return corrupt(chunk + ": read error");
    crc ^= 0xFFFFFFFFu;
    // libpng skips an ancillary chunk (lower-case first letter) whose CRC fails; a critical
    // one is an error there too.
    const bool critical = (h[4] & 0x20) == 0;
    if (critical && crc != be32(stored))
      return corrupt(chunk + ": CRC " + hex(be32(stored)) + " stored, " + hex(crc) +
                     " computed (damaged data)");
    at += 12 + uint64_t(length);
    if (type == "IEND") return Status::Ok();
  }
}

}  // namespace

Status check_png_chunks(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return Status::Ok();  // the image reader reports what cannot be opened
  const uint64_t size = uint64_t(in.tellg());
  in.seekg(0);
  return check_chunks(
      size,
      [&](uint8_t* dst, size_t n) {
        return bool(in.read(reinterpret_cast<char*>(dst), std::streamsize(n)));
      },
      path);
}

Status check_png_chunks(std::span<const uint8_t> bytes, const std::string& name) {
  size_t at = 0;
  return check_chunks(
      bytes.size(),
      [&](uint8_t* dst, size_t n) {
        if (bytes.size() - at < n) return false;
        std::memcpy(dst, bytes.data() + at, n);
        at += n;
        return true;
      },
      name);
}

}  // namespace vt
