// The feedback buffer and its resolver.
//
// Feedback buffer (written by the renderer's feedback pass, read back to the CPU): one uint32
// per pixel, row-major, no padding between rows:
//   bits  0-11  page x at the wanted level (0..4095)
//   bits 12-23  page y at the wanted level (0..4095)
//   bits 24-28  wanted level (0..31)
//   bits 29-31  virtual texture id (0..6): several virtual textures share one buffer, each
//               streamer reads the values of its own id (0 for an engine with one)
//   0xFFFFFFFF  no request (background pixel)
// Values of another texture are skipped (counted apart); texture id 7 (other than the
// background value) or a page outside the geometry is counted as invalid and ignored.
//
// The resolver turns a buffer into the deduplicated set of pages the frame needs: each request
// is shifted by the LOD bias, moved to its nearest present ancestor (pages absent from the file
// resolve to the parent), and completed with its chain of present ancestors up to the last
// level. Result order is the load priority: coarser level first, then more pixels first, then
// (y, x) so the order never depends on anything but the buffer.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "format/page_geometry.h"
#include "runtime/page_source.h"

namespace vt {

inline constexpr uint32_t kFeedbackNone = 0xFFFFFFFFu;
inline constexpr uint32_t kFeedbackMaxPages = 4096;  // per axis, 12 bits
inline constexpr uint32_t kFeedbackMaxLevels = 32;   // 5 bits
inline constexpr uint32_t kFeedbackMaxTextures = 7;  // 3 bits; 7 is reserved (background)

inline uint32_t feedback_pack(uint32_t level, uint32_t x, uint32_t y, uint32_t texture = 0) {
  return (x & 0xFFFu) | ((y & 0xFFFu) << 12) | ((level & 0x1Fu) << 24) | ((texture & 7u) << 29);
}
inline uint32_t feedback_texture(uint32_t value) {
  return value >> 29;
}
inline PageId feedback_unpack(uint32_t value) {
  return PageId{(value >> 24) & 0x1Fu, value & 0xFFFu, (value >> 12) & 0xFFFu};
}

struct PageRequest {
  PageId id;
  uint32_t pixels = 0;  // pixels asking for this page or any of its descendants
};

struct ResolveStats {
  uint64_t pixels = 0;                // non-background pixels of this resolver's texture
  uint64_t invalid_pixels = 0;        // of them: malformed values or pages outside the geometry
  uint64_t other_texture_pixels = 0;  // pixels of other virtual textures (skipped)
  uint32_t unique_values = 0;         // distinct feedback values before ancestor completion
};

// Reusable: keeps its hash tables between frames so a steady state allocates nothing.
// Not thread-safe (one resolver per caller thread).
class FeedbackResolver {
 public:
  // `source` gives the geometry (at most 4096 x 4096 pages at level 0 and 32 levels, the
  // format's limits; Streamer::create checks) and the presence map; it must outlive the
  // resolver. Only values whose texture id is `texture_id` (< kFeedbackMaxTextures) count.
  explicit FeedbackResolver(const PageSource& source, uint32_t texture_id = 0);
  ~FeedbackResolver();
  FeedbackResolver(FeedbackResolver&&) noexcept;
  FeedbackResolver& operator=(FeedbackResolver&&) noexcept;

  // Resolves `feedback` (any number of pixels) with `lod_bias` >= 0 levels added to every
  // request. Replaces `out` with the prioritised page set. Runs in one pass over the buffer
  // (runs of equal values are counted at once) plus work proportional to the distinct pages.
  ResolveStats resolve(std::span<const uint32_t> feedback, uint32_t lod_bias,
                       std::vector<PageRequest>& out);

  // Nearest present page at or above `id` (id itself when present); the last level's page when
  // no ancestor is present.
  PageId nearest_present(PageId id) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vt
