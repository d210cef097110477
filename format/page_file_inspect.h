// What a page file holds and whether it is intact: per-level page counts and bytes (for
// `vtbake info`), every page's checksum (for `vtbake verify`), and one level reassembled into
// an image (for `vtbake extract`).
#pragma once

#include <cstdint>
#include <vector>

#include "common/status.h"
#include "format/page_file.h"

namespace vt {

struct LevelStats {
  uint32_t level = 0;
  uint32_t pages_x = 0, pages_y = 0;
  uint64_t stored_pages = 0;  // (page, layer) pairs, summed over layers
  uint64_t constant_pages = 0;
  uint64_t absent_pages = 0;
  uint64_t bytes = 0;      // stored bytes of the level's pages
  uint64_t raw_bytes = 0;  // decoded bytes of its stored and constant pages
};

struct PageFileStats {
  std::vector<LevelStats> levels;  // level 0 first
  uint64_t stored_bytes = 0;       // sum of levels[].bytes
  uint64_t raw_bytes = 0;          // sum of levels[].raw_bytes
  // raw_bytes / stored_bytes (0 when nothing is stored): how much the codecs saved.
  double compression_ratio = 0;
};

// Counts pages from the index (reads no page data).
PageFileStats page_file_stats(const PageFileReader& reader);

struct BadPage {
  PageId id;
  uint32_t layer = 0;
  Status status;
};

struct VerifyReport {
  uint64_t pages_checked = 0;      // stored (page, layer) pairs whose checksum was computed
  std::vector<BadPage> bad_pages;  // in index order, whatever the thread count
};

// Checks the checksum of every stored page with `threads` threads (0 = hardware threads).
VerifyReport verify_pages(const PageFileReader& reader, int threads = 0);

// One level's payload texels as an image of level_width x level_height texels, the layer's
// channels interleaved, row-major, texel_bytes() per texel.
struct LevelImage {
  uint32_t width = 0, height = 0;
  uint32_t channels = 0;
  TexelType texel_type = TexelType::kU8;
  std::vector<uint8_t> texels;
  uint64_t filled_from_ancestor = 0;  // absent pages filled from a coarser level
  uint64_t filled_with_zero = 0;      // absent pages with no present ancestor
};

// Reassembles a level from its pages' payloads (borders dropped). An absent page is filled from
// its nearest present ancestor (page (x >> d, y >> d) of level + d), upsampled nearest: level
// texel (tx, ty) reads ancestor level texel (tx >> d, ty >> d); with no present ancestor it
// stays zero. A page that fails to read or decode gives its error. A level image larger than
// `max_bytes` gives kInvalidArgument naming the file, the level and the size before anything is
// allocated: a header is small whatever geometry it claims (an 11 KB file can describe a
// 2^24 x 2^24 level), so the size a file asks for is never trusted.
inline constexpr uint64_t kMaxLevelImageBytes = uint64_t(4) << 30;  // 4 GiB
Expected<LevelImage> extract_level(const PageFileReader& reader, uint32_t level, uint32_t layer,
                                   uint64_t max_bytes = kMaxLevelImageBytes);

}  // namespace vt
