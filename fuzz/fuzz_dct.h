// The DCT fuzz target's input layout, shared by the target (fuzz_dct.cpp) and the seed writer.
//
// Input: byte 0 selects the target (bit 0: tables parser; else page decoder, bits 1-3 the
// channel layout, bit 4 trained tables), byte 1 the quality, byte 2 the page size; the rest is
// the data under test.
#pragma once

#include <array>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <utility>
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
