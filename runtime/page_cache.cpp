#include "runtime/page_cache.h"

#include <algorithm>

namespace vt {

PageCache::PageCache(const PageGeometry& geometry, uint32_t slot_count)
    : geometry_(geometry), slots_(std::max<uint32_t>(slot_count, 1)) {
  free_.reserve(slots_.size());
  // Pop from the back: lowest slot first, so slot assignment is deterministic and compact.
  for (uint32_t s = uint32_t(slots_.size()); s-- > 0;) free_.push_back(s);
  index_.reserve(slots_.size() * 2);
}

std::optional<uint32_t> PageCache::slot_of(const PageId& id) const {
  auto it = index_.find(key(id));
  if (it == index_.end()) return std::nullopt;
  return it->second;
}

std::optional<PageId> PageCache::page_in(uint32_t slot) const {
  if (slot >= slots_.size() || !slots_[slot].used) return std::nullopt;
  return slots_[slot].page;
}

void PageCache::lru_remove(uint32_t s) {
  SlotInfo& info = slots_[s];
  if (info.prev != kNone)
    slots_[info.prev].next = info.next;
  else
    lru_head_ = info.next;
  if (info.next != kNone)
    slots_[info.next].prev = info.prev;
  else
    lru_tail_ = info.prev;
  info.prev = info.next = kNone;
}

void PageCache::lru_push_back(uint32_t s) {
  SlotInfo& info = slots_[s];
  info.prev = lru_tail_;
  info.next = kNone;
  if (lru_tail_ != kNone)
    slots_[lru_tail_].next = s;
  else
    lru_head_ = s;
  lru_tail_ = s;
}

void PageCache::touch(const PageId& id, uint64_t frame) {
  auto slot = slot_of(id);
  if (!slot) return;
  SlotInfo& info = slots_[*slot];
  if (info.last_used >= frame) return;
  info.last_used = frame;
  if (!info.pinned) {
    lru_remove(*slot);
    lru_push_back(*slot);
  }
}

bool PageCache::evictable(const PageId& page) const {
  auto slot = slot_of(page);
  if (!slot) return false;
  const SlotInfo& info = slots_[*slot];
  return !info.pinned && info.children == 0;
}

void PageCache::release(uint32_t s, std::vector<CacheEvent>& events) {
  SlotInfo& info = slots_[s];
  if (info.parent) {
    auto ps = slot_of(*info.parent);
    if (ps && slots_[*ps].children > 0) --slots_[*ps].children;
  }
  lru_remove(s);
  index_.erase(key(info.page));
  events.push_back({CacheEvent::Kind::kUnmap, info.page, s});
  info = SlotInfo{};
  free_.push_back(s);
}

bool PageCache::unmap(const PageId& page, std::vector<CacheEvent>& events) {
  if (!evictable(page)) return false;
  release(*slot_of(page), events);
  return true;
}

std::optional<uint32_t> PageCache::map(const PageId& page, std::optional<PageId> parent,
                                       uint64_t frame, std::vector<CacheEvent>& events) {
  if (resident(page)) return std::nullopt;
  std::optional<uint32_t> parent_slot;
  if (parent) {
    parent_slot = slot_of(*parent);
    if (!parent_slot) return std::nullopt;  // the chain rule: parent first
  }
  if (free_.empty()) {
    // Oldest first; parents (children > 0) and pages in use this frame are skipped. Parents
    // are touched with their children, so they sit just before them in the list.
    uint32_t victim = kNone;
    for (uint32_t s = lru_head_; s != kNone; s = slots_[s].next) {
      const SlotInfo& info = slots_[s];
      if (info.last_used >= frame) break;  // the rest of the list is younger still
      if (info.children == 0 && s != parent_slot) {
        victim = s;
        break;
      }
    }
    if (victim == kNone) return std::nullopt;
    release(victim, events);
  }
  const uint32_t s = free_.back();
  free_.pop_back();
  SlotInfo& info = slots_[s];
  info.page = page;
  info.parent = parent;
  info.last_used = frame;
  info.used = true;
  info.pinned = !parent;
  info.children = 0;
  if (!info.pinned) lru_push_back(s);
  if (parent_slot) ++slots_[*parent_slot].children;
  index_.emplace(key(page), s);
  events.push_back({CacheEvent::Kind::kMap, page, s});
  return s;
}

std::vector<PageId> PageCache::resident_pages() const {
  std::vector<PageId> out;
  for (const SlotInfo& info : slots_)
    if (info.used) out.push_back(info.page);
  return out;
}

}  // namespace vt
