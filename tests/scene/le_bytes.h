// Little-endian binary writers for the scene tests' hand-made model files (Quake MDL, MD2, MD3,
// IQM).
#pragma once

#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <string>

namespace vt::test {

inline std::string le32(std::initializer_list<int64_t> values) {
  std::string out;
  for (int64_t v : values)
    for (int b = 0; b < 4; ++b) out.push_back(char(uint32_t(v) >> (8 * b)));
  return out;
}

inline std::string lef(std::initializer_list<float> values) {
  std::string out;
  for (float f : values) {
    uint32_t v;
    std::memcpy(&v, &f, 4);
    out += le32({v});
  }
  return out;
}

}  // namespace vt::test
