// One mutex serialises the streamer's state (cache, table, ready pages, uploads); the loader
// has its own lock and its workers never touch the streamer, so update() never waits for a
// page to be read or decoded.
#include "runtime/streamer.h"

#include <algorithm>
#include <map>
#include <mutex>
#include <unordered_map>
#include <unordered_set>

namespace vt {

struct Streamer::Impl {
  std::shared_ptr<const PageSource> source;
  StreamerOptions options;
  PageGeometry geometry;
  uint32_t last_level = 0;
  uint64_t slot_bytes = 0;
  PageCache cache;
  PageTable table;
  FeedbackResolver resolver;
  std::unique_ptr<PageLoader> loader;

  mutable std::mutex mutex;
  uint64_t frame = 0;
  uint32_t lod_bias = 0;
  uint32_t calm_frames = 0;
  std::vector<PageRequest> needed;
  std::vector<PageRequest> scratch;
  std::unordered_set<uint64_t> needed_keys;
  std::unordered_map<uint64_t, LoadPriority> requested;  // handed to the loader, not collected
  std::map<uint64_t, PageRequest> explicit_requests;     // request() calls not yet mapped
  std::vector<LoadedPage> ready;                         // collected, waiting for a slot/parent
  std::unordered_set<uint64_t> ready_keys;
  // Pages whose load failed (corrupt or unreadable): not retried, their parent stands in.
  std::unordered_set<uint64_t> failed;
  std::vector<PageUpload> uploads;
  std::vector<CacheEvent> events;

  Impl(std::shared_ptr<const PageSource> s, const StreamerOptions& o, uint32_t slots)
      : source(std::move(s)),
        options(o),
        geometry(source->geometry()),
        last_level(geometry.level_count() - 1),
        slot_bytes(vt::slot_bytes(*source)),
        cache(geometry, slots),
        table(geometry),
        resolver(*source, o.texture_id) {}

  PageId root() const { return PageId{last_level, 0, 0}; }

  // Nearest present ancestor (the root counts as present); nullopt for the root itself.
  std::optional<PageId> parent_of(const PageId& id) const {
    if (id.level >= last_level) return std::nullopt;
    return resolver.nearest_present(PageId{id.level + 1, id.x / 2, id.y / 2});
  }

  uint32_t staging_pages() const {
    return loader->in_flight() + uint32_t(ready.size()) + uint32_t(uploads.size());
  }

  void apply_events() {
    for (const CacheEvent& e : events) {
      if (e.kind == CacheEvent::Kind::kUnmap)
        table.unmap(e.page);
      else
        table.map(e.page, e.slot % options.slots_x, e.slot / options.slots_x);
    }
    events.clear();
  }

  bool map_page(LoadedPage& page, uint64_t f, FrameStats& stats) {
    auto slot = cache.map(page.id, parent_of(page.id), f, events);
    for (const CacheEvent& e : events) stats.evicted += e.kind == CacheEvent::Kind::kUnmap;
    apply_events();
    if (!slot) return false;
    PageUpload up;
    up.page = page.id;
    up.slot_x = *slot % options.slots_x;
    up.slot_y = *slot / options.slots_x;
    up.layers = std::move(page.layers);
    uploads.push_back(std::move(up));
    explicit_requests.erase(page_key(page.id));
    ++stats.mapped;
    return true;
  }

  // Maps collected pages whose parent is resident, coarse first, within the byte limit. A
  // page whose parent is still loading waits; one that finds no slot is dropped (thrashing).
  void map_ready(FrameStats& stats) {
    std::stable_sort(ready.begin(), ready.end(), [](const LoadedPage& a, const LoadedPage& b) {
      return a.id.level > b.id.level;
    });
    uint64_t bytes = 0;
    bool progress = true;
    while (progress && !ready.empty()) {
      progress = false;
      for (size_t i = 0; i < ready.size();) {
        LoadedPage& page = ready[i];
        const auto parent = parent_of(page.id);
        const bool wanted =
            needed_keys.count(page_key(page.id)) || explicit_requests.count(page_key(page.id));
        if (!page.status.ok() || cache.resident(page.id) || !wanted) {
          stats.load_errors += !page.status.ok();
          stats.dropped += !page.status.ok();
          // A failed prefetch is not retried forever; feedback may ask again.
          if (!page.status.ok()) {
            explicit_requests.erase(page_key(page.id));
            failed.insert(page_key(page.id));
          }
          erase_ready(i);
          continue;
        }
        if (parent && !cache.resident(*parent)) {
          // The parent is not coming (cancelled, dropped): let this one go too.
          if (!requested.count(page_key(*parent)) && !has_ready(*parent)) {
            erase_ready(i);
            ++stats.dropped;
            continue;
          }
          ++i;
          continue;
        }
        if (bytes > 0 && bytes + slot_bytes > options.upload_byte_limit) return;
        if (!map_page(page, frame, stats)) {
          stats.thrashing = true;
          ++stats.dropped;
        } else {
          bytes += slot_bytes;
          progress = true;
        }
        erase_ready(i);
      }
    }
  }

  bool has_ready(const PageId& id) const { return ready_keys.count(page_key(id)) != 0; }
  void erase_ready(size_t i) {
    ready_keys.erase(page_key(ready[i].id));
    ready.erase(ready.begin() + std::ptrdiff_t(i));
  }

  void queue_loads(const std::vector<PageRequest>& list, FrameStats& stats) {
    for (const PageRequest& r : list) {
      if (cache.resident(r.id)) continue;
      const uint64_t k = page_key(r.id);
      const LoadPriority prio{r.id.level, r.pixels};
      if (auto it = requested.find(k); it != requested.end()) {
        loader->reprioritise(r.id, prio);
        continue;
      }
      if (has_ready(r.id) || failed.count(k)) continue;
      if (staging_pages() >= options.max_in_flight) break;
      if (loader->request(r.id, prio)) {
        requested.emplace(k, prio);
        ++stats.queued;
      }
    }
  }

  void collect() {
    const size_t before = ready.size();
    loader->collect(ready);
    for (size_t i = before; i < ready.size(); ++i) {
      requested.erase(page_key(ready[i].id));
      ready_keys.insert(page_key(ready[i].id));
    }
  }

  // Whether the frame's working set one level finer would fill at most 3/4 of the cache (the
  // margin keeps the bias from flipping back and forth at the boundary).
  bool finer_fits(std::span<const uint32_t> feedback) {
    resolver.resolve(feedback, lod_bias - 1, scratch);
    return uint64_t(scratch.size()) * 4 <= uint64_t(cache.capacity()) * 3;
  }

  FrameStats update(std::span<const uint32_t> feedback) {
    FrameStats stats;
    ++frame;
    stats.frame = frame;
    const ResolveStats rs = resolver.resolve(feedback, lod_bias, needed);
    stats.invalid_pixels = rs.invalid_pixels;
    stats.other_texture_pixels = rs.other_texture_pixels;
    stats.needed = uint32_t(needed.size());
    needed_keys.clear();
    for (const PageRequest& r : needed) needed_keys.insert(page_key(r.id));
    for (const auto& [k, r] : explicit_requests) needed_keys.insert(k);

    for (const PageRequest& r : needed) {
      if (cache.resident(r.id)) {
        cache.touch(r.id, frame);
        ++stats.resident_hits;
      }
    }
    for (const auto& [k, r] : explicit_requests) cache.touch(r.id, frame);

    // Cancel loads nobody asks for any more.
    for (auto it = requested.begin(); it != requested.end();) {
      if (!needed_keys.count(it->first)) {
        const uint64_t k = it->first;
        PageId id{uint32_t(k >> 48), uint32_t(k & 0xFFFFFF), uint32_t((k >> 24) & 0xFFFFFF)};
        loader->cancel(id);
        it = requested.erase(it);
        ++stats.cancelled;
      } else {
        ++it;
      }
    }

    collect();
    map_ready(stats);
    queue_loads(needed, stats);
    std::vector<PageRequest> extra;
    for (const auto& [k, r] : explicit_requests) extra.push_back(r);
    queue_loads(extra, stats);

    // Thrash control: one level coarser per frame while the set does not fit; one finer after
    // a calm stretch in which the set at the next finer level would fit with a margin.
    const uint32_t cap = cache.capacity();
    const uint32_t max_bias = std::min(options.max_lod_bias, last_level);
    if (stats.needed > cap || stats.thrashing) {
      stats.thrashing = true;
      calm_frames = 0;
      if (lod_bias < max_bias) ++lod_bias;
    } else if (lod_bias > 0 && finer_fits(feedback)) {
      if (++calm_frames >= options.frames_before_lowering) {
        --lod_bias;
        calm_frames = 0;
      }
    } else {
      calm_frames = 0;
    }
    stats.lod_bias = lod_bias;
    stats.resident_bytes = uint64_t(cache.resident_count()) * slot_bytes;
    return stats;
  }
};

Streamer::Streamer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Streamer::~Streamer() = default;

Expected<std::unique_ptr<Streamer>> Streamer::create(std::shared_ptr<const PageSource> source,
                                                     const StreamerOptions& options) {
  if (!source) return Error(ErrorCode::kInvalidArgument, "streamer: no page source");
  const PageGeometry& g = source->geometry();
  VT_RETURN_IF_ERROR(g.validate().with_context("streamer"));
  if (g.pages_x(0) > kFeedbackMaxPages || g.pages_y(0) > kFeedbackMaxPages ||
      g.level_count() > kFeedbackMaxLevels)
    return Error(ErrorCode::kUnsupported,
                 "streamer: more than 4096 x 4096 pages at level 0 (the feedback format's limit)");
  if (source->layer_count() == 0) return Error(ErrorCode::kInvalidArgument, "streamer: no layers");
  if (options.slots_x == 0 || options.slots_y == 0 || options.slots_x > 256 ||
      options.slots_y > 256)
    return Error(ErrorCode::kInvalidArgument, "streamer: slots_x and slots_y must be 1..256");
  if (options.max_in_flight == 0)
    return Error(ErrorCode::kInvalidArgument, "streamer: max_in_flight must be >= 1");
  const uint64_t per_slot = slot_bytes(*source);
  if (per_slot == 0) return Error(ErrorCode::kInvalidArgument, "streamer: empty slots");
  uint64_t slots = uint64_t(options.slots_x) * options.slots_y;
  if (options.memory_budget_bytes != 0) {
    const uint64_t staging = uint64_t(options.max_in_flight) * per_slot;
    if (options.memory_budget_bytes < staging + per_slot)
      return Error(ErrorCode::kResourceLimit,
                   "streamer: memory budget of " + std::to_string(options.memory_budget_bytes) +
                       " bytes holds neither the staging of " +
                       std::to_string(options.max_in_flight) + " pages nor one slot of " +
                       std::to_string(per_slot) + " bytes");
    slots = std::min(slots, (options.memory_budget_bytes - staging) / per_slot);
  }
  if (options.texture_id >= kFeedbackMaxTextures)
    return Error(ErrorCode::kInvalidArgument,
                 "streamer: texture_id must be 0.." + std::to_string(kFeedbackMaxTextures - 1));
  LoaderOptions lo;
  lo.threads = options.threads;
  lo.max_in_flight = options.max_in_flight;
  lo.jobs = options.jobs;
  lo.allocator = options.allocator;
  auto loader = PageLoader::create(source, lo);
  if (!loader.ok()) return loader.status().with_context("streamer");

  auto impl = std::make_unique<Impl>(source, options, uint32_t(slots));
  impl->loader = std::move(loader).value();

  // The root is pinned and loaded here, so the table is valid from the first frame on.
  LoadedPage root;
  root.id = impl->root();
  for (uint32_t l = 0; l < source->layer_count(); ++l) {
    root.layers.emplace_back(source->upload_bytes(l), options.allocator);
    if (root.layers[l].size() != source->upload_bytes(l))
      return Error(ErrorCode::kResourceLimit, "streamer: the allocator returned no memory");
    if (source->present(root.id)) {
      Status s = source->load(root.id, l, root.layers[l]);
      if (!s.ok()) return s.with_context("streamer: " + page_name(root.id));
    }
  }
  FrameStats unused;
  if (!impl->map_page(root, 0, unused))
    return Error(ErrorCode::kInternal, "streamer: could not map the root page");
  return std::unique_ptr<Streamer>(new Streamer(std::move(impl)));
}

FrameStats Streamer::update(std::span<const uint32_t> feedback) {
  std::lock_guard lock(impl_->mutex);
  return impl_->update(feedback);
}

void Streamer::request(const PageId& id) {
  std::lock_guard lock(impl_->mutex);
  Impl& m = *impl_;
  if (!m.geometry.contains(id)) return;
  PageId p = m.resolver.nearest_present(id);
  for (;;) {
    const uint64_t k = page_key(p);
    if (!m.cache.resident(p)) {
      auto [it, inserted] = m.explicit_requests.emplace(k, PageRequest{p, 1});
      if (!inserted) ++it->second.pixels;
    } else {
      m.cache.touch(p, m.frame);
    }
    auto parent = m.parent_of(p);
    if (!parent) break;
    p = *parent;
  }
  FrameStats unused;
  std::vector<PageRequest> list;
  for (const auto& [k, r] : m.explicit_requests) list.push_back(r);
  std::sort(list.begin(), list.end(),
            [](const PageRequest& a, const PageRequest& b) { return a.id.level > b.id.level; });
  m.queue_loads(list, unused);
}

bool Streamer::evict(const PageId& id) {
  std::lock_guard lock(impl_->mutex);
  Impl& m = *impl_;
  if (!m.cache.unmap(id, m.events)) return false;
  m.apply_events();
  // A pending upload of that page must not reach the GPU after its slot is reused.
  std::erase_if(m.uploads, [&](const PageUpload& u) { return u.page == id; });
  return true;
}

std::vector<PageUpload> Streamer::take_uploads() {
  std::lock_guard lock(impl_->mutex);
  std::vector<PageUpload> out;
  out.swap(impl_->uploads);
  return out;
}

PageTable Streamer::page_table() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->table;
}

void Streamer::with_page_table(const std::function<void(const PageTable&)>& fn) const {
  std::lock_guard lock(impl_->mutex);
  fn(impl_->table);
}

void Streamer::clear_table_dirty() {
  std::lock_guard lock(impl_->mutex);
  impl_->table.clear_dirty();
}

uint32_t Streamer::lod_bias() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->lod_bias;
}

bool Streamer::idle() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->requested.empty() && impl_->ready.empty() && impl_->loader->in_flight() == 0;
}

void Streamer::wait_idle() {
  impl_->loader->wait_idle();
}

uint32_t Streamer::capacity() const {
  return impl_->cache.capacity();
}

uint64_t Streamer::memory_bytes() const {
  std::lock_guard lock(impl_->mutex);
  const Impl& m = *impl_;
  return (uint64_t(m.cache.resident_count()) + m.staging_pages()) * m.slot_bytes;
}

uint64_t Streamer::memory_budget() const {
  return impl_->options.memory_budget_bytes;
}

std::vector<PageId> Streamer::resident_pages() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->cache.resident_pages();
}

const PageSource& Streamer::source() const {
  return *impl_->source;
}
uint32_t Streamer::slots_x() const {
  return impl_->options.slots_x;
}
uint32_t Streamer::slots_y() const {
  return impl_->options.slots_y;
}

Status Streamer::check_invariants() const {
  std::lock_guard lock(impl_->mutex);
  const Impl& m = *impl_;
  const PageGeometry& g = m.geometry;
  if (m.cache.resident_count() > m.cache.capacity())
    return Error(ErrorCode::kInternal, "more resident pages than slots");
  const uint64_t bytes = (uint64_t(m.cache.resident_count()) + m.staging_pages()) * m.slot_bytes;
  if (m.options.memory_budget_bytes != 0 && bytes > m.options.memory_budget_bytes)
    return Error(ErrorCode::kInternal, "memory budget exceeded: " + std::to_string(bytes));
  for (const PageId& p : m.cache.resident_pages()) {
    auto parent = m.parent_of(p);
    if (parent && !m.cache.resident(*parent))
      return Error(ErrorCode::kInternal, page_name(p) + " is resident without its parent");
    if (!m.source->present(p) && p.level != m.last_level)
      return Error(ErrorCode::kInternal, page_name(p) + " is resident but absent from the source");
  }
  for (uint32_t l = 0; l < g.level_count(); ++l)
    for (uint32_t y = 0; y < g.pages_y(l); ++y)
      for (uint32_t x = 0; x < g.pages_x(l); ++x) {
        const PageId v{l, x, y};
        const PageTableEntry e = m.table.entry(v);
        // Expected: the nearest resident page at or above v.
        PageId want = v;
        while (!m.cache.resident(want) && want.level < m.last_level)
          want = PageId{want.level + 1, want.x / 2, want.y / 2};
        auto slot = m.cache.slot_of(want);
        if (!slot) {
          if (e.valid()) return Error(ErrorCode::kInternal, "valid entry with no resident page");
          continue;
        }
        const PageTableEntry expect{uint8_t(*slot % m.options.slots_x),
                                    uint8_t(*slot / m.options.slots_x), uint8_t(want.level),
                                    kPageTableValid};
        if (!(e == expect))
          return Error(ErrorCode::kInternal, "page table entry of " + page_name(v) +
                                                 " does not point at " + page_name(want));
      }
  return Status::Ok();
}

}  // namespace vt
