// UTF-8 checks and the Latin-1 reading of text that is not UTF-8 (header-only: the scene
// importers, the metadata writers and the CLI's JSON all need them).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace vt {

inline void append_utf8(uint32_t cp, std::string* out) {
  if (cp < 0x80) {
    out->push_back(static_cast<char>(cp));
  } else if (cp < 0x800) {
    out->push_back(static_cast<char>(0xc0 | (cp >> 6)));
    out->push_back(static_cast<char>(0x80 | (cp & 0x3f)));
  } else if (cp < 0x10000) {
    out->push_back(static_cast<char>(0xe0 | (cp >> 12)));
    out->push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3f)));
    out->push_back(static_cast<char>(0x80 | (cp & 0x3f)));
  } else {
    out->push_back(static_cast<char>(0xf0 | (cp >> 18)));
    out->push_back(static_cast<char>(0x80 | ((cp >> 12) & 0x3f)));
    out->push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3f)));
    out->push_back(static_cast<char>(0x80 | (cp & 0x3f)));
  }
}

inline bool valid_utf8(std::string_view text) {
  const auto* d = reinterpret_cast<const uint8_t*>(text.data());
  const size_t n = text.size();
  for (size_t i = 0; i < n;) {
    // Strict (RFC 3629, as JSON writers demand): no overlong forms, surrogates or code points
    // past U+10FFFF. lo/hi bound the second byte.
    const uint8_t b = d[i];
    int extra = 0;
    uint8_t lo = 0x80, hi = 0xbf;
    if (b < 0x80) {
      extra = 0;
    } else if (b >= 0xc2 && b <= 0xdf) {
      extra = 1;
    } else if (b >= 0xe0 && b <= 0xef) {
      extra = 2;
      lo = b == 0xe0 ? 0xa0 : 0x80;
      hi = b == 0xed ? 0x9f : 0xbf;
    } else if (b >= 0xf0 && b <= 0xf4) {
      extra = 3;
      lo = b == 0xf0 ? 0x90 : 0x80;
      hi = b == 0xf4 ? 0x8f : 0xbf;
    } else {
      return false;
    }
    if (extra > 0 && i + extra >= n) return false;
    if (extra > 0 && (d[i + 1] < lo || d[i + 1] > hi)) return false;
    for (int k = 2; k <= extra; ++k)
      if ((d[i + k] & 0xc0) != 0x80) return false;
    i += extra + 1;
  }
  return true;
}

// Every byte as the code point of its value (Latin-1).
inline std::string latin1_to_utf8(std::string_view text) {
  std::string out;
  for (const char c : text) append_utf8(static_cast<unsigned char>(c), &out);
  return out;
}

// `text` when it is UTF-8, else its Latin-1 reading: names from formats that do not say their
// encoding (3DS, ASE, IQM, MD3, old OBJ) are mostly in an 8-bit Windows code page.
inline std::string as_utf8(std::string_view text) {
  return valid_utf8(text) ? std::string(text) : latin1_to_utf8(text);
}

}  // namespace vt
