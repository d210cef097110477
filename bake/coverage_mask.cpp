#include "bake/coverage_mask.h"

#define XXH_STATIC_LINKING_ONLY  // XXH3_state_t on the stack
#include <xxhash.h>
#include <algorithm>
#include <bit>
#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "bake/level_store.h"
#include "bake/pyramid.h"

namespace vt {
namespace {

// Rows of packed words <-> one byte per texel, a word (or a byte of one) at a time: a 64K atlas's
// mask is 4.3 G texels, packed once and unpacked several times by every bake and shard (bit by
// bit that was ~0.8 ns a texel, 3.5 s a pass).
void pack_row(const uint8_t* texels, uint32_t width, uint32_t* words) {
  uint32_t x = 0;
#if defined(__SSE2__)
  const __m128i zero = _mm_setzero_si128();
  for (; x + 32 <= width; x += 32) {
    const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(texels + x));
    const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(texels + x + 16));
    const uint32_t zero_a = uint32_t(_mm_movemask_epi8(_mm_cmpeq_epi8(a, zero)));
    const uint32_t zero_b = uint32_t(_mm_movemask_epi8(_mm_cmpeq_epi8(b, zero)));
    words[x / 32] = ~(zero_a | zero_b << 16);
  }
#endif
  for (; x < width; x += 32) {
    uint32_t word = 0;
    for (uint32_t i = 0; i < 32 && x + i < width; ++i) word |= uint32_t(texels[x + i] != 0) << i;
    words[x / 32] = word;
  }
}

// Byte b's 8 bits as 8 bytes of 0 or 1 (little-endian: bit i in byte i).
struct SpreadBits {
  uint64_t bytes[256];
  constexpr SpreadBits() : bytes() {
    for (int b = 0; b < 256; ++b)
      for (int i = 0; i < 8; ++i) bytes[b] |= uint64_t((b >> i) & 1) << (8 * i);
  }
};
constexpr SpreadBits kSpreadBits;

void unpack_row(const uint32_t* words, uint32_t width, uint8_t* texels) {
  uint32_t x = 0;
  for (; x + 8 <= width; x += 8) {
    uint64_t spread = kSpreadBits.bytes[(words[x / 32] >> (x % 32)) & 0xffu];
    if constexpr (std::endian::native == std::endian::big) spread = __builtin_bswap64(spread);
    std::memcpy(texels + x, &spread, 8);
  }
  for (; x < width; ++x) texels[x] = uint8_t((words[x / 32] >> (x % 32)) & 1u);
}

}  // namespace

Expected<std::shared_ptr<CoverageMask>> CoverageMask::create(uint32_t width, uint32_t height,
                                                             bool in_memory,
                                                             const std::string& scratch_dir) {
  std::shared_ptr<CoverageMask> m(new CoverageMask());
  m->width_ = width, m->height_ = height;
  VT_ASSIGN_OR_RETURN(m->store_, LevelStore::create(m->words(), height, 1, in_memory, scratch_dir));
  if (!in_memory) {  // a scratch file reads as zeros only where written: write the empty rows
    const uint32_t band = m->band_rows();
    const std::vector<float> zeros(size_t(m->words()) * band, 0.0f);
    for (uint32_t y = 0; y < height; y += band)
      VT_RETURN_IF_ERROR(m->store_->write_rows(y, std::min(band, height - y), zeros.data()));
  }
  return m;
}

std::shared_ptr<CoverageMask> CoverageMask::from_bytes(uint32_t width, uint32_t height,
                                                       const uint8_t* bytes) {
  auto m = create(width, height, true, "");
  (void)(*m)->write_rows(0, height, bytes);  // in memory: cannot fail
  return *m;
}

uint64_t CoverageMask::pyramid_memory_bytes(uint64_t width, uint64_t height,
                                            uint64_t memory_limit) {
  uint64_t bytes = 0;
  for (;; width = (width + 1) / 2, height = (height + 1) / 2) {
    if (fits_memory(width, height, memory_limit)) bytes += packed_bytes(width, height);
    if (width <= 1 && height <= 1) return bytes;
  }
}

CoverageMask::~CoverageMask() = default;

bool CoverageMask::in_memory() const {
  return store_->in_memory();
}

// Rows moved at a time: about 4 MiB of bytes.
uint32_t CoverageMask::band_rows() const {
  return uint32_t(
      std::clamp<uint64_t>((uint64_t(4) << 20) / std::max(width_, 1u), 1, std::max(height_, 1u)));
}

Status CoverageMask::write_rows(uint32_t y0, uint32_t rows, const uint8_t* texels) {
  hash_.reset();
  std::vector<uint32_t> packed(size_t(words()) * rows);
  for (uint32_t r = 0; r < rows; ++r)
    pack_row(texels + size_t(r) * width_, width_, packed.data() + size_t(r) * words());
  return store_->write_rows(y0, rows, reinterpret_cast<const float*>(packed.data()));
}

Status CoverageMask::read_rows(uint32_t y0, uint32_t y1, std::vector<uint8_t>& out) const {
  std::vector<uint32_t> packed(size_t(words()) * (y1 - y0));
  VT_RETURN_IF_ERROR(store_->read(y0, y1, reinterpret_cast<float*>(packed.data())));
  out.resize(size_t(width_) * (y1 - y0));
  for (uint32_t r = 0; r < y1 - y0; ++r)
    unpack_row(packed.data() + size_t(r) * words(), width_, out.data() + size_t(r) * width_);
  return Status::Ok();
}

Status CoverageMask::read_addressed_rows(int64_t y_begin, uint32_t rows, AddressMode mode,
                                         std::vector<uint8_t>& out) const {
  out.resize(size_t(width_) * rows);
  const int64_t y_end = y_begin + rows;
  const int64_t lo = std::clamp<int64_t>(y_begin, 0, height_);
  const int64_t hi = std::clamp<int64_t>(y_end, 0, height_);
  std::vector<uint8_t> part;
  if (hi > lo) {
    VT_RETURN_IF_ERROR(read_rows(uint32_t(lo), uint32_t(hi), part));
    std::copy(part.begin(), part.end(), out.begin() + size_t(lo - y_begin) * width_);
  }
  for (int64_t y = y_begin; y < y_end; ++y) {  // the few rows past an edge
    if (y >= lo && y < hi) continue;
    const uint32_t a = uint32_t(address_texel(y, height_, mode));
    VT_RETURN_IF_ERROR(read_rows(a, a + 1, part));
    std::copy(part.begin(), part.end(), out.begin() + size_t(y - y_begin) * width_);
  }
  return Status::Ok();
}

Expected<std::vector<uint8_t>> CoverageMask::to_bytes() const {
  std::vector<uint8_t> out;
  VT_RETURN_IF_ERROR(read_rows(0, height_, out));
  return out;
}

Expected<uint64_t> CoverageMask::content_hash() const {
  if (hash_) return *hash_;
  XXH3_state_t state;
  XXH3_64bits_reset(&state);
  std::vector<uint8_t> rows;
  for (uint32_t y = 0; y < height_; y += band_rows()) {
    VT_RETURN_IF_ERROR(read_rows(y, std::min(height_, y + band_rows()), rows));
    XXH3_64bits_update(&state, rows.data(), rows.size());
  }
  hash_ = XXH3_64bits_digest(&state);
  return *hash_;
}

Expected<std::shared_ptr<CoverageMask>> CoverageMask::downsample(
    bool in_memory, const std::string& scratch_dir) const {
  VT_ASSIGN_OR_RETURN(std::shared_ptr<CoverageMask> out,
                      create((width_ + 1) / 2, (height_ + 1) / 2, in_memory, scratch_dir));
  // Bands of an even number of source rows: a destination row's pair never straddles two.
  const uint32_t band = std::max(2u, band_rows() / 2 * 2);
  std::vector<uint8_t> src;
  for (uint32_t y0 = 0; y0 < height_; y0 += band) {
    const uint32_t y1 = std::min(height_, y0 + band);
    VT_RETURN_IF_ERROR(read_rows(y0, y1, src));
    // Only the last band can be odd, and its last row is the level's: the band's clamp is the
    // level's.
    const std::vector<uint8_t> dst = downsample_coverage(src.data(), width_, y1 - y0);
    VT_RETURN_IF_ERROR(out->write_rows(y0 / 2, (y1 - y0 + 1) / 2, dst.data()));
  }
  return out;
}

}  // namespace vt
