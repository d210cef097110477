// Test helper: a copy of a page file with pages moved or their texels edited, every checksum
// recomputed by the writer (so `verify` passes): how the validation tests sabotage a bake.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "format/layer_codec.h"
#include "format/page_file.h"

namespace vt::render {

// Which page's content goes into (id, layer), and an edit of its decoded texels (returns true
// when it changed them).
using PageRemap = std::function<PageId(const PageId& id, uint32_t layer)>;
using PageEdit =
    std::function<bool(const PageId& id, uint32_t layer, std::vector<uint8_t>& texels)>;

// Copies the page file `in` to `out` page by page through `remap` and `edit`; edited pages are
// coded again with the layer's codec, the rest copied as they are.
inline Status rewrite_page_file(const std::string& in, const std::string& out,
                                const PageRemap& remap, const PageEdit& edit) {
  VT_ASSIGN_OR_RETURN(auto reader, PageFileReader::open(in));
  PageFileDesc desc;
  desc.geometry = reader->geometry();
  desc.layers = reader->layers();
  desc.metadata_json = reader->metadata_json();
  VT_ASSIGN_OR_RETURN(auto writer, PageFileWriter::create(out, desc));
  const PageGeometry& g = desc.geometry;
  for (uint32_t layer = 0; layer < desc.layers.size(); ++layer) {
    std::vector<uint8_t> texels(reader->decoded_page_bytes(layer));
    for (uint32_t l = 0; l < g.level_count(); ++l)
      for (uint32_t y = 0; y < g.pages_y(l); ++y)
        for (uint32_t x = 0; x < g.pages_x(l); ++x) {
          const PageId id{l, x, y}, src = remap(id, layer);
          VT_ASSIGN_OR_RETURN(PageEntry e, reader->entry(src, layer));
          if (e.state == PageState::kAbsent) continue;
          VT_RETURN_IF_ERROR(reader->read_texels(src, layer, texels));
          if (edit(id, layer, texels)) {
            std::vector<uint8_t> bytes;
            VT_RETURN_IF_ERROR(reader->layer_codec(layer).encode(texels.data(), {}, bytes));
            VT_RETURN_IF_ERROR(writer->add_page(id, layer, bytes));
          } else if (e.state == PageState::kConstant) {
            VT_RETURN_IF_ERROR(writer->add_constant_page(
                id, layer, std::span<const uint8_t>(e.constant, desc.layers[layer].texel_bytes())));
          } else {
            VT_ASSIGN_OR_RETURN(auto bytes, reader->read_stored(src, layer));
            VT_RETURN_IF_ERROR(writer->add_page(id, layer, bytes));
          }
        }
  }
  return writer->finish();
}

}  // namespace vt::render
