#include "runtime/vt_runtime_c.h"

#include <cstring>
#include <mutex>
#include <string>
#include <vector>

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
  std::string error;
};

namespace {

int code_of(const vt::Status& s) {
  switch (s.code()) {
    case vt::ErrorCode::kOk:
      return VTRT_OK;
    case vt::ErrorCode::kInvalidArgument:
      return VTRT_INVALID_ARGUMENT;
    case vt::ErrorCode::kNotFound:
      return VTRT_NOT_FOUND;
    case vt::ErrorCode::kIo:
      return VTRT_IO;
    case vt::ErrorCode::kCorrupt:
      return VTRT_CORRUPT;
    case vt::ErrorCode::kUnsupported:
      return VTRT_UNSUPPORTED;
    case vt::ErrorCode::kResourceLimit:
      return VTRT_RESOURCE_LIMIT;
    default:
      return VTRT_INTERNAL;
  }
}

void copy_message(const std::string& msg, char* out, size_t capacity) {
  if (!out || capacity == 0) return;
  const size_t n = std::min(msg.size(), capacity - 1);
  std::memcpy(out, msg.data(), n);
  out[n] = '\0';
}

int fail(const vtrt_streamer* h, int code, const std::string& msg) {
  const_cast<vtrt_streamer*>(h)->error = msg;
  return code;
}

}  // namespace

extern "C" {

void vtrt_default_options(vtrt_options* o) {
  if (!o) return;
  const vt::StreamerOptions d;
  o->slots_x = d.slots_x;
  o->slots_y = d.slots_y;
  o->memory_budget_bytes = d.memory_budget_bytes;
  o->threads = d.threads;
  o->max_in_flight = d.max_in_flight;
  o->upload_byte_limit = d.upload_byte_limit;
  o->max_lod_bias = d.max_lod_bias;
  o->bc7_as_rgba8 = 0;
}

int vtrt_open(const char* path, const vtrt_options* options, vtrt_streamer** out,
              char* error_message, size_t message_capacity) {
  if (!out) return VTRT_INVALID_ARGUMENT;
  *out = nullptr;
  if (!path) {
    copy_message("vtrt_open: no path", error_message, message_capacity);
    return VTRT_INVALID_ARGUMENT;
  }
  vtrt_options o;
  vtrt_default_options(&o);
  if (options) o = *options;
  auto reader = vt::PageFileReader::open(path);
  if (!reader.ok()) {
    copy_message(reader.status().message(), error_message, message_capacity);
    return code_of(reader.status());
  }
  vt::PageFileSourceOptions so;
  so.bc7_as_rgba8 = o.bc7_as_rgba8 != 0;
  auto source = vt::make_page_file_source(
      std::shared_ptr<const vt::PageFileReader>(std::move(reader).value()), so);
  if (!source.ok()) {
    copy_message(source.status().message(), error_message, message_capacity);
    return code_of(source.status());
  }
  vt::StreamerOptions so2;
  so2.slots_x = o.slots_x;
  so2.slots_y = o.slots_y;
  so2.memory_budget_bytes = o.memory_budget_bytes;
  so2.threads = o.threads;
  so2.max_in_flight = o.max_in_flight;
  so2.upload_byte_limit = o.upload_byte_limit;
  so2.max_lod_bias = o.max_lod_bias;
  std::shared_ptr<const vt::PageSource> shared(std::move(source).value());
  auto streamer = vt::Streamer::create(shared, so2);
  if (!streamer.ok()) {
    copy_message(std::string(path) + ": " + streamer.status().message(), error_message,
                 message_capacity);
    return code_of(streamer.status());
  }
  auto* h = new vtrt_streamer;
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
  *out = h;
  return VTRT_OK;
}

void vtrt_close(vtrt_streamer* h) {
  delete h;
}

const char* vtrt_last_error(const vtrt_streamer* h) {
  return h ? h->error.c_str() : "";
}

int vtrt_geometry_get(const vtrt_streamer* h, vtrt_geometry* out) {
  if (!h || !out) return VTRT_INVALID_ARGUMENT;
  const vt::PageGeometry& g = h->source->geometry();
  out->width = g.width;
  out->height = g.height;
  out->payload = g.payload;
  out->border = g.border;
  out->page_size = g.page_size();
  out->level_count = g.level_count();
  out->layer_count = h->source->layer_count();
  return VTRT_OK;
}

int vtrt_layer_upload_format(const vtrt_streamer* h, uint32_t layer, uint32_t* format,
                             size_t* bytes) {
  if (!h || !format || !bytes) return VTRT_INVALID_ARGUMENT;
  if (layer >= h->source->layer_count()) return fail(h, VTRT_INVALID_ARGUMENT, "no such layer");
  *format = uint32_t(h->source->upload_format(layer));
  *bytes = h->source->upload_bytes(layer);
  return VTRT_OK;
}

int vtrt_update(vtrt_streamer* h, const uint32_t* feedback, size_t count, vtrt_frame_stats* stats) {
  if (!h) return VTRT_INVALID_ARGUMENT;
  if (!feedback && count != 0) return fail(h, VTRT_INVALID_ARGUMENT, "vtrt_update: no feedback");
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
  return VTRT_OK;
}

uint32_t vtrt_upload_count(const vtrt_streamer* h) {
  if (!h) return 0;
  std::lock_guard lock(h->mutex);
  return uint32_t(h->uploads.size());
}

int vtrt_upload_get(const vtrt_streamer* h, uint32_t index, uint32_t layer, vtrt_upload* out) {
  if (!h || !out) return VTRT_INVALID_ARGUMENT;
  std::lock_guard lock(h->mutex);
  if (index >= h->uploads.size() || layer >= h->uploads[index].layers.size())
    return fail(h, VTRT_INVALID_ARGUMENT, "vtrt_upload_get: index or layer out of range");
  const vt::PageUpload& u = h->uploads[index];
  out->level = u.page.level;
  out->page_x = u.page.x;
  out->page_y = u.page.y;
  out->slot_x = u.slot_x;
  out->slot_y = u.slot_y;
  out->data = u.layers[layer].data();
  out->size = u.layers[layer].size();
  return VTRT_OK;
}

int vtrt_page_table_level(const vtrt_streamer* h, uint32_t level, const uint8_t** data,
                          uint32_t* width, uint32_t* height, uint32_t dirty[4]) {
  if (!h || !data || !width || !height) return VTRT_INVALID_ARGUMENT;
  std::lock_guard lock(h->mutex);
  if (level >= h->table.size())
    return fail(h, VTRT_INVALID_ARGUMENT, "vtrt_page_table_level: no such level");
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
  return VTRT_OK;
}

void vtrt_wait_idle(vtrt_streamer* h) {
  if (h) h->streamer->wait_idle();
}

int vtrt_idle(const vtrt_streamer* h) {
  return h && h->streamer->idle() ? 1 : 0;
}

}  // extern "C"
