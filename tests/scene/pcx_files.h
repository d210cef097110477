// PCX files written byte by byte, for the PCX decoder's test and fuzz seeds: a 3 x 2 image of 256
// colours (run-length runs, the palette at the end; indices {1 2 1} {2 2 1}, 1 red, 2 blue) and
// a 3 x 1 RGB one of three planes (R {200 20 30}, G {40 50 60}, B {70 80 90}; the 200, a byte
// of 0xC0 or more, escaped as a run of one).
#pragma once

#include <string>

namespace vt::test {

// The 128-byte header: 8 bits a plane, run-length coded, window (0, 0)-(w - 1, h - 1).
inline std::string pcx_header(int w, int h, int planes, int line_bytes) {
  std::string b(128, '\0');
  b[0] = 0x0a, b[1] = 5, b[2] = 1, b[3] = 8;
  b[8] = char(w - 1), b[10] = char(h - 1);
  b[65] = char(planes), b[66] = char(line_bytes);
  return b;
}

inline std::string pcx_paletted_3x2() {
  std::string palette(768, '\0');
  palette[3] = char(255);  // 1: red
  palette[8] = char(255);  // 2: blue
  return pcx_header(3, 2, 1, 4) + std::string("\x01\x02\x01\x00\xc2\x02\x01\x00", 8) + '\x0c' +
         palette;
}

inline std::string pcx_rgb_3x1() {
  return pcx_header(3, 1, 3, 4) +
         std::string("\xc1\xc8\x14\x1e\x00\x28\x32\x3c\x00\x46\x50\x5a\x00", 13);
}

}  // namespace vt::test
