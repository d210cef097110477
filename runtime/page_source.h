// Where the runtime gets pages from. PageSource is the small interface the cache, resolver and
// loader are written against: geometry, which pages exist, and a page's bytes in the format the
// physical cache holds. make_page_file_source adapts a format/ PageFileReader (DCT -> the
// layer's BC format at the real-time level, stored BC passed through after zstd, raw -> RGBA8);
// tests use small fake sources, so the core logic needs no file.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

#include "codec/bc.h"
#include "common/status.h"
#include "format/page_file.h"
#include "format/page_geometry.h"
#include "runtime/page_buffer.h"

namespace vt {

class PageSource {
 public:
  virtual ~PageSource() = default;

  virtual const PageGeometry& geometry() const = 0;
  virtual uint32_t layer_count() const = 0;
  // Format of the bytes load() writes for a layer: a BC format (BC6H for half-float layers),
  // kRgba8, kR8, kRg8, kRgba16f or kRgba32f, always covering page_size x page_size texels
  // (borders included).
  virtual RuntimeFormat upload_format(uint32_t layer) const = 0;
  // Bytes load() writes for a layer (one physical slot of that layer).
  virtual size_t upload_bytes(uint32_t layer) const = 0;
  // True when the page is stored or constant in every layer. A page absent in any layer is
  // never loaded: the runtime falls back to its nearest present ancestor. Thread-safe.
  virtual bool present(const PageId& id) const = 0;
  // Writes the upload bytes of a present page's layer into `out` (upload_bytes(layer) bytes).
  // Thread-safe: called concurrently from the loader's worker threads.
  virtual Status load(const PageId& id, uint32_t layer, std::span<uint8_t> out) const = 0;
};

// Total bytes of one physical slot over all layers.
inline size_t slot_bytes(const PageSource& source) {
  size_t total = 0;
  for (uint32_t l = 0; l < source.layer_count(); ++l) total += source.upload_bytes(l);
  return total;
}

struct PageFileSourceOptions {
  BcQuality bc_quality = BcQuality::kRealtime;  // used when a page must be (re)encoded to BC
  // Lavapipe samples BC7 very slowly: optionally upload BC7 layers as RGBA8 instead.
  bool bc7_as_rgba8 = false;
  // For a GPU without BC6H (or a reference render): upload BC6H layers as RGBA16F, the stored
  // half texels as they are (BC6H blocks stored in the file are decoded).
  bool bc6h_as_rgba16f = false;
  Allocator allocator;  // a page's decode scratch (decoded texels before the BC encode)
};

// Adapts a page file. Checks up front that every layer can be delivered (8-bit layers to any
// 8-bit format; half layers to RGBA16F or BC6H, encoded at load with bc_quality unless stored
// as BC6H blocks; float layers to RGBA32F) and builds the presence map (one bit per
// page; at most 4096 x 4096 pages at level 0, the feedback format's limit). Errors name the file.
Expected<std::unique_ptr<PageSource>> make_page_file_source(
    std::shared_ptr<const PageFileReader> reader, const PageFileSourceOptions& options = {});

}  // namespace vt
