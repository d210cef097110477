// The C API over PageFileReader: a thin layer that turns Status into codes and messages.
#include "format/page_file_c.h"

#include <cstring>
#include <memory>
#include <string>

#include "format/c_api_internal.h"
#include "format/page_file.h"

struct vtpf_file {
  std::unique_ptr<vt::PageFileReader> reader;
};

using vt::c_api::fail;
using vt::c_api::fail_null;
using vt::c_api::guard;

namespace {

int buffer_too_small(const vtpf_file* file, size_t capacity, const char* what, size_t needed) {
  return fail(vt::Error(vt::ErrorCode::kInvalidArgument,
                        file->reader->path() + ": buffer of " + std::to_string(capacity) +
                            " bytes for " + what + " of " + std::to_string(needed)));
}

}  // namespace

extern "C" {

int vtpf_open(const char* path, int verify_checksums, vtpf_file** out) {
  if (!out) return fail_null("out");
  *out = nullptr;
  if (!path) return fail_null("path");
  return guard([&] {
    vt::ReaderOptions options;
    options.verify_checksums = verify_checksums != 0;
    auto reader = vt::PageFileReader::open(path, options);
    if (!reader.ok()) return fail(reader.status());
    *out = new vtpf_file{std::move(reader).value()};
    return int(VT_OK);
  });
}

int vtpf_open_callbacks(const vt_read_callbacks* io, const char* name, int verify_checksums,
                        vtpf_file** out) {
  if (!out) return fail_null("out");
  *out = nullptr;
  return guard([&] {
    auto bytes = vt::c_api::callback_byte_source(io);
    if (!bytes) return int(VT_ERR_INVALID_ARGUMENT);
    vt::ReaderOptions options;
    options.verify_checksums = verify_checksums != 0;
    auto reader = vt::PageFileReader::open(std::move(bytes), name ? name : "(callbacks)", options);
    if (!reader.ok()) return fail(reader.status());
    *out = new vtpf_file{std::move(reader).value()};
    return int(VT_OK);
  });
}

void vtpf_close(vtpf_file* file) {
  delete file;
}

int vtpf_get_geometry(const vtpf_file* file, vtpf_geometry* out) {
  if (!file) return fail_null("file");
  if (!out) return fail_null("out");
  vt::c_api::fill_geometry(file->reader->geometry(), out);
  out->layer_count = uint32_t(file->reader->layers().size());
  out->version = file->reader->version();
  return VT_OK;
}

uint32_t vtpf_pages_x(const vtpf_file* file, uint32_t level) {
  if (!file || level >= file->reader->geometry().level_count()) return 0;
  return file->reader->geometry().pages_x(level);
}

uint32_t vtpf_pages_y(const vtpf_file* file, uint32_t level) {
  if (!file || level >= file->reader->geometry().level_count()) return 0;
  return file->reader->geometry().pages_y(level);
}

int vtpf_get_layer(const vtpf_file* file, uint32_t layer, vtpf_layer_info* out) {
  if (!file) return fail_null("file");
  if (!out) return fail_null("out");
  const auto& layers = file->reader->layers();
  if (layer >= layers.size())
    return fail(vt::Error(vt::ErrorCode::kInvalidArgument,
                          file->reader->path() + ": no layer " + std::to_string(layer)));
  const vt::LayerSpec& l = layers[layer];
  out->semantic = uint8_t(l.semantic);
  out->channels = l.channels;
  out->texel_type = uint8_t(l.texel_type);
  out->codec = uint8_t(l.codec);
  out->runtime_format = uint8_t(l.runtime_format);
  out->color_space = uint8_t(l.color_space);
  out->address_mode = uint8_t(l.address_mode);
  out->texel_bytes = l.texel_bytes();
  out->name = l.name.c_str();
  out->decoded_page_bytes = file->reader->decoded_page_bytes(layer);
  return VT_OK;
}

const char* vtpf_metadata(const vtpf_file* file, size_t* size) {
  if (!file) {
    if (size) *size = 0;
    return "";
  }
  if (size) *size = file->reader->metadata_json().size();
  return file->reader->metadata_json().data();
}

int vtpf_get_entry(const vtpf_file* file, uint32_t level, uint32_t x, uint32_t y, uint32_t layer,
                   vtpf_page_entry* out) {
  if (!file) return fail_null("file");
  if (!out) return fail_null("out");
  auto e = file->reader->entry({level, x, y}, layer);
  if (!e.ok()) return fail(e.status());
  out->state = uint8_t(e->state);
  out->codec = uint8_t(e->codec);
  out->offset = e->offset;
  out->size = e->size;
  out->checksum = e->checksum;
  std::memcpy(out->constant, e->constant, sizeof(out->constant));
  return VT_OK;
}

int vtpf_read_stored(const vtpf_file* file, uint32_t level, uint32_t x, uint32_t y, uint32_t layer,
                     void* buf, size_t capacity, size_t* size) {
  if (!file) return fail_null("file");
  auto e = file->reader->entry({level, x, y}, layer);
  if (!e.ok()) return fail(e.status());
  if (size) *size = e->size;
  if (e->state == vt::PageState::kStored && (capacity < e->size || !buf))
    return buffer_too_small(file, capacity, "a page", e->size);
  return guard([&] {
    auto bytes = file->reader->read_stored({level, x, y}, layer);
    if (!bytes.ok()) return fail(bytes.status());
    std::memcpy(buf, bytes->data(), bytes->size());
    return int(VT_OK);
  });
}

int vtpf_read_texels(const vtpf_file* file, uint32_t level, uint32_t x, uint32_t y, uint32_t layer,
                     void* out, size_t capacity) {
  if (!file) return fail_null("file");
  if (!out) return fail_null("out");
  const size_t needed = file->reader->decoded_page_bytes(layer);
  if (layer < file->reader->layers().size() && capacity < needed)
    return buffer_too_small(file, capacity, "a decoded page", needed);
  return guard([&] {
    vt::Status s = file->reader->read_texels(
        {level, x, y}, layer, std::span<uint8_t>(static_cast<uint8_t*>(out), needed));
    return s.ok() ? int(VT_OK) : fail(s);
  });
}

int vtpf_verify(const vtpf_file* file) {
  if (!file) return fail_null("file");
  return guard([&] {
    vt::Status s = file->reader->verify();
    return s.ok() ? int(VT_OK) : fail(s);
  });
}

}  // extern "C"
