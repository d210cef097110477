// libFuzzer entry for the page DCT decoder and tables parser. Build alone with
// -fsanitize=fuzzer, or as a plain function: test_dct_fuzz.cpp includes this file and drives it
// with random and mutated inputs under the sanitizers.
//
// Input: byte 0 selects the target (bit 0: tables parser; else page decoder, bits 1-3 the
// channel layout, bit 4 trained tables), byte 1 the quality, byte 2 the page size; the rest is
// the data under test.
#include <array>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>
#include <vector>

#include "codec/dct.h"

namespace vt::dct_fuzz {

constexpr size_t kHeaderBytes = 3;

struct Setup {
  DctSettings settings;
  int width = 8;
  int height = 8;
  bool trained = false;
};

inline Setup setup_from(const uint8_t* header) {
  static const std::array<std::pair<int, DctPlaneLayout>, 8> kLayouts = {{
      {1, DctPlaneLayout::kPlanes},
      {2, DctPlaneLayout::kPlanes},
      {3, DctPlaneLayout::kPlanes},
      {4, DctPlaneLayout::kPlanes},
      {3, DctPlaneLayout::kYCoCg},
      {4, DctPlaneLayout::kYCoCg},
      {3, DctPlaneLayout::kYCoCg420},
      {4, DctPlaneLayout::kYCoCg420},
  }};
  Setup s;
  const auto& l = kLayouts[(header[0] >> 1) & 7];
  s.settings.channels = l.first;
  s.settings.layout = l.second;
  s.settings.quality = 1 + header[1] % 100;
  s.width = 8 * (1 + (header[2] & 7));
  s.height = 8 * (1 + ((header[2] >> 3) & 7));
  s.trained = (header[0] & 16) != 0;
  return s;
}

inline DctTablesPtr tables_for(const Setup& s) {
  std::vector<uint8_t> page(size_t(s.width) * s.height * s.settings.channels);
  // Training on a busy page skews the initial probabilities, which reaches other paths.
  for (size_t i = 0; i < page.size(); i++) page[i] = uint8_t((i * 37) ^ (i >> 5));
  const std::span<const uint8_t> training[] = {page};
  auto t = dct_make_tables(
      s.settings, s.width, s.height,
      s.trained ? std::span(training) : std::span<const std::span<const uint8_t>>());
  if (!t.ok()) std::abort();
  return std::move(t).value();
}

}  // namespace vt::dct_fuzz

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
