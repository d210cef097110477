// Text and file names as OBJ/MTL exporters write them (see scene/obj_mtl.h).
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <filesystem>

#include "common/utf8.h"
#include "scene/obj_mtl.h"

namespace vt::scene::detail {
namespace {

Expected<std::string> utf16_to_utf8(const uint8_t* data, size_t size, bool big_endian,
                                    const std::string& path) {
  if (size % 2 != 0)
    return Error(ErrorCode::kCorrupt, path + ": UTF-16 text with an odd number of bytes");
  auto unit = [&](size_t i) {
    return big_endian ? uint32_t(data[i] << 8 | data[i + 1]) : uint32_t(data[i + 1] << 8 | data[i]);
  };
  std::string out;
  out.reserve(size / 2);
  for (size_t i = 0; i < size; i += 2) {
    uint32_t cp = unit(i);
    if (cp >= 0xd800 && cp < 0xdc00 && i + 3 < size) {
      uint32_t low = unit(i + 2);
      if (low >= 0xdc00 && low < 0xe000) {
        cp = 0x10000 + ((cp - 0xd800) << 10) + (low - 0xdc00);
        i += 2;
      }
    }
    if (cp >= 0xd800 && cp < 0xe000) cp = 0xfffd;  // an unpaired surrogate
    append_utf8(cp, &out);
  }
  return out;
}

}  // namespace

Expected<std::string> decode_text(const std::vector<uint8_t>& bytes, const std::string& path,
                                  std::string* note) {
  note->clear();
  const uint8_t* d = bytes.data();
  size_t n = bytes.size();
  if (n >= 3 && d[0] == 0xef && d[1] == 0xbb && d[2] == 0xbf) return std::string(d + 3, d + n);
  if (n >= 2 && d[0] == 0xff && d[1] == 0xfe) return utf16_to_utf8(d + 2, n - 2, false, path);
  if (n >= 2 && d[0] == 0xfe && d[1] == 0xff) return utf16_to_utf8(d + 2, n - 2, true, path);
  // No BOM: ASCII text written as UTF-16 has a zero in every other byte.
  if (n >= 2 && d[0] != 0 && d[1] == 0) return utf16_to_utf8(d, n, false, path);
  if (n >= 2 && d[0] == 0 && d[1] != 0) return utf16_to_utf8(d, n, true, path);
  std::string text(d, d + n);
  if (valid_utf8(text)) return text;
  *note = "not UTF-8: read as Latin-1";
  return latin1_to_utf8(text);
}

void LineCursor::skip_space() {
  while (p < end && (*p == ' ' || *p == '\t' || *p == '\r')) ++p;
}

bool LineCursor::at_line_end() {
  skip_space();
  return p >= end || *p == '\n' || *p == '#';
}

std::string LineCursor::word() {
  skip_space();
  const char* s = p;
  while (p < end && !std::isspace(static_cast<unsigned char>(*p))) ++p;
  return std::string(s, p);
}

std::string LineCursor::rest_of_line() {
  skip_space();
  const char* s = p;
  while (p < end && *p != '\n') ++p;
  const char* e = p;
  while (e > s && (e[-1] == '\r' || e[-1] == ' ' || e[-1] == '\t')) --e;
  return std::string(s, e);
}

bool LineCursor::number(float* out) {
  skip_space();
  auto r = std::from_chars(p, end, *out);
  if (r.ec == std::errc::result_out_of_range) {  // keep huge values as inf, not an error
    *out = static_cast<float>(std::strtod(std::string(p, r.ptr).c_str(), nullptr));
  } else if (r.ec != std::errc()) {
    // from_chars rejects a leading '+' and "nan"/"inf" spellings some exporters use.
    // A malformed tail ("3.1+e2") is left unread, as assimp reads it.
    const char* s = p;
    std::string w = word();
    char* e = nullptr;
    if (!w.empty()) *out = std::strtof(w.c_str(), &e);
    p = s + (e ? e - w.c_str() : 0);
    return p != s;
  }
  p = r.ptr;
  return true;
}

void LineCursor::next_line() {
  while (p < end && *p != '\n') ++p;
  if (p < end) ++p;
}

std::vector<Token> split_tokens(const std::string& text) {
  std::vector<Token> out;
  size_t i = 0;
  while (i < text.size()) {
    if (std::isspace(static_cast<unsigned char>(text[i]))) {
      ++i;
      continue;
    }
    Token t;
    t.begin = i;
    if (text[i] == '"') {
      size_t close = text.find('"', i + 1);
      if (close == std::string::npos) close = text.size();
      t.text = text.substr(i + 1, close - i - 1);
      i = close + 1;
    } else {
      while (i < text.size() && !std::isspace(static_cast<unsigned char>(text[i]))) ++i;
      t.text = text.substr(t.begin, i - t.begin);
    }
    out.push_back(std::move(t));
  }
  return out;
}

}  // namespace vt::scene::detail
