// libFuzzer target for the page DCT decoder and tables parser (fuzz/CMakeLists.txt builds it as
// vt_fuzz_dct; the input layout is in fuzz_dct.h). tests/codec/test_dct_fuzz.cpp includes this
// file and drives it with random and mutated inputs, so the normal suite runs it too.
#include <cstdint>
#include <cstdlib>
#include <map>
#include <span>
#include <tuple>
#include <vector>

#include "codec/dct.h"
#include "fuzz/fuzz_dct.h"

namespace {

// Making tables (training them on a page for half the layouts) cost far more than decoding a
// page, so the target ran at about 150 inputs/s. Tables depend only on the three header
// bytes, so they are made once per header and kept; mutations of the page bytes, which is
// where the decoder's paths are, then cost a decode each. Bounded so a long run that visits
// many headers keeps a small footprint.
const vt::DctTables& tables_for_header(const uint8_t* header) {
  using Key = std::tuple<uint8_t, uint8_t, uint8_t>;
  static std::map<Key, vt::DctTablesPtr> cache;
  // The bits setup_from reads: byte 0 bits 1-4, the quality, the page size's 6 bits.
  const Key key{uint8_t(header[0] & 0x1E), uint8_t(header[1] % 100), uint8_t(header[2] & 0x3F)};
  auto it = cache.find(key);
  if (it != cache.end()) return *it->second;
  if (cache.size() >= 512) cache.clear();
  return *cache.emplace(key, vt::dct_fuzz::tables_for(vt::dct_fuzz::setup_from(header)))
              .first->second;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vt;
  if (size < dct_fuzz::kHeaderBytes) return 0;
  const std::span<const uint8_t> body(data + dct_fuzz::kHeaderBytes, size - dct_fuzz::kHeaderBytes);
  if (data[0] & 1) {
    auto tables = dct_parse_tables(body);
    if (tables.ok()) {
      // Whatever parses must serialise back to bytes that parse to the same tables.
      const auto bytes = dct_serialize_tables(**tables);
      auto again = dct_parse_tables(bytes);
      if (!again.ok() || dct_serialize_tables(**again) != bytes) std::abort();
    }
    return 0;
  }
  const dct_fuzz::Setup setup = dct_fuzz::setup_from(data);
  const DctTables& tables = tables_for_header(data);
  const size_t texels = size_t(setup.width) * setup.height * setup.settings.channels;
  std::vector<uint8_t> a(texels, 0x11), b(texels, 0x22);
  const Status sa = dct_decode_page(tables, body, setup.width, setup.height, a.data());
  if (!sa.ok() && sa.code() != ErrorCode::kCorrupt) std::abort();
  if (sa.ok()) {
    // Every texel written, and the same bytes decode to the same texels.
    const Status sb = dct_decode_page(tables, body, setup.width, setup.height, b.data());
    if (!sb.ok() || a != b) std::abort();
  }
  return 0;
}
