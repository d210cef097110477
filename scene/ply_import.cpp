// A small PLY reader for what Draco's PLY decoder refuses: `tristrips` elements (strips with -1
// restarts). Reads ascii, binary_little_endian and binary_big_endian; x/y/z of `vertex`, and
// `face` lists (fanned) or `tristrips` lists. Used as the fallback of load_ply.
#include <algorithm>
#include <cctype>
#include <cstring>
#include <sstream>

#include "scene/scene_io_util.h"

namespace vt::scene::detail {
namespace {

struct Property {
  std::string name, type, count_type;  // count_type non-empty for lists
};
struct Element {
  std::string name;
  size_t count = 0;
  std::vector<Property> props;
};

template <class T>
double load(const uint8_t* b) {
  T v;
  std::memcpy(&v, b, sizeof(T));
  return static_cast<double>(v);
}

// PLY's scalar types under both spellings (PLY 1.0 and the sized names).
struct ScalarType {
  const char* name;
  const char* sized_name;
  size_t size;
  double (*load)(const uint8_t*);
};
constexpr ScalarType kScalarTypes[] = {
    {"char", "int8", 1, load<int8_t>},    {"uchar", "uint8", 1, load<uint8_t>},
    {"short", "int16", 2, load<int16_t>}, {"ushort", "uint16", 2, load<uint16_t>},
    {"int", "int32", 4, load<int32_t>},   {"uint", "uint32", 4, load<uint32_t>},
    {"float", "float32", 4, load<float>}, {"double", "float64", 8, load<double>},
};

const ScalarType* scalar_type(const std::string& t) {
  for (const ScalarType& s : kScalarTypes)
    if (t == s.name || t == s.sized_name) return &s;
  return nullptr;
}

struct Reader {
  const uint8_t* p;
  const uint8_t* end;
  int format;  // 0 ascii, 1 little endian, 2 big endian
  bool ok = true;

  double binary(const std::string& t) {
    const ScalarType* type = scalar_type(t);
    if (!type || static_cast<size_t>(end - p) < type->size) {
      ok = false;
      return 0;
    }
    uint8_t b[8];
    std::memcpy(b, p, type->size);
    p += type->size;
    if (format == 2) std::reverse(b, b + type->size);
    return type->load(b);
  }
  double ascii() {
    while (p < end && std::isspace(*p)) ++p;
    const uint8_t* s = p;
    while (p < end && !std::isspace(*p)) ++p;
    if (s == p) {
      ok = false;
      return 0;
    }
    return std::strtod(std::string(s, p).c_str(), nullptr);
  }
  double value(const std::string& t) { return format == 0 ? ascii() : binary(t); }
};

}  // namespace

Expected<Scene> load_ply_own(const std::string& path) {
  VT_ASSIGN_OR_RETURN(auto bytes, read_file(path));
  std::string text(bytes.begin(), bytes.begin() + std::min<size_t>(bytes.size(), 1 << 16));
  size_t header_end = text.find("end_header");
  if (text.rfind("ply", 0) != 0 || header_end == std::string::npos)
    return Error(ErrorCode::kCorrupt, path + ": not a PLY file (no ply/end_header)");
  std::istringstream header(text.substr(0, header_end));
  std::vector<Element> elements;
  int format = -1;
  for (std::string line; std::getline(header, line);) {
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "format") {
      std::string f;
      ls >> f;
      format = f == "ascii"                  ? 0
               : f == "binary_little_endian" ? 1
               : f == "binary_big_endian"    ? 2
                                             : -1;
    } else if (word == "element") {
      Element e;
      ls >> e.name >> e.count;
      elements.push_back(e);
    } else if (word == "property" && !elements.empty()) {
      Property pr;
      ls >> pr.type;
      if (pr.type == "list") ls >> pr.count_type >> pr.type;
      ls >> pr.name;
      elements.back().props.push_back(pr);
    }
  }
  if (format < 0) return Error(ErrorCode::kCorrupt, path + ": unknown PLY format");
  size_t data = header_end + std::strlen("end_header");
  while (data < bytes.size() && bytes[data] != '\n') ++data;
  Reader r{bytes.data() + std::min(data + 1, bytes.size()), bytes.data() + bytes.size(), format};
  Primitive prim;
  for (const Element& e : elements) {
    // Never trust the count: each element needs at least one byte per entry.
    if (e.count > bytes.size())
      return Error(ErrorCode::kCorrupt, path + ": element " + e.name + " count exceeds the file");
    for (size_t i = 0; i < e.count && r.ok; ++i) {
      Vec3 pos = {0, 0, 0};
      for (const Property& pr : e.props) {
        if (!pr.count_type.empty()) {
          size_t n = static_cast<size_t>(r.value(pr.count_type));
          if (n > bytes.size())
            return Error(ErrorCode::kCorrupt, path + ": list length exceeds the file");
          std::vector<int64_t> list(n);
          for (size_t k = 0; k < n && r.ok; ++k) list[k] = static_cast<int64_t>(r.value(pr.type));
          if (e.name == "face" && (pr.name == "vertex_indices" || pr.name == "vertex_index")) {
            for (size_t k = 2; k < n; ++k)
              prim.indices.insert(prim.indices.end(), {static_cast<uint32_t>(list[0]),
                                                       static_cast<uint32_t>(list[k - 1]),
                                                       static_cast<uint32_t>(list[k])});
          } else if (e.name == "tristrips" &&
                     (pr.name == "vertex_indices" || pr.name == "vertex_index")) {
            size_t start = 0;
            for (size_t k = 0; k <= n; ++k) {
              if (k < n && list[k] >= 0) continue;
              for (size_t j = start + 2; j < k; ++j) {  // alternate winding along the strip
                uint32_t a = static_cast<uint32_t>(list[j - 2]),
                         b = static_cast<uint32_t>(list[j - 1]), c = static_cast<uint32_t>(list[j]);
                if ((j - start) % 2 == 0)
                  prim.indices.insert(prim.indices.end(), {a, b, c});
                else
                  prim.indices.insert(prim.indices.end(), {b, a, c});
              }
              start = k + 1;
            }
          }
        } else {
          double v = r.value(pr.type);
          if (e.name == "vertex") {
            if (pr.name == "x") pos[0] = static_cast<float>(v);
            if (pr.name == "y") pos[1] = static_cast<float>(v);
            if (pr.name == "z") pos[2] = static_cast<float>(v);
          }
        }
      }
      if (e.name == "vertex") prim.positions.push_back(pos);
    }
    if (!r.ok) return Error(ErrorCode::kCorrupt, path + ": PLY data ends inside element " + e.name);
  }
  // Indices are range-checked by validate_geometry (callers); negative ones were cast to huge
  // values and fail that check with the triangle named.
  std::vector<Primitive> prims;
  prims.push_back(std::move(prim));
  return single_mesh_scene(path, "ply", std::move(prims));
}

}  // namespace vt::scene::detail
