// 32-bit BMP and TGA files written byte by byte, with the fourth byte and the header's alpha
// fields exactly as given (OpenImageIO's writers always declare their alpha).
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace vt::test {

inline void put_le(std::vector<uint8_t>& out, uint32_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(uint8_t(v >> (8 * i)));
}

inline bool write_file(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  return bool(f);
}

// `rgba`: w * h texels, top row first. A BI_RGB BMP (rows bottom-up, B G R and the fourth byte).
inline bool write_bmp32(const std::string& path, uint32_t w, uint32_t h,
                        const std::vector<uint8_t>& rgba) {
  std::vector<uint8_t> b = {'B', 'M'};
  const uint32_t data = w * h * 4;
  put_le(b, 54 + data, 4);
  put_le(b, 0, 4);
  put_le(b, 54, 4);
  for (uint32_t v : {40u, w, h}) put_le(b, v, 4);
  put_le(b, 1, 2);                                                      // planes
  put_le(b, 32, 2);                                                     // bits per pixel
  for (uint32_t v : {0u, data, 2835u, 2835u, 0u, 0u}) put_le(b, v, 4);  // BI_RGB
  for (uint32_t y = h; y-- > 0;)
    for (uint32_t x = 0; x < w; ++x) {
      const uint8_t* t = &rgba[(size_t(y) * w + x) * 4];
      b.insert(b.end(), {t[2], t[1], t[0], t[3]});
    }
  return write_file(path, b);
}

// An uncompressed true-colour TGA, 32 bits a pixel, top row first; `alpha_bits` goes in the
// image descriptor (0: the header says the fourth byte is no alpha).
inline bool write_tga32(const std::string& path, uint32_t w, uint32_t h,
                        const std::vector<uint8_t>& rgba, uint8_t alpha_bits) {
  std::vector<uint8_t> b = {0, 0, 2};  // no ID, no palette, true colour
  put_le(b, 0, 4);                     // palette fields
  put_le(b, 0, 1);
  put_le(b, 0, 4);  // origin
  put_le(b, w, 2);
  put_le(b, h, 2);
  b.push_back(32);
  b.push_back(uint8_t(0x20 | (alpha_bits & 0x0F)));  // top-left origin
  for (size_t i = 0; i < size_t(w) * h; ++i) {
    const uint8_t* t = &rgba[i * 4];
    b.insert(b.end(), {t[2], t[1], t[0], t[3]});
  }
  return write_file(path, b);
}

}  // namespace vt::test
