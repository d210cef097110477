// The resolver's hot loop reads the buffer once and counts runs of equal values (a feedback
// buffer is mostly long runs); each run costs one probe into a flat open-addressing table keyed
// by the value. Only the few thousand distinct values then go through validation, the LOD
// bias, the presence map and the ancestor chain, into a second flat table keyed by page index.
#include <algorithm>
#include <array>
#include <utility>

#include "common/hash.h"
#include "runtime/feedback.h"

namespace vt {

namespace {

// Flat open-addressing map uint32 -> count. A slot holds key + 1 (0 = empty) and the index of
// the entry in dense arrays (keys, counts, slots), so iterating and clearing cost O(entries)
// and counting into a known entry touches only the small dense count array.
class CountTable {
 public:
  CountTable() { slots_.resize(1024); }
  void clear() {
    // By recorded slot: emptying slots while looking keys up would cut probe chains.
    for (uint32_t i : entry_slot_) slots_[i] = {};
    keys_.clear();
    counts_.clear();
    entry_slot_.clear();
  }
  // Adds `count` to `key`; returns the entry's dense index and whether it is new.
  std::pair<uint32_t, bool> add(uint32_t key, uint32_t count) {
    uint32_t i = find(key);
    if (slots_[i].key != 0) {
      counts_[slots_[i].index] += count;
      return {slots_[i].index, false};
    }
    if ((keys_.size() + 1) * 2 > slots_.size()) {
      grow();
      i = find(key);
    }
    const uint32_t index = uint32_t(keys_.size());
    slots_[i] = {key + 1, index};
    keys_.push_back(key);
    counts_.push_back(count);
    entry_slot_.push_back(i);
    return {index, true};
  }
  void add_at(uint32_t index, uint32_t count) { counts_[index] += count; }
  size_t size() const { return keys_.size(); }
  uint32_t key(uint32_t index) const { return keys_[index]; }
  uint32_t count(uint32_t index) const { return counts_[index]; }

 private:
  struct Slot {
    uint32_t key = 0;
    uint32_t index = 0;
  };
  uint32_t find(uint32_t key) const {
    const uint32_t mask = uint32_t(slots_.size() - 1);
    uint32_t i = hash32(key) & mask;
    while (slots_[i].key != 0 && slots_[i].key != key + 1) i = (i + 1) & mask;
    return i;
  }
  void grow() {
    slots_.assign(slots_.size() * 2, {});
    for (uint32_t e = 0; e < keys_.size(); ++e) {
      const uint32_t i = find(keys_[e]);
      slots_[i] = {keys_[e] + 1, e};
      entry_slot_[e] = i;
    }
  }
  std::vector<Slot> slots_;
  std::vector<uint32_t> keys_;
  std::vector<uint32_t> counts_;
  std::vector<uint32_t> entry_slot_;
};

}  // namespace

struct FeedbackResolver::Impl {
  const PageSource& source;
  uint32_t texture_id = 0;
  PageGeometry geometry;
  uint32_t levels = 0;
  std::vector<uint32_t> level_base;
  CountTable values;
  CountTable pages;
  struct Recent {
    uint32_t key = 0;  // value + 1; 0 = empty
    uint32_t index = 0;
  };
  std::array<Recent, 256> recent;
  std::vector<std::vector<std::pair<PageId, uint32_t>>> buckets;  // per level: page, entry

  Impl(const PageSource& s, uint32_t texture)
      : source(s), texture_id(texture), geometry(s.geometry()) {
    levels = geometry.level_count();
    uint64_t base = 0;
    for (uint32_t l = 0; l < levels; ++l) {
      level_base.push_back(uint32_t(base));
      base += geometry.pages_in_level(l);
    }
  }
  uint32_t key(const PageId& id) const {
    return level_base[id.level] + id.y * geometry.pages_x(id.level) + id.x;
  }
  PageId nearest_present(PageId id) const {
    while (id.level + 1 < levels && !source.present(id)) {
      id = PageId{id.level + 1, id.x / 2, id.y / 2};
    }
    if (id.level + 1 >= levels) id = PageId{levels - 1, 0, 0};
    return id;
  }
};

FeedbackResolver::FeedbackResolver(const PageSource& source, uint32_t texture_id)
    : impl_(std::make_unique<Impl>(source, texture_id)) {}
FeedbackResolver::~FeedbackResolver() = default;
FeedbackResolver::FeedbackResolver(FeedbackResolver&&) noexcept = default;
FeedbackResolver& FeedbackResolver::operator=(FeedbackResolver&&) noexcept = default;

PageId FeedbackResolver::nearest_present(PageId id) const {
  return impl_->nearest_present(id);
}

ResolveStats FeedbackResolver::resolve(std::span<const uint32_t> feedback, uint32_t lod_bias,
                                       std::vector<PageRequest>& out) {
  Impl& m = *impl_;
  ResolveStats stats;
  out.clear();
  m.values.clear();
  m.pages.clear();
  m.recent.fill({});
  if (m.levels == 0) return stats;

  const size_t n = feedback.size();
  size_t i = 0;
  while (i < n) {
    const uint32_t v = feedback[i];
    size_t j = i + 1;
    while (j < n && feedback[j] == v) ++j;
    if (v != kFeedbackNone) {
      const uint32_t run = uint32_t(std::min<size_t>(j - i, UINT32_MAX));
      // Feedback is row-coherent: the values of one row mostly recur in the next rows, so a
      // tiny direct-mapped cache in L1 answers most runs without probing the big table.
      auto& r = m.recent[(v * 0x9E3779B1u) >> 24];
      if (r.key == v + 1) {
        m.values.add_at(r.index, run);
      } else {
        r = {v + 1, m.values.add(v, run).first};
      }
    }
    i = j;
  }
  stats.unique_values = uint32_t(m.values.size());

  // Each distinct request lands on its nearest present page; then counts flow up one level at
  // a time (a parent collects its children's pixels), so each page is visited once instead of
  // once per descendant request.
  const uint32_t last = m.levels - 1;
  for (auto& b : m.buckets) b.clear();
  m.buckets.resize(m.levels);
  for (uint32_t e = 0; e < m.values.size(); ++e) {
    const uint32_t v = m.values.key(e);
    const uint32_t count = m.values.count(e);
    const uint32_t texture = feedback_texture(v);
    if (texture != m.texture_id && texture < kFeedbackMaxTextures) {
      stats.other_texture_pixels += count;
      continue;
    }
    stats.pixels += count;
    const PageId req = feedback_unpack(v);
    if (texture != m.texture_id || !m.geometry.contains(req)) {
      stats.invalid_pixels += count;
      continue;
    }
    const uint32_t level = std::min(req.level + std::min(lod_bias, last), last);
    const uint32_t shift = level - req.level;
    const PageId id = m.nearest_present(PageId{level, req.x >> shift, req.y >> shift});
    auto [index, inserted] = m.pages.add(m.key(id), count);
    if (inserted) m.buckets[id.level].push_back({id, index});
  }
  for (uint32_t l = 0; l < last; ++l) {
    for (const auto& [id, index] : m.buckets[l]) {
      const PageId parent = m.nearest_present(PageId{l + 1, id.x / 2, id.y / 2});
      auto [pi, inserted] = m.pages.add(m.key(parent), m.pages.count(index));
      if (inserted) m.buckets[parent.level].push_back({parent, pi});
    }
  }

  out.reserve(m.pages.size());
  for (const auto& bucket : m.buckets)
    for (const auto& [id, index] : bucket) out.push_back({id, m.pages.count(index)});
  std::sort(out.begin(), out.end(), [](const PageRequest& a, const PageRequest& b) {
    if (a.id.level != b.id.level) return a.id.level > b.id.level;
    if (a.pixels != b.pixels) return a.pixels > b.pixels;
    if (a.id.y != b.id.y) return a.id.y < b.id.y;
    return a.id.x < b.id.x;
  });
  return stats;
}

}  // namespace vt
