// The physical page cache: which page lives in which slot of the physical texture(s). A fixed
// pool of slots shared by all layers (slot s holds page p in every layer's cache texture), LRU
// replacement, the last level's page pinned, and a structural rule the page table relies on:
// a page is only mapped while its parent chain is resident, so only leaves (pages with no
// resident child) are ever evicted.
// Bookkeeping only, no texel storage: the Streamer pairs it with the loader and page table.
// Not thread-safe (the Streamer serialises access).
#pragma once

#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

#include "format/page_geometry.h"

namespace vt {

struct CacheEvent {
  enum class Kind : uint8_t { kMap, kUnmap };
  Kind kind = Kind::kMap;
  PageId page;
  uint32_t slot = 0;  // slot index: x = slot % slots_x, y = slot / slots_x
};

class PageCache {
 public:
  // `slot_count` slots (>= 1).
  PageCache(const PageGeometry& geometry, uint32_t slot_count);

  uint32_t capacity() const { return uint32_t(slots_.size()); }
  uint32_t resident_count() const { return uint32_t(index_.size()); }
  std::optional<uint32_t> slot_of(const PageId& id) const;
  bool resident(const PageId& id) const { return slot_of(id).has_value(); }
  // Page held by a slot, if any.
  std::optional<PageId> page_in(uint32_t slot) const;

  // Marks a resident page used in `frame` (LRU age). No-op for pages not resident.
  void touch(const PageId& id, uint64_t frame);

  // Maps `page` (not resident) into a free slot, or evicts the least recently used evictable
  // page: a leaf, not pinned, not used in `frame`. `parent` is the nearest present ancestor,
  // which must be resident (nullopt only for a root: a page with no present ancestor). Root
  // pages are pinned. Appends the unmap (if any) and the map to `events`. Returns the slot, or
  // nullopt when every slot is pinned, a parent, or in use this frame (the cache is thrashing).
  std::optional<uint32_t> map(const PageId& page, std::optional<PageId> parent, uint64_t frame,
                              std::vector<CacheEvent>& events);
  // Evicts a resident leaf that is not pinned. False (and no change) otherwise.
  bool unmap(const PageId& page, std::vector<CacheEvent>& events);
  // Whether unmap(page) would succeed.
  bool evictable(const PageId& page) const;

  // Resident pages in slot order (for tests and tools).
  std::vector<PageId> resident_pages() const;

 private:
  struct SlotInfo {
    PageId page;
    std::optional<PageId> parent;
    uint64_t last_used = 0;
    uint32_t children = 0;  // resident pages whose parent is this one
    bool used = false;
    bool pinned = false;
    uint32_t prev = kNone, next = kNone;  // LRU list of unpinned slots, oldest first
  };
  static constexpr uint32_t kNone = 0xFFFFFFFFu;
  uint64_t key(const PageId& id) const {
    return (uint64_t(id.level) << 48) | (uint64_t(id.y) << 24) | id.x;
  }
  void lru_remove(uint32_t slot);
  void lru_push_back(uint32_t slot);
  void release(uint32_t slot, std::vector<CacheEvent>& events);

  PageGeometry geometry_;
  std::vector<SlotInfo> slots_;
  std::vector<uint32_t> free_;
  std::unordered_map<uint64_t, uint32_t> index_;
  uint32_t lru_head_ = kNone, lru_tail_ = kNone;
};

}  // namespace vt
