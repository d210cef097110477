// The C API over Streamer: a thin layer that turns Status into codes and messages
// (format/c_api_internal.h) and keeps the caller's copy of the page table.
#include "runtime/vt_runtime_c.h"

#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "format/c_api_internal.h"
#include "runtime/page_source.h"
#include "runtime/streamer.h"

struct vtrt_streamer {
  std::shared_ptr<const vt::PageSource> source;
  std::unique_ptr<vt::Streamer> streamer;
  mutable std::mutex mutex;  // guards the fields below (the streamer locks itself)
  std::vector<vt::PageUpload> uploads;
  // The caller's view of the page table, refreshed by dirty rectangles at each update.
  std::vector<std::vector<uint8_t>> table;
  std::vector<uint32_t> table_w, table_h;
  std::vector<vt::TableRect> dirty;
};

using vt::c_api::fail;
using vt::c_api::fail_null;
using vt::c_api::guard;

namespace {

int out_of_range(const char* what) {
  return fail(vt::Error(vt::ErrorCode::kInvalidArgument, std::string(what) + " out of range"));
}

// vtrt_options mirrors StreamerOptions field by field: one list of the shared fields serves both
// directions.
template <typename From, typename To>
void copy_streamer_fields(const From& from, To& to) {
  to.slots_x = from.slots_x;
  to.slots_y = from.slots_y;
  to.memory_budget_bytes = from.memory_budget_bytes;
  to.threads = from.threads;
  to.max_in_flight = from.max_in_flight;
  to.upload_byte_limit = from.upload_byte_limit;
  to.max_lod_bias = from.max_lod_bias;
}

vt::StreamerOptions streamer_options(const vtrt_options& o) {
  vt::StreamerOptions so;
  copy_streamer_fields(o, so);
  return so;
}

}  // namespace

namespace {

// The streamer over an open reader, into *out (every vtrt_open form).
int open_streamer(std::shared_ptr<const vt::PageFileReader> reader, const vtrt_open_info& info,
                  vtrt_streamer** out) {
  vtrt_options o;
  vtrt_default_options(&o);
  if (info.options) o = *info.options;
  const std::string reader_name = reader->path();
  vt::Allocator allocator;
  if (info.allocator)
    allocator = {info.allocator->allocate, info.allocator->release, info.allocator->user};
  vt::PageFileSourceOptions so;
  so.bc7_as_rgba8 = o.bc7_as_rgba8 != 0;
  so.allocator = allocator;
  auto source = vt::make_page_file_source(std::move(reader), so);
  if (!source.ok()) return fail(source.status().with_context(reader_name));
  std::shared_ptr<const vt::PageSource> shared(std::move(source).value());
  vt::StreamerOptions sto = streamer_options(o);
  sto.texture_id = info.texture_id;
  sto.allocator = allocator;
  if (info.jobs) sto.jobs = {info.jobs->submit, info.jobs->user};
  auto streamer = vt::Streamer::create(shared, sto);
  if (!streamer.ok()) return fail(streamer.status().with_context(reader_name));
  auto h = std::make_unique<vtrt_streamer>();
  h->source = shared;
  h->streamer = std::move(streamer).value();
  h->streamer->with_page_table([&](const vt::PageTable& t) {
    for (uint32_t l = 0; l < t.level_count(); ++l) {
      auto d = t.level_data(l);
      h->table.emplace_back(d.begin(), d.end());
      h->table_w.push_back(t.width(l));
      h->table_h.push_back(t.height(l));
      h->dirty.push_back({0, 0, t.width(l), t.height(l)});
    }
  });
  h->streamer->clear_table_dirty();
  *out = h.release();
  return int(VT_OK);
}

}  // namespace

extern "C" {

void vtrt_default_options(vtrt_options* o) {
  if (!o) return;
  copy_streamer_fields(vt::StreamerOptions{}, *o);
  o->bc7_as_rgba8 = 0;
}

int vtrt_open_ex(const vtrt_open_info* info, vtrt_streamer** out) {
  if (!out) return fail_null("out");
  *out = nullptr;
  if (!info) return fail_null("info");
  if (info->struct_size < sizeof(vtrt_open_info))
    return fail(vt::Error(vt::ErrorCode::kInvalidArgument,
                          "vtrt_open_ex: struct_size " + std::to_string(info->struct_size) +
                              " is not sizeof(vtrt_open_info) (" +
                              std::to_string(sizeof(vtrt_open_info)) + ")"));
  if ((info->path != nullptr) == (info->io != nullptr))
    return fail(vt::Error(vt::ErrorCode::kInvalidArgument,
                          "vtrt_open_ex: give exactly one of path and io"));
  if (info->jobs && !info->jobs->submit) return fail_null("jobs->submit");
  return guard([&] {
    std::shared_ptr<const vt::ByteSource> bytes;
    if (info->io) {
      bytes = vt::c_api::callback_byte_source(info->io);
      if (!bytes) return int(VT_ERR_INVALID_ARGUMENT);  // the message is set
    }
    auto reader =
        bytes ? vt::PageFileReader::open(std::move(bytes), info->name ? info->name : "(callbacks)")
              : vt::PageFileReader::open(info->path);
    if (!reader.ok()) return fail(reader.status());
    return open_streamer(std::move(reader).value(), *info, out);
  });
}

int vtrt_open(const char* path, const vtrt_options* options, vtrt_streamer** out) {
  if (!out) return fail_null("out");
  *out = nullptr;
  if (!path) return fail_null("path");
  vtrt_open_info info{};
  info.struct_size = sizeof info;
  info.path = path;
  info.options = options;
  return vtrt_open_ex(&info, out);
}

int vtrt_open_callbacks(const vt_read_callbacks* io, const char* name, const vtrt_options* options,
                        vtrt_streamer** out) {
  if (!out) return fail_null("out");
  *out = nullptr;
  if (!io) return fail_null("io");
  vtrt_open_info info{};
  info.struct_size = sizeof info;
  info.io = io;
  info.name = name;
  info.options = options;
  return vtrt_open_ex(&info, out);
}

void vtrt_close(vtrt_streamer* h) {
  delete h;
}

int vtrt_get_geometry(const vtrt_streamer* h, vtrt_geometry* out) {
  if (!h) return fail_null("streamer");
  if (!out) return fail_null("out");
  vt::c_api::fill_geometry(h->source->geometry(), out);
  out->layer_count = h->source->layer_count();
  return VT_OK;
}

int vtrt_get_upload_format(const vtrt_streamer* h, uint32_t layer, uint32_t* format,
                           size_t* bytes) {
  if (!h) return fail_null("streamer");
  if (!format || !bytes) return fail_null("format or bytes");
  if (layer >= h->source->layer_count()) return out_of_range("vtrt_get_upload_format: layer");
  *format = uint32_t(h->source->upload_format(layer));
  *bytes = h->source->upload_bytes(layer);
  return VT_OK;
}

int vtrt_update(vtrt_streamer* h, const uint32_t* feedback, size_t count, vtrt_frame_stats* stats) {
  if (!h) return fail_null("streamer");
  if (!feedback && count != 0) return fail_null("feedback");
  return guard([&] {
    // Held across update, copy and clear so that no other caller's update slips in between.
    std::lock_guard lock(h->mutex);
    const vt::FrameStats s =
        h->streamer->update(std::span<const uint32_t>(feedback, feedback ? count : 0));
    h->uploads = h->streamer->take_uploads();
    h->streamer->with_page_table([&](const vt::PageTable& t) {
      for (uint32_t l = 0; l < t.level_count(); ++l) {
        const vt::TableRect r = t.dirty(l);
        h->dirty[l] = r;
        if (r.empty()) continue;
        const auto src = t.level_data(l);
        const size_t row = size_t(t.width(l)) * 4;
        for (uint32_t y = r.y0; y < r.y1; ++y)
          std::memcpy(&h->table[l][y * row + r.x0 * 4], &src[y * row + r.x0 * 4],
                      size_t(r.x1 - r.x0) * 4);
      }
    });
    h->streamer->clear_table_dirty();
    if (stats) {
      stats->frame = s.frame;
      stats->needed = s.needed;
      stats->resident_hits = s.resident_hits;
      stats->queued = s.queued;
      stats->cancelled = s.cancelled;
      stats->mapped = s.mapped;
      stats->evicted = s.evicted;
      stats->dropped = s.dropped;
      stats->load_errors = s.load_errors;
      stats->lod_bias = s.lod_bias;
      stats->thrashing = s.thrashing ? 1 : 0;
    }
    return int(VT_OK);
  });
}

uint32_t vtrt_upload_count(const vtrt_streamer* h) {
  if (!h) return 0;
  std::lock_guard lock(h->mutex);
  return uint32_t(h->uploads.size());
}

int vtrt_get_upload(const vtrt_streamer* h, uint32_t index, uint32_t layer, vtrt_upload* out) {
  if (!h) return fail_null("streamer");
  if (!out) return fail_null("out");
  std::lock_guard lock(h->mutex);
  if (index >= h->uploads.size() || layer >= h->uploads[index].layers.size())
    return out_of_range("vtrt_get_upload: index or layer");
  const vt::PageUpload& u = h->uploads[index];
  out->level = u.page.level;
  out->page_x = u.page.x;
  out->page_y = u.page.y;
  out->slot_x = u.slot_x;
  out->slot_y = u.slot_y;
  out->data = u.layers[layer].data();
  out->size = u.layers[layer].size();
  return VT_OK;
}

int vtrt_get_page_table_level(const vtrt_streamer* h, uint32_t level, const uint8_t** data,
                              uint32_t* width, uint32_t* height, uint32_t dirty[4]) {
  if (!h) return fail_null("streamer");
  if (!data || !width || !height) return fail_null("data, width or height");
  std::lock_guard lock(h->mutex);
  if (level >= h->table.size()) return out_of_range("vtrt_get_page_table_level: level");
  *data = h->table[level].data();
  *width = h->table_w[level];
  *height = h->table_h[level];
  if (dirty) {
    const vt::TableRect r = h->dirty[level];
    dirty[0] = r.x0;
    dirty[1] = r.y0;
    dirty[2] = r.x1;
    dirty[3] = r.y1;
  }
  return VT_OK;
}

void vtrt_wait_idle(vtrt_streamer* h) {
  if (h) h->streamer->wait_idle();
}

int vtrt_idle(const vtrt_streamer* h) {
  return h && h->streamer->idle() ? 1 : 0;
}

}  // extern "C"
