// PLY import with vtbake's own reader: ascii, binary_little_endian and binary_big_endian;
// `vertex` x/y/z, normals (nx/ny/nz), texture coordinates (u/v, s/t, texture_u/texture_v,
// texture_s/texture_t; v up, as OBJ, so flipped to glTF's v down), colours (red/green/blue
// [/alpha] or diffuse_red/...; integers normalised by their type's maximum), `face` lists
// (fanned) and `tristrips` lists (-1 restarts). Draco's PLY reader is not used: it trusts the
// header (a binary file claiming 10^8 vertices with 3 present crashed it). Here the header is
// checked against the file size and the ceilings of import_budget.h before anything is
// allocated, and every index against the vertex count.
//
// Colours: PLY has no colour-space field; scanners and MeshLab write display colours, so the
// values are taken as sRGB-encoded and converted to linear (Primitive::colors is linear, like
// glTF's COLOR_0). Alpha stays as written.
#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <new>
#include <sstream>
#include <stdexcept>

#include "common/srgb.h"
#include "scene/import_budget.h"
#include "scene/scene_io_util.h"

namespace vt::scene::detail {
namespace {

template <class T>
double load(const uint8_t* b) {
  T v;
  std::memcpy(&v, b, sizeof(T));
  return static_cast<double>(v);
}

// PLY's scalar types under both spellings (PLY 1.0 and the sized names). `unit` maps an
// integer colour onto [0, 1].
struct ScalarType {
  const char* name;
  const char* sized_name;
  size_t size;
  double (*load)(const uint8_t*);
  double unit;
};
constexpr ScalarType kScalarTypes[] = {
    {"char", "int8", 1, load<int8_t>, 127.0},
    {"uchar", "uint8", 1, load<uint8_t>, 255.0},
    {"short", "int16", 2, load<int16_t>, 32767.0},
    {"ushort", "uint16", 2, load<uint16_t>, 65535.0},
    {"int", "int32", 4, load<int32_t>, 2147483647.0},
    {"uint", "uint32", 4, load<uint32_t>, 4294967295.0},
    {"float", "float32", 4, load<float>, 1.0},
    {"double", "float64", 8, load<double>, 1.0},
};

const ScalarType* scalar_type(const std::string& t) {
  for (const ScalarType& s : kScalarTypes)
    if (t == s.name || t == s.sized_name) return &s;
  return nullptr;
}

// What a vertex property means to the scene model.
enum Role : uint8_t { kSkip, kX, kY, kZ, kNx, kNy, kNz, kU, kV, kRed, kGreen, kBlue, kAlpha };

Role vertex_role(const std::string& n) {
  static const std::pair<const char*, Role> kNames[] = {
      {"x", kX},
      {"y", kY},
      {"z", kZ},
      {"nx", kNx},
      {"ny", kNy},
      {"nz", kNz},
      {"u", kU},
      {"v", kV},
      {"s", kU},
      {"t", kV},
      {"texture_u", kU},
      {"texture_v", kV},
      {"texture_s", kU},
      {"texture_t", kV},
      {"red", kRed},
      {"green", kGreen},
      {"blue", kBlue},
      {"alpha", kAlpha},
      {"diffuse_red", kRed},
      {"diffuse_green", kGreen},
      {"diffuse_blue", kBlue},
      {"diffuse_alpha", kAlpha},
  };
  for (const auto& [name, role] : kNames)
    if (n == name) return role;
  return kSkip;
}

struct Property {
  std::string name;
  const ScalarType* type = nullptr;
  const ScalarType* count_type = nullptr;  // set for lists
  Role role = kSkip;
};
struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> props;
  bool is_vertex() const { return name == "vertex"; }
  bool is_faces() const { return name == "face" || name == "tristrips"; }
};
struct Header {
  int format = -1;  // 0 ascii, 1 little endian, 2 big endian
  std::vector<Element> elements;
  size_t data = 0;  // offset of the first data byte
};

Status corrupt(const std::string& path, const std::string& what) {
  return Error(ErrorCode::kCorrupt, path + ": PLY: " + what);
}

bool is_index_list(const Element& e, const Property& p) {
  return e.is_faces() && p.count_type && (p.name == "vertex_indices" || p.name == "vertex_index");
}

Status parse_property(const std::string& path, std::istringstream& ls, Element* e) {
  Property pr;
  std::string type, count_type;
  ls >> type;
  if (type == "list") {
    ls >> count_type >> type;
    pr.count_type = scalar_type(count_type);
    if (!pr.count_type || pr.count_type->unit == 1.0)
      return corrupt(path, "element " + e->name + ": list count type '" + count_type +
                               "' is not an integer type");
  }
  ls >> pr.name;
  pr.type = scalar_type(type);
  if (!pr.type)
    return corrupt(path, "element " + e->name + " property '" + pr.name + "' has unknown type '" +
                             type.substr(0, 32) + "'");
  if (e->is_vertex() && !pr.count_type) pr.role = vertex_role(pr.name);
  e->props.push_back(pr);
  return Status::Ok();
}

Expected<Header> parse_header(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::string text(bytes.begin(), bytes.begin() + std::min<size_t>(bytes.size(), 1 << 16));
  size_t end = text.find("end_header");
  if (text.rfind("ply", 0) != 0 || end == std::string::npos)
    return Error(ErrorCode::kCorrupt, path + ": not a PLY file (no ply/end_header)");
  Header h;
  std::istringstream lines(text.substr(0, end));
  for (std::string line; std::getline(lines, line);) {
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "format") {
      std::string f;
      ls >> f;
      h.format = f == "ascii"                  ? 0
                 : f == "binary_little_endian" ? 1
                 : f == "binary_big_endian"    ? 2
                                               : -1;
    } else if (word == "element") {
      Element e;
      std::string count;
      ls >> e.name >> count;
      auto r = std::from_chars(count.data(), count.data() + count.size(), e.count);
      if (r.ec != std::errc() || r.ptr != count.data() + count.size())
        return corrupt(path,
                       "element " + e.name + " has no valid count ('" + count.substr(0, 32) + "')");
      h.elements.push_back(e);
    } else if (word == "property") {
      if (h.elements.empty()) return corrupt(path, "property before any element");
      VT_RETURN_IF_ERROR(parse_property(path, ls, &h.elements.back()));
    }
  }
  if (h.format < 0) return corrupt(path, "unknown format (not ascii or binary)");
  h.data = end + std::strlen("end_header");
  while (h.data < bytes.size() && bytes[h.data] != '\n') ++h.data;
  h.data = std::min(h.data + 1, bytes.size());
  return h;
}

// Every element's count against the least its entries can occupy in what is left of the file
// (binary: the scalar sizes and list counts; ascii: a character and a separator per value),
// and the vertex and face counts against the ceilings.
Status check_budget(const std::string& path, const Header& h, size_t file_size) {
  uint64_t left = file_size - h.data + (h.format == 0 ? 1 : 0);  // ascii: no final separator
  for (const Element& e : h.elements) {
    uint64_t unit = 0;
    for (const Property& p : e.props)
      unit += h.format == 0 ? 2 : (p.count_type ? p.count_type->size : p.type->size);
    std::string what = path + ": PLY element " + e.name;
    // Entries without properties occupy no bytes, so no file size bounds their count.
    if (e.count > 0 && e.props.empty())
      return corrupt(path, "element " + e.name + " has " + std::to_string(e.count) +
                               " entries but no properties");
    VT_RETURN_IF_ERROR(check_backed(what, e.count, unit, "the rest of the file", left));
    if (e.is_vertex()) VT_RETURN_IF_ERROR(check_ceiling(what, e.count, kMaxVertices, "vertices"));
    if (e.is_faces()) VT_RETURN_IF_ERROR(check_ceiling(what, e.count, kMaxIndices / 3, "faces"));
    left -= e.count * unit;
  }
  return Status::Ok();
}

struct Reader {
  const uint8_t* p;
  const uint8_t* end;
  int format;
  bool ok = true;

  double value(const ScalarType* t) {
    if (format != 0) {
      if (static_cast<size_t>(end - p) < t->size) return fail();
      uint8_t b[8];
      std::memcpy(b, p, t->size);
      p += t->size;
      if (format == 2) std::reverse(b, b + t->size);
      return t->load(b);
    }
    while (p < end && std::isspace(*p)) ++p;
    const uint8_t* s = p;
    while (p < end && !std::isspace(*p)) ++p;
    double v = 0;
    auto r = std::from_chars(reinterpret_cast<const char*>(s), reinterpret_cast<const char*>(p), v);
    if (s == p || r.ptr != reinterpret_cast<const char*>(p)) return fail();
    return v;
  }
  size_t bytes_left() const { return static_cast<size_t>(end - p); }
  double fail() {
    ok = false;
    return 0;
  }
};

// The scene model's arrays for the vertex element, sized once the header passed the budget.
struct VertexSink {
  bool normals = false, uvs = false, colors = false;
  Primitive* prim;

  void init(const Element& e) {
    for (const Property& p : e.props) {
      normals |= p.role == kNx || p.role == kNy || p.role == kNz;
      uvs |= p.role == kU || p.role == kV;
      colors |= p.role == kRed || p.role == kGreen || p.role == kBlue || p.role == kAlpha;
    }
    prim->positions.assign(e.count, {0, 0, 0});
    if (normals) prim->normals.assign(e.count, {0, 0, 0});
    if (uvs) prim->uvs.assign(1, std::vector<Vec2>(e.count, {0, 1}));
    if (colors) prim->colors.assign(e.count, {0, 0, 0, 1});
  }
  void set(size_t i, const Property& p, double v) {
    float f = static_cast<float>(v), c = static_cast<float>(v / p.type->unit);
    switch (p.role) {
      case kX:
      case kY:
      case kZ:
        prim->positions[i][p.role - kX] = f;
        break;
      case kNx:
      case kNy:
      case kNz:
        prim->normals[i][p.role - kNx] = f;
        break;
      case kU:
        prim->uvs[0][i][0] = f;
        break;
      case kV:
        prim->uvs[0][i][1] = 1.0f - f;
        break;
      case kRed:
      case kGreen:
      case kBlue:
        prim->colors[i][p.role - kRed] = srgb_to_linear(c);
        break;
      case kAlpha:
        prim->colors[i][3] = c;
        break;
      case kSkip:
        break;
    }
  }
};

// Appends the triangles of one face or strip list, each index checked against the vertices.
// An ASCII value as written ("1e+30", "nan"): shortest round-trip form.
std::string number_text(double v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

// A list entry as an integer; values outside int64 (and NaN) saturate, so that add_triangles
// refuses them as out-of-range vertices instead of the conversion being undefined.
int64_t saturated_int(double v) {
  if (v >= 9.2e18) return INT64_MAX;
  if (!(v > -9.2e18)) return INT64_MIN;
  return static_cast<int64_t>(v);
}

Status add_triangles(const std::string& path, const Element& e, uint64_t entry,
                     const std::vector<int64_t>& list, size_t vertices,
                     std::vector<uint32_t>* out) {
  bool strip = e.name == "tristrips";
  for (int64_t v : list)
    if ((v < 0 && !(strip && v == -1)) || v >= static_cast<int64_t>(vertices))
      return corrupt(path, e.name + " " + std::to_string(entry) + " uses vertex " +
                               std::to_string(v) + " but there are " + std::to_string(vertices));
  size_t n = list.size();
  VT_RETURN_IF_ERROR(check_ceiling(path + ": PLY " + e.name, uint64_t{out->size()} + 3 * n,
                                   kMaxIndices, "indices"));
  auto u = [&](size_t k) { return static_cast<uint32_t>(list[k]); };
  if (!strip) {
    for (size_t k = 2; k < n; ++k) out->insert(out->end(), {u(0), u(k - 1), u(k)});
    return Status::Ok();
  }
  for (size_t start = 0, k = 0; k <= n; ++k) {
    if (k < n && list[k] >= 0) continue;
    for (size_t j = start + 2; j < k; ++j) {  // alternate winding along the strip
      if ((j - start) % 2 == 0)
        out->insert(out->end(), {u(j - 2), u(j - 1), u(j)});
      else
        out->insert(out->end(), {u(j - 1), u(j - 2), u(j)});
    }
    start = k + 1;
  }
  return Status::Ok();
}

Status read_elements(const std::string& path, const Header& h, const std::vector<uint8_t>& bytes,
                     Primitive* prim) {
  Reader r{bytes.data() + h.data, bytes.data() + bytes.size(), h.format};
  size_t vertices = 0;
  for (const Element& e : h.elements)
    if (e.is_vertex()) vertices = e.count;
  VertexSink sink{.prim = prim};
  std::vector<int64_t> list;
  for (const Element& e : h.elements) {
    if (e.is_vertex()) sink.init(e);
    for (uint64_t i = 0; i < e.count && r.ok && !e.props.empty(); ++i) {
      for (const Property& pr : e.props) {
        if (!pr.count_type) {
          double v = r.value(pr.type);
          if (e.is_vertex()) sink.set(i, pr, v);
          continue;
        }
        double n = r.value(pr.count_type);
        size_t least = h.format == 0 ? 2 : pr.type->size;
        // Written so that NaN fails too; the count is printed as read (it may not fit an int).
        if (!(n >= 0 && n <= static_cast<double>(r.bytes_left() / least + 1)))
          return corrupt(path, e.name + " " + std::to_string(i) + ": a list of " + number_text(n) +
                                   " entries runs past the end of the file");
        list.resize(static_cast<size_t>(n));
        for (int64_t& v : list) v = saturated_int(r.value(pr.type));
        if (r.ok && is_index_list(e, pr))
          VT_RETURN_IF_ERROR(add_triangles(path, e, i, list, vertices, &prim->indices));
      }
    }
    if (!r.ok) return corrupt(path, "data ends inside element " + e.name);
  }
  return Status::Ok();
}

}  // namespace

Expected<Scene> load_ply(const std::string& path) {
  VT_ASSIGN_OR_RETURN(auto bytes, read_file(path));
  VT_ASSIGN_OR_RETURN(Header h, parse_header(path, bytes));
  bool faces = false;
  uint64_t vertices = 0;
  for (const Element& e : h.elements) {
    if (e.is_vertex()) vertices = e.count;
    for (const Property& p : e.props) faces |= e.count > 0 && is_index_list(e, p);
  }
  if (!faces)
    return Error(ErrorCode::kUnsupported, "PLY: " + path + " has no faces (a point cloud of " +
                                              std::to_string(vertices) +
                                              " vertices): nothing to bake");
  VT_RETURN_IF_ERROR(check_budget(path, h, bytes.size()));
  Primitive prim;
  try {
    VT_RETURN_IF_ERROR(read_elements(path, h, bytes, &prim));
  } catch (const std::bad_alloc&) {
    return Error(ErrorCode::kResourceLimit, path + ": PLY: out of memory");
  }
  std::vector<Primitive> prims;
  prims.push_back(std::move(prim));
  return single_mesh_scene(path, "ply", std::move(prims));
}

}  // namespace vt::scene::detail
