// The resolver's hot loop reads the buffer once and counts runs of equal values (a feedback
// buffer is mostly long runs); each run costs one probe into a flat open-addressing table keyed
// by the value. Only the few thousand distinct values then go through validation, the LOD
// bias, the presence map and the ancestor chain, into a second flat table keyed by page index.
#include <algorithm>
#include <array>
#include <bit>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "common/hash.h"
#include "runtime/feedback.h"
#include "runtime/page_index.h"

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

// Calls f(value, length) for each run of equal values in p[0, n), in order. Runs end where a
// value differs from the one before it, found four positions a compare: the scan carries no
// dependency from one run to the next, so short runs (a view of many small charts) cost little
// more than long ones.
template <class F>
void for_each_run(const uint32_t* p, size_t n, F&& f) {
  if (n == 0) return;
  size_t start = 0, k = 1;
#if defined(__SSE2__)
  for (; k + 4 <= n; k += 4) {
    const __m128i here = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + k));
    const __m128i before = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + k - 1));
    unsigned ends =
        ~unsigned(_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(here, before)))) & 0xFu;
    for (; ends != 0; ends &= ends - 1) {
      const size_t end = k + size_t(std::countr_zero(ends));
      f(p[start], end - start);
      start = end;
    }
  }
#endif
  for (; k < n; ++k) {
    if (p[k] != p[k - 1]) {
      f(p[start], k - start);
      start = k;
    }
  }
  f(p[start], n - start);
}

// Sorts keys ascending: least significant byte first, each pass a stable counting sort, passes
// skipped where every key has the same byte. Thousands of keys cost a few passes over them,
// where std::sort's comparisons cost several times that.
void radix_sort(std::vector<uint64_t>& keys, std::vector<uint64_t>& scratch) {
  if (keys.size() < 2) return;
  std::array<std::array<uint32_t, 256>, 8> counts{};
  for (const uint64_t k : keys)
    for (int d = 0; d < 8; ++d) ++counts[d][(k >> (8 * d)) & 0xFF];
  scratch.resize(keys.size());
  for (int d = 0; d < 8; ++d) {
    auto& c = counts[d];
    if (c[(keys[0] >> (8 * d)) & 0xFF] == keys.size()) continue;
    uint32_t sum = 0;
    for (uint32_t& n : c) sum += std::exchange(n, sum);
    for (const uint64_t k : keys) scratch[c[(k >> (8 * d)) & 0xFF]++] = k;
    keys.swap(scratch);
  }
}

}  // namespace

struct FeedbackResolver::Impl {
  const PageSource& source;
  uint32_t texture_id = 0;
  PageIndex index;  // a page's key in `pages` is its number (under 2^32 within the limits)
  CountTable values;
  CountTable pages;
  struct Recent {
    uint32_t key = 0;  // value + 1; 0 = empty
    uint32_t index = 0;
  };
  // A row of a view of many small charts holds a hundred or more distinct values: 2,048 entries
  // (16 KiB, in L1) keep their collisions, each a probe into `values` every row, rare.
  std::array<Recent, 2048> recent;
  std::vector<std::vector<std::pair<PageId, uint32_t>>> buckets;  // per level: page, entry
  std::vector<uint64_t> order, order_scratch;                     // sort keys, see resolve()

  Impl(const PageSource& s, uint32_t texture)
      : source(s), texture_id(texture), index(s.geometry()) {}
  uint32_t key(const PageId& id) const { return uint32_t(index.number(id)); }
  PageId nearest_present(PageId id) const {
    const uint32_t levels = index.levels();
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
  if (m.index.levels() == 0) return stats;

  for_each_run(feedback.data(), feedback.size(), [&m](uint32_t v, size_t length) {
    if (v == kFeedbackNone) return;
    const uint32_t run = uint32_t(std::min<size_t>(length, UINT32_MAX));
    // Feedback is row-coherent: the values of one row mostly recur in the next rows, so a
    // small direct-mapped cache in L1 answers most runs without probing the big table.
    auto& r = m.recent[(v * 0x9E3779B1u) >> 21];
    if (r.key == v + 1) {
      m.values.add_at(r.index, run);
    } else {
      r = {v + 1, m.values.add(v, run).first};
    }
  });
  stats.unique_values = uint32_t(m.values.size());

  // Each distinct request lands on its nearest present page; then counts flow up one level at
  // a time (a parent collects its children's pixels), so each page is visited once instead of
  // once per descendant request.
  const uint32_t last = m.index.levels() - 1;
  for (auto& b : m.buckets) b.clear();
  m.buckets.resize(m.index.levels());
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
    if (texture != m.texture_id || !m.index.contains(req)) {
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

  // The priority order as one integer per page: level descending, pixels descending, then y
  // and x (5 + 32 + 12 + 12 bits), so the sort compares integers, not four fields.
  m.order.clear();
  for (const auto& bucket : m.buckets) {
    for (const auto& [id, index] : bucket) {
      m.order.push_back(uint64_t(kFeedbackMaxLevels - 1 - id.level) << 56 |
                        uint64_t(~m.pages.count(index)) << 24 | uint64_t(id.y) << 12 | id.x);
    }
  }
  radix_sort(m.order, m.order_scratch);
  out.resize(m.order.size());
  for (size_t k = 0; k < m.order.size(); ++k) {
    const uint64_t o = m.order[k];
    out[k] = {PageId{kFeedbackMaxLevels - 1 - uint32_t(o >> 56), uint32_t(o & 0xFFF),
                     uint32_t(o >> 12 & 0xFFF)},
              ~uint32_t(o >> 24)};
  }
  return stats;
}

}  // namespace vt
