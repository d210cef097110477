// The virtual-texture streamer: what an engine calls once per frame. It resolves the frame's
// feedback buffer, refreshes the LRU age of resident pages, queues absent ones on the loader
// (coarser first), cancels loads no longer needed, maps finished pages into the cache (parent
// chain first, never above the memory budget), updates the page table and hands back this
// frame's upload list. When the frame's working set exceeds the cache it raises the LOD bias
// one level per frame until it fits, and lowers it again when the set has shrunk for a while.
//
// Per frame:  streamer->update(feedback);  for (auto& u : streamer->take_uploads()) copy
// u.layers[l] into slot (u.slot_x, u.slot_y) of layer l's cache texture;  upload the page
// table's dirty rectangles (page_table.h);  streamer->clear_table_dirty();  draw.
// Uploads of a frame must be applied before drawing with that frame's page table (a slot may
// have been reused). All methods are thread-safe; update() never waits for I/O or decoding.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "common/status.h"
#include "format/page_geometry.h"
#include "runtime/feedback.h"
#include "runtime/page_cache.h"
#include "runtime/page_loader.h"
#include "runtime/page_source.h"
#include "runtime/page_table.h"

namespace vt {

struct StreamerOptions {
  uint32_t slots_x = 32;  // physical cache: slots_x x slots_y slots (each <= 256)
  uint32_t slots_y = 32;
  // Upper bound on resident page bytes (all layers) plus loader staging
  // (max_in_flight pages). 0: no bound beyond the slot count. Slots that would exceed it are
  // not used; create() fails with kResourceLimit when not even the staging and one slot fit.
  uint64_t memory_budget_bytes = 0;
  uint32_t threads = 2;  // loader threads; ignored when `jobs` is enabled
  uint32_t max_in_flight = 64;
  uint64_t upload_byte_limit = 16u << 20;  // per update(); at least one page is always let out
  uint32_t max_lod_bias = 8;
  // The bias is lowered after this many consecutive frames whose working set, at one level
  // finer, would have filled at most 3/4 of the cache.
  uint32_t frames_before_lowering = 30;
  // Which virtual texture of the feedback buffer this streamer serves (feedback.h: several
  // textures share one buffer). 0..kFeedbackMaxTextures-1.
  uint32_t texture_id = 0;
  JobSystem jobs;       // the engine's job system instead of the loader's threads
  Allocator allocator;  // upload and staging buffers (see page_buffer.h)
};

struct PageUpload {
  PageId page;
  uint32_t slot_x = 0, slot_y = 0;
  std::vector<PageBuffer> layers;  // PageSource::upload_bytes(l) bytes per layer
};

struct FrameStats {
  uint64_t frame = 0;
  uint32_t needed = 0;  // distinct pages the frame needs (with ancestor chains)
  uint32_t resident_hits = 0;
  uint32_t queued = 0;  // new loads this frame
  uint32_t cancelled = 0;
  uint32_t mapped = 0;  // pages mapped (== uploads) this frame
  uint32_t evicted = 0;
  uint32_t dropped = 0;      // finished loads that found no slot (thrashing) or failed
  uint32_t load_errors = 0;  // pages the source could not deliver (never retried: the
                             // parent stands in for them)
  uint32_t lod_bias = 0;     // bias in force for the next frame
  bool thrashing = false;    // the working set did not fit the cache this frame
  uint64_t invalid_pixels = 0;
  uint64_t other_texture_pixels = 0;  // pixels of another virtual texture's id (skipped)
  uint64_t resident_bytes = 0;
};

class Streamer {
 public:
  // Loads the last level's page synchronously (it is pinned) and queues it as the first upload.
  static Expected<std::unique_ptr<Streamer>> create(std::shared_ptr<const PageSource> source,
                                                    const StreamerOptions& options);
  ~Streamer();
  Streamer(const Streamer&) = delete;
  Streamer& operator=(const Streamer&) = delete;

  // One frame: `feedback` is the buffer described in feedback.h (any size; empty is fine).
  FrameStats update(std::span<const uint32_t> feedback);
  // Explicit prefetch of one page (and its ancestor chain), as if one pixel asked for it.
  void request(const PageId& id);
  // Explicit eviction of a resident leaf page that is not pinned. False when not possible.
  bool evict(const PageId& id);

  // This frame's uploads (moved out; empty on the second call). Take them every frame: uploads
  // not taken hold staging memory, and no new load starts while staging is full.
  std::vector<PageUpload> take_uploads();
  // A copy of the page table (for uploads: level_data + dirty rectangles).
  PageTable page_table() const;
  // Calls `fn` with the live table under the streamer's lock (no copy: for large tables,
  // copy just the dirty rectangles). `fn` must not call back into the streamer.
  void with_page_table(const std::function<void(const PageTable&)>& fn) const;
  void clear_table_dirty();

  uint32_t lod_bias() const;
  bool idle() const;  // nothing queued, loading or waiting to be mapped
  // Blocks until the loader has finished every queued page (tools, tests, validation).
  void wait_idle();

  uint32_t capacity() const;       // usable slots (after the memory budget)
  uint64_t memory_bytes() const;   // resident + staging bytes now
  uint64_t memory_budget() const;  // 0 when unbounded
  std::vector<PageId> resident_pages() const;
  // Checks the invariants (every table entry points at a resident page of its level or a
  // coarser one, every resident page's present ancestors are resident, the budget holds).
  Status check_invariants() const;
  const PageSource& source() const;
  uint32_t slots_x() const;
  uint32_t slots_y() const;

 private:
  struct Impl;
  explicit Streamer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace vt
