// The resolver's hot loop reads the buffer once and counts runs of equal values (a feedback
// buffer is mostly long runs); each run costs one probe into a flat open-addressing table keyed
// by the value. Only the few thousand distinct values then go through validation, the LOD
// bias, the presence map and the ancestor chain, into a second flat table keyed by page index.
#include <algorithm>

#include "runtime/feedback.h"

namespace vt {

namespace {

struct Slot {
  uint32_t key = 0;  // value + 1; 0 = empty
  uint32_t count = 0;
};

inline uint32_t hash32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

// Flat hash map uint32 -> count with insertion-order list, cleared in O(used).
class CountTable {
 public:
  CountTable() { slots_.resize(1024); }
  void clear() {
    // Emptying a slot breaks the probe chains through it, so find every slot first.
    if (keys_.size() * 8 >= slots_.size()) {
      std::fill(slots_.begin(), slots_.end(), Slot{});
    } else {
      found_.clear();
      for (uint32_t k : keys_) found_.push_back(find(k));
      for (uint32_t i : found_) slots_[i] = {};
    }
    keys_.clear();
  }
  void add(uint32_t key, uint32_t count) {
    if ((keys_.size() + 1) * 2 > slots_.size()) grow();
    uint32_t i = find(key);
    if (slots_[i].key == 0) {
      slots_[i].key = key + 1;
      keys_.push_back(key);
    }
    slots_[i].count += count;
  }
  uint32_t count(uint32_t key) const { return slots_[find(key)].count; }
  const std::vector<uint32_t>& keys() const { return keys_; }

 private:
  uint32_t find(uint32_t key) const {
    const uint32_t mask = uint32_t(slots_.size() - 1);
    uint32_t i = hash32(key) & mask;
    while (slots_[i].key != 0 && slots_[i].key != key + 1) i = (i + 1) & mask;
    return i;
  }
  void grow() {
    std::vector<Slot> old;
    old.swap(slots_);
    slots_.assign(old.size() * 2, {});
    for (const Slot& s : old)
      if (s.key != 0) slots_[find(s.key - 1)] = s;
  }
  std::vector<Slot> slots_;
  std::vector<uint32_t> keys_;
  std::vector<uint32_t> found_;
};

}  // namespace

struct FeedbackResolver::Impl {
  const PageSource& source;
  PageGeometry geometry;
  uint32_t levels = 0;
  std::vector<uint32_t> level_base;
  CountTable values;
  CountTable pages;

  explicit Impl(const PageSource& s) : source(s), geometry(s.geometry()) {
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
  PageId from_key(uint32_t k) const {
    uint32_t l =
        uint32_t(std::upper_bound(level_base.begin(), level_base.end(), k) - level_base.begin()) -
        1;
    const uint32_t i = k - level_base[l];
    const uint32_t w = geometry.pages_x(l);
    return PageId{l, i % w, i / w};
  }
  PageId nearest_present(PageId id) const {
    while (id.level + 1 < levels && !source.present(id)) {
      id = PageId{id.level + 1, id.x / 2, id.y / 2};
    }
    if (id.level + 1 >= levels) id = PageId{levels - 1, 0, 0};
    return id;
  }
};

FeedbackResolver::FeedbackResolver(const PageSource& source)
    : impl_(std::make_unique<Impl>(source)) {}
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
  if (m.levels == 0) return stats;

  const size_t n = feedback.size();
  size_t i = 0;
  while (i < n) {
    const uint32_t v = feedback[i];
    size_t j = i + 1;
    while (j < n && feedback[j] == v) ++j;
    if (v != kFeedbackNone) m.values.add(v, uint32_t(std::min<size_t>(j - i, UINT32_MAX)));
    i = j;
  }
  stats.unique_values = uint32_t(m.values.keys().size());

  const uint32_t last = m.levels - 1;
  for (uint32_t v : m.values.keys()) {
    const uint32_t count = m.values.count(v);
    stats.pixels += count;
    const PageId req = feedback_unpack(v);
    if ((v >> 29) != 0 || !m.geometry.contains(req)) {
      stats.invalid_pixels += count;
      continue;
    }
    const uint32_t level = std::min(req.level + std::min(lod_bias, last), last);
    const uint32_t shift = level - req.level;
    PageId id = m.nearest_present(PageId{level, req.x >> shift, req.y >> shift});
    // The page and its present ancestors; every one gets the pixels of its descendants.
    for (;;) {
      m.pages.add(m.key(id), count);
      if (id.level >= last) break;
      id = m.nearest_present(PageId{id.level + 1, id.x / 2, id.y / 2});
    }
  }

  out.reserve(m.pages.keys().size());
  for (uint32_t k : m.pages.keys()) out.push_back({m.from_key(k), m.pages.count(k)});
  std::sort(out.begin(), out.end(), [](const PageRequest& a, const PageRequest& b) {
    if (a.id.level != b.id.level) return a.id.level > b.id.level;
    if (a.pixels != b.pixels) return a.pixels > b.pixels;
    if (a.id.y != b.id.y) return a.id.y < b.id.y;
    return a.id.x < b.id.x;
  });
  return stats;
}

}  // namespace vt
