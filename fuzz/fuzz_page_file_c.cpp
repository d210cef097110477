// libFuzzer target: a page file through the C API (format/page_file_c.h), as an engine calls it:
// open with checksums on and off, query everything, read every page (capped per input) into
// buffers of exactly the size the API reports, and one byte short, which must be refused. Then
// the runtime C API opens a streamer on the same file. The input is the whole .vtpf.
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "format/page_file_c.h"
#include "fuzz/fuzz_input.h"
#include "runtime/vt_runtime_c.h"

namespace vt::fuzz {
namespace {

constexpr int kMaxPageReads = 256;

// Every failing call leaves a message naming the file.
void check_c_refusal(int rc, const std::string& path) {
  if (rc == VT_OK) return;
  const char* message = vt_last_error();
  if (!message || !*message) finding("C API error without a message", std::to_string(rc));
  if (rc == VT_ERR_INTERNAL) finding("C API internal error", message);
  if (std::strstr(message, path.c_str()) == nullptr)
    finding("C API error does not name the file", message);
}

void read_page(const vtpf_file* f, uint32_t level, uint32_t x, uint32_t y, uint32_t layer,
               size_t decoded_bytes, const std::string& path) {
  vtpf_page_entry entry;
  if (vtpf_get_entry(f, level, x, y, layer, &entry) != VT_OK)
    finding("vtpf_get_entry failed inside the grid", vt_last_error());
  if (entry.state == VTPF_PAGE_STORED) {
    size_t size = 0;
    if (vtpf_read_stored(f, level, x, y, layer, nullptr, 0, &size) != VT_ERR_INVALID_ARGUMENT ||
        size != entry.size)
      finding("vtpf_read_stored with no room", "did not report the page's size");
    std::vector<uint8_t> stored(size);
    check_c_refusal(vtpf_read_stored(f, level, x, y, layer, stored.data(), size, &size), path);
  }
  // One byte short of the decoded size must be refused without a write.
  std::vector<uint8_t> texels(decoded_bytes + 1, 0xA5);
  if (decoded_bytes > 0 &&
      vtpf_read_texels(f, level, x, y, layer, texels.data(), decoded_bytes - 1) == VT_OK)
    finding("vtpf_read_texels accepted a short buffer", std::to_string(decoded_bytes));
  const int rc = vtpf_read_texels(f, level, x, y, layer, texels.data(), decoded_bytes);
  if (entry.state == VTPF_PAGE_ABSENT && rc != VT_ERR_NOT_FOUND)
    finding("absent page read without VT_ERR_NOT_FOUND", std::to_string(rc));
  if (entry.state != VTPF_PAGE_ABSENT) check_c_refusal(rc, path);
  if (texels[decoded_bytes] != 0xA5) finding("vtpf_read_texels wrote past its capacity", "");
}

void read_file(const vtpf_file* f, const std::string& path) {
  vtpf_geometry g;
  if (vtpf_get_geometry(f, &g) != VT_OK) finding("vtpf_get_geometry failed", vt_last_error());
  size_t metadata_size = 0;
  const char* metadata = vtpf_metadata(f, &metadata_size);
  if (metadata_size > 0 && !metadata) finding("metadata size without metadata", "");
  std::vector<vtpf_layer_info> layers(g.layer_count);
  for (uint32_t l = 0; l < g.layer_count; ++l)
    if (vtpf_get_layer(f, l, &layers[l]) != VT_OK || !layers[l].name)
      finding("vtpf_get_layer failed for a layer in range", std::to_string(l));
  vtpf_layer_info outside;
  if (vtpf_get_layer(f, g.layer_count, &outside) == VT_OK)
    finding("vtpf_get_layer accepted a layer past the count", "");
  int budget = kMaxPageReads;
  for (uint32_t level = 0; level < g.level_count; ++level)
    for (uint32_t y = 0; y < vtpf_pages_y(f, level); ++y)
      for (uint32_t x = 0; x < vtpf_pages_x(f, level); ++x)
        for (uint32_t l = 0; l < g.layer_count; ++l) {
          if (budget-- <= 0) return;
          read_page(f, level, x, y, l, layers[l].decoded_page_bytes, path);
        }
  check_c_refusal(vtpf_verify(f), path);
}

}  // namespace
}  // namespace vt::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vt;
  const std::string path = fuzz::write_input("input.vtpf", fuzz::as_text(data, size));
  for (const int checksums : {1, 0}) {
    vtpf_file* f = nullptr;
    const int rc = vtpf_open(path.c_str(), checksums, &f);
    if (rc != VT_OK) {
      if (f) fuzz::finding("vtpf_open failed but returned a file", "");
      fuzz::check_c_refusal(rc, path);
      return 0;
    }
    fuzz::read_file(f, path);
    vtpf_close(f);
  }
  vtrt_options options;
  vtrt_default_options(&options);
  options.threads = 1;
  vtrt_streamer* streamer = nullptr;
  const int rc = vtrt_open(path.c_str(), &options, &streamer);
  fuzz::check_c_refusal(rc, path);
  if (rc == VT_OK) {
    vtrt_geometry g;
    if (vtrt_get_geometry(streamer, &g) != VT_OK) fuzz::finding("vtrt_get_geometry failed", "");
    vtrt_close(streamer);
  }
  return 0;
}
