// A procedural PageSource for runtime tests: no file. Page contents are a hash of (page, layer,
// texel), so any slot mix-up shows; a page is absent when `absent` says so.
#pragma once

#include <atomic>
#include <chrono>
#include <cstring>
#include <functional>
#include <thread>

#include "common/hash.h"
#include "runtime/page_source.h"

namespace vt::testing {

class FakeSource final : public PageSource {
 public:
  FakeSource(PageGeometry g, uint32_t layers, std::function<bool(const PageId&)> absent = {})
      : geometry_(g), layers_(layers), absent_(std::move(absent)) {}

  const PageGeometry& geometry() const override { return geometry_; }
  uint32_t layer_count() const override { return layers_; }
  RuntimeFormat upload_format(uint32_t) const override { return RuntimeFormat::kRgba8; }
  size_t upload_bytes(uint32_t) const override {
    return size_t(geometry_.page_size()) * geometry_.page_size() * 4;
  }
  bool present(const PageId& id) const override {
    return geometry_.contains(id) && !(absent_ && absent_(id));
  }
  Status load(const PageId& id, uint32_t layer, std::span<uint8_t> out) const override {
    loads_.fetch_add(1, std::memory_order_relaxed);
    if (!present(id)) return Error(ErrorCode::kNotFound, "fake: absent page");
    if (delay_us_ > 0) std::this_thread::sleep_for(std::chrono::microseconds(delay_us_));
    if (fail_ && fail_(id)) return Error(ErrorCode::kCorrupt, "fake: page checksum mismatch");
    fill(id, layer, out);
    return Status::Ok();
  }
  // Content only depends on the page and layer (the first word names them, for quick checks).
  static void fill(const PageId& id, uint32_t layer, std::span<uint8_t> out) {
    const uint32_t seed = hash32(id.level * 0x9E3779B9u ^ hash32(id.x * 65537u + id.y) ^ layer);
    for (size_t i = 0; i < out.size(); i += 4) {
      const uint32_t v = hash32(seed + uint32_t(i));
      std::memcpy(&out[i], &v, std::min<size_t>(4, out.size() - i));
    }
  }
  uint64_t loads() const { return loads_.load(); }
  void set_delay_us(int us) { delay_us_ = us; }
  // Pages for which load() reports corrupt data (present, but unreadable).
  void set_failing(std::function<bool(const PageId&)> fail) { fail_ = std::move(fail); }

 private:
  PageGeometry geometry_;
  uint32_t layers_;
  std::function<bool(const PageId&)> absent_;
  mutable std::atomic<uint64_t> loads_{0};
  int delay_us_ = 0;
  std::function<bool(const PageId&)> fail_;
};

// A small geometry: 8 x 6 pages of 8 + 2 * 4 texels (levels: 8x6, 4x3, 2x2, 1x1).
inline PageGeometry small_geometry(uint32_t pages_x = 8, uint32_t pages_y = 6) {
  PageGeometry g;
  g.payload = 8;
  g.border = 4;
  g.width = pages_x * g.payload;
  g.height = pages_y * g.payload;
  return g;
}

}  // namespace vt::testing
