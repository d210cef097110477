// libFuzzer target: a page file through the C++ reader and every layer decoder, then through the
// runtime page source. The input is the whole .vtpf. Each file is opened with page checksums
// verified and not: unverified reads hand damaged bytes to the decoders, which must refuse them
// without a bad access. Pages read per input are capped so one input stays fast.
#include <cstdint>
#include <memory>
#include <vector>

#include "format/layer_codec.h"
#include "format/page_file.h"
#include "fuzz/fuzz_input.h"
#include "runtime/page_source.h"

namespace vt::fuzz {
namespace {

constexpr int kMaxPageReads = 256;

void read_pages(const PageFileReader& reader) {
  const PageGeometry& g = reader.geometry();
  const uint32_t layers = uint32_t(reader.layers().size());
  std::vector<uint8_t> texels;
  int budget = kMaxPageReads;
  for (uint32_t level = 0; level < g.level_count(); ++level)
    for (uint32_t y = 0; y < g.pages_y(level); ++y)
      for (uint32_t x = 0; x < g.pages_x(level); ++x)
        for (uint32_t layer = 0; layer < layers; ++layer) {
          if (budget-- <= 0) return;
          const PageId id{level, x, y};
          auto entry = reader.entry(id, layer);
          if (!entry.ok()) finding("entry of a page in the grid failed", entry.status().message());
          if (entry->state == PageState::kStored) {
            auto stored = reader.read_stored(id, layer);
            if (stored.ok() && stored->size() != entry->size)
              finding("read_stored size differs from the index", page_name(id, layer));
            check_refusal(stored.status(), reader.path());
            check_refusal(reader.verify_page(id, layer), reader.path());
          }
          texels.assign(reader.decoded_page_bytes(layer), 0);
          const Status s = reader.read_texels(id, layer, texels);
          if (entry->state == PageState::kAbsent && s.code() != ErrorCode::kNotFound)
            finding("absent page read without kNotFound", page_name(id, layer));
          if (entry->state != PageState::kAbsent) check_refusal(s, reader.path());
        }
}

void load_runtime_pages(std::shared_ptr<const PageFileReader> reader) {
  auto source = make_page_file_source(reader);
  if (!source.ok()) return check_refusal(source.status(), reader->path());
  const PageGeometry& g = (*source)->geometry();
  std::vector<uint8_t> upload;
  int budget = kMaxPageReads;
  for (uint32_t level = 0; level < g.level_count(); ++level)
    for (uint32_t y = 0; y < g.pages_y(level); ++y)
      for (uint32_t x = 0; x < g.pages_x(level); ++x) {
        if (!(*source)->present({level, x, y})) continue;
        for (uint32_t layer = 0; layer < (*source)->layer_count(); ++layer) {
          if (budget-- <= 0) return;
          upload.assign((*source)->upload_bytes(layer), 0);
          check_refusal((*source)->load({level, x, y}, layer, upload), reader->path());
        }
      }
}

}  // namespace
}  // namespace vt::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vt;
  const std::string path = fuzz::write_input("input.vtpf", fuzz::as_text(data, size));
  for (const bool checksums : {true, false}) {
    auto reader = PageFileReader::open(path, ReaderOptions{checksums});
    if (!reader.ok()) {
      fuzz::check_refusal(reader.status(), path);
      return 0;
    }
    fuzz::check_refusal((*reader)->verify(), path);
    fuzz::read_pages(**reader);
    if (!checksums) fuzz::load_runtime_pages(std::move(reader).value());
  }
  return 0;
}
