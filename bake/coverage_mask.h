// Which texels of a level some chart covers: 1 bit per texel (rows packed in 32-bit words), in
// memory while it is small beside the memory limit and otherwise in an unlinked scratch file
// (a LevelStore), read and written in bands of rows. Every user reads rows, never the whole mask,
// so a world-scale atlas's masks cost no memory per texel.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/status.h"
#include "format/page_geometry.h"

namespace vt {

class LevelStore;

class CoverageMask {
 public:
  // A mask with no texel covered; in a scratch file under `scratch_dir` unless `in_memory`.
  static Expected<std::shared_ptr<CoverageMask>> create(uint32_t width, uint32_t height,
                                                        bool in_memory,
                                                        const std::string& scratch_dir);
  // An in-memory mask from one byte per texel (non-zero = covered), width * height bytes.
  static std::shared_ptr<CoverageMask> from_bytes(uint32_t width, uint32_t height,
                                                  const uint8_t* bytes);
  // Whether a width x height mask stays in memory under `memory_limit`: up to 1/64 of it (a
  // 16,384^2 mask at 2 GiB). A bake holds level 0's mask and, per layer, two levels' at most.
  static bool fits_memory(uint64_t width, uint64_t height, uint64_t memory_limit) {
    return packed_bytes(width, height) <= memory_limit / 64;
  }
  static uint64_t packed_bytes(uint64_t width, uint64_t height) {
    return (width + 31) / 32 * 4 * height;
  }
  // Memory the masks of a width x height level and its pyramid take at most under
  // `memory_limit` (those that fits_memory keeps there; about 1/48 of the limit at most).
  static uint64_t pyramid_memory_bytes(uint64_t width, uint64_t height, uint64_t memory_limit);
  ~CoverageMask();
  CoverageMask(const CoverageMask&) = delete;
  CoverageMask& operator=(const CoverageMask&) = delete;

  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  bool in_memory() const;

  // Sets rows [y0, y0 + rows) from one byte per texel (non-zero = covered).
  Status write_rows(uint32_t y0, uint32_t rows, const uint8_t* texels);
  // Rows [y0, y1) as one byte per texel, 0 or 1, into `out` (resized). Safe from many threads.
  Status read_rows(uint32_t y0, uint32_t y1, std::vector<uint8_t>& out) const;
  // Rows [y_begin, y_begin + rows), which may reach past the edges, resolved by `mode` as a
  // RowWindow resolves a level's rows (the downsample's CoverageBand), into `out` (resized).
  Status read_addressed_rows(int64_t y_begin, uint32_t rows, AddressMode mode,
                             std::vector<uint8_t>& out) const;
  // The whole mask as bytes (tests and the validator's small levels).
  Expected<std::vector<uint8_t>> to_bytes() const;
  // Rows moved at a time by the mask's own loops (about 4 MiB as bytes); callers that stream a
  // mask to or from a file use it too.
  uint32_t band_rows() const;
  // XXH3 of to_bytes(), computed in bands (the plan hash's, as when masks were bytes) once
  // until the next write: every layer of a scene bake shares level 0's mask.
  Expected<uint64_t> content_hash() const;
  // The half-size level's mask: a texel is covered when any of its 2x2 footprint is (the
  // footprint clamped at odd sizes; downsample_coverage's rule), derived in bands.
  Expected<std::shared_ptr<CoverageMask>> downsample(bool in_memory,
                                                     const std::string& scratch_dir) const;

 private:
  CoverageMask() = default;
  uint32_t words() const { return (width_ + 31) / 32; }
  uint32_t width_ = 0, height_ = 0;
  std::unique_ptr<LevelStore> store_;  // words() 32-bit words a row (moved as floats' bytes)
  mutable std::optional<uint64_t> hash_;
};

}  // namespace vt
