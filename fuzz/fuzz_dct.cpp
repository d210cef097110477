// libFuzzer target for the page DCT decoder and tables parser (fuzz/CMakeLists.txt builds it as
// vt_fuzz_dct; the input layout is in fuzz_dct.h). tests/codec/test_dct_fuzz.cpp includes this
// file and drives it with random and mutated inputs, so the normal suite runs it too.
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "codec/dct.h"
#include "fuzz/fuzz_dct.h"

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
  const DctTablesPtr tables = dct_fuzz::tables_for(setup);
  const size_t texels = size_t(setup.width) * setup.height * setup.settings.channels;
  std::vector<uint8_t> a(texels, 0x11), b(texels, 0x22);
  const Status sa = dct_decode_page(*tables, body, setup.width, setup.height, a.data());
  if (!sa.ok() && sa.code() != ErrorCode::kCorrupt) std::abort();
  if (sa.ok()) {
    // Every texel written, and the same bytes decode to the same texels.
    const Status sb = dct_decode_page(*tables, body, setup.width, setup.height, b.data());
    if (!sb.ok() || a != b) std::abort();
  }
  return 0;
}
