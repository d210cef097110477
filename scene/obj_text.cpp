// Text and file names as OBJ/MTL exporters write them (see scene/obj_mtl.h).
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <filesystem>

#include "scene/obj_mtl.h"

namespace vt::scene::detail {

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
