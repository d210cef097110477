// AC3D (.ac, .ac3d) and TORCS / Speed Dreams ACC (.acc): FlightGear's, TORCS's and CRRCSim's
// models. Read here rather than through assimp 5.2, which coerces ACC's triangle strips
// (surface type 4) into polygons (wrong triangles, silently) and takes an object's last
// `texture` line, where ACC lists the base texture first and then its extra layers.
//
// What the games' renderers (PLIB, OpenSceneGraph) draw, mapped onto the scene model:
// - an OBJECT is a node (`loc` then `rot`, relative to its parent); its surfaces become one
//   primitive per (material, two-sided) pair; polygons are ear-clipped, strips unrolled (their
//   joining triangles, which repeat a vertex, dropped), lines skipped with a count;
// - a material's `rgb` is the base colour factor and `trans` its transparency (1 - alpha);
//   `emis` is emission modulated by the object's texture (fixed-function GL_MODULATE), so it
//   becomes an emissive factor with the base texture as its map;
// - the object's first `texture` is its base colour map, with `texrep`/`texoff` applied to its
//   UVs; ACC's further layers (tiled, skids, shad) are ignored with a count; a texture with an
//   alpha channel blends, as those renderers draw it;
// - ACC vertex normals (six numbers a vertex) are kept; without them a shaded surface (SURF flag
//   0x10) is smoothed within the object's `crease` angle, a flat one takes its faces' normals.
// Names are as written (load_scene makes them UTF-8); texture paths as the disk spells them.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>
#include <tuple>

#include "common/vec.h"
#include "scene/image_load.h"
#include "scene/obj_mtl.h"
#include "scene/scene_io_util.h"

namespace vt::scene::detail {
namespace {

constexpr int kMaxDepth = 1024;
constexpr const char* kNoTexture = "empty_texture_no_mapping";  // ACC's placeholder layer
constexpr const char* kNullName = "(null)";

enum SurfaceType { kPolygon = 0, kClosedLine = 1, kLine = 2, kTriangleStrip = 4 };
constexpr unsigned kSurfaceShaded = 0x10, kSurfaceTwoSided = 0x20;  // SURF flags

struct AcMaterial {
  std::string name;
  Vec3 rgb = {1, 1, 1};
  Vec3 emissive = {0, 0, 0};
  float trans = 0;
};

// One object's geometry as read, before its surfaces become primitives.
struct AcObject {
  std::string name;
  std::string texture;  // the base layer as written; empty when none
  bool texture_seen = false;
  Vec2 texrep = {1, 1}, texoff = {0, 0};
  std::array<double, 9> rot = {1, 0, 0, 0, 1, 0, 0, 0, 1};  // row-major
  Vec3 loc = {0, 0, 0};
  std::vector<Vec3> vertices, normals;  // normals: all or none
  float crease = 61;                    // degrees; OpenSceneGraph's default
};

// One triangle of a surface, its corners as the scene takes them (UVs with texrep, texoff and
// the v flip applied; ACC's normals when the file gives them).
struct AcTriangle {
  int mat = 0;
  unsigned flags = 0;
  std::array<uint32_t, 3> vertex{};  // indices into the object's vertices, for smoothing
  std::array<Vec3, 3> position{};
  std::array<Vec2, 3> uv{};
  std::array<Vec3, 3> normal{};
  bool has_normals = false;
};

// A primitive being filled: vertices shared by identical (vertex, uv, normal).
struct PrimitiveBuilder {
  Primitive prim;
  std::map<std::tuple<uint32_t, float, float, float, float, float, float, float, float>, uint32_t>
      index_of;
};

Vec3d v3(const Vec3& a) {
  return {a[0], a[1], a[2]};
}

// Ear clipping in the polygon's own plane (projected along the axis its Newell normal is
// largest on), so concave outlines (FlightGear's buildings) keep their shape; a polygon that
// has no ear left (self-intersecting) is fanned from there. `out` gets corner indices.
// Polygons of more corners are fanned: clipping costs up to n^3 steps.
constexpr size_t kMaxClippedCorners = 1024;

void triangulate_polygon(const std::vector<Vec3>& p, std::vector<std::array<size_t, 3>>* out) {
  const size_t n = p.size();
  if (n == 3 || n > kMaxClippedCorners) {
    for (size_t i = 1; i + 1 < n; ++i) out->push_back({0, i, i + 1});
    return;
  }
  double normal[3] = {0, 0, 0};
  for (size_t i = 0; i < n; ++i) {
    const Vec3& a = p[i];
    const Vec3& b = p[(i + 1) % n];
    normal[0] += (double(a[1]) - b[1]) * (double(a[2]) + b[2]);
    normal[1] += (double(a[2]) - b[2]) * (double(a[0]) + b[0]);
    normal[2] += (double(a[0]) - b[0]) * (double(a[1]) + b[1]);
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(normal[k]) > std::abs(normal[axis])) axis = k;
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const double orientation = normal[axis] < 0 ? -1.0 : 1.0;
  auto turn = [&](size_t a, size_t b, size_t c) {  // > 0: a left turn in the plane
    return orientation * ((double(p[b][u]) - p[a][u]) * (double(p[c][v]) - p[a][v]) -
                          (double(p[b][v]) - p[a][v]) * (double(p[c][u]) - p[a][u]));
  };
  std::vector<size_t> left(n);
  for (size_t i = 0; i < n; ++i) left[i] = i;
  if (normal[axis] == 0 || !std::isfinite(normal[axis])) left.clear();  // no plane: fan below
  while (left.size() > 3) {
    bool clipped = false;
    for (size_t i = 0; i < left.size() && !clipped; ++i) {
      const size_t a = left[(i + left.size() - 1) % left.size()], b = left[i],
                   c = left[(i + 1) % left.size()];
      if (turn(a, b, c) <= 0) continue;  // reflex or flat corner
      bool inside = false;
      for (size_t q : left) {
        if (q == a || q == b || q == c) continue;
        if (turn(a, b, q) >= 0 && turn(b, c, q) >= 0 && turn(c, a, q) >= 0) {
          inside = true;
          break;
        }
      }
      if (inside) continue;
      out->push_back({a, b, c});
      left.erase(left.begin() + std::ptrdiff_t(i));
      clipped = true;
    }
    if (!clipped) break;
  }
  if (left.size() == 3) {
    out->push_back({left[0], left[1], left[2]});
    return;
  }
  if (left.empty()) {
    for (size_t i = 0; i < n; ++i) left.push_back(i);
  }
  for (size_t i = 1; i + 1 < left.size(); ++i) out->push_back({left[0], left[i], left[i + 1]});
}

// Whether the image file has alpha that carries data; false when it cannot be opened (the bake,
// which reads it, reports that).
bool has_alpha_channel(const std::string& path) {
  std::string error;
  std::unique_ptr<OIIO::ImageInput> in = open_image_input(path, error);
  if (!in) return false;
  Expected<int> channels = data_channels(*in);
  return channels.ok() && (*channels == 2 || *channels >= 4);
}

class Ac3dReader {
 public:
  Ac3dReader(const std::string& path, std::string text)
      : path_(path), folder_(parent_folder(path)), text_(std::move(text)) {
    scene_.source_path = path;
  }

  Expected<Scene> read() {
    if (!next_line() || line_.rfind("AC3D", 0) != 0)
      return Error(ErrorCode::kCorrupt, path_ + ": not an AC3D file (no 'AC3D' header)");
    while (next_line()) {
      if (tokens_.empty()) continue;
      const std::string& key = tokens_[0].text;
      if (key == "MATERIAL") {
        VT_RETURN_IF_ERROR(material());
      } else if (key == "OBJECT") {
        VT_ASSIGN_OR_RETURN(int root, object(0));
        scene_.roots.push_back(root);
      } else {
        unknown(key);
      }
    }
    if (scene_.roots.empty()) return Error(ErrorCode::kCorrupt, path_ + ": no OBJECT: no model");
    if (triangles_ == 0)
      return Error(ErrorCode::kInvalidArgument,
                   path_ + ": no surfaces: nothing to bake" +
                       (lines_ > 0 ? " (the file holds " + std::to_string(lines_) + " lines only)"
                                   : std::string()));
    summarise();
    untexture_surfaces_without_uvs(&scene_);
    return std::move(scene_);
  }

 private:
  void warn(const std::string& what) { scene_.warnings.push_back(path_ + ": " + what); }
  Status corrupt(const std::string& what) const {
    return Error(ErrorCode::kCorrupt, path_ + ":" + std::to_string(line_number_) + ": " + what);
  }
  void unknown(const std::string& key) {
    if (unknown_.insert(key).second && unknown_.size() <= 8)
      warn("line " + std::to_string(line_number_) + ": '" + key + "' is not AC3D; ignored");
  }

  // The next line (without its end) split into tokens; false at the end of the file.
  bool next_line() {
    if (pos_ >= text_.size()) return false;
    size_t end = text_.find('\n', pos_);
    if (end == std::string::npos) end = text_.size();
    line_.assign(text_, pos_, end - pos_);
    if (!line_.empty() && line_.back() == '\r') line_.pop_back();
    pos_ = std::min(end + 1, text_.size());
    ++line_number_;
    tokens_ = split_tokens(line_);
    return true;
  }

  // Token i as a finite number; false when there is none or it is not one (NaN and infinity
  // included: every caller refuses them or does without).
  bool number(size_t i, double* out) const {
    if (i >= tokens_.size()) return false;
    const char* s = tokens_[i].text.c_str();
    char* end = nullptr;
    *out = std::strtod(s, &end);
    return end != s && std::isfinite(*out);
  }
  template <size_t N, class T>
  Status numbers(size_t first, std::array<T, N>* out, const char* what) const {
    for (size_t k = 0; k < N; ++k) {
      double v;
      if (!number(first + k, &v)) return corrupt(std::string("bad '") + what + "' line");
      (*out)[k] = T(v);
    }
    return Status::Ok();
  }
  Expected<size_t> count(const char* what) const {
    double v;
    if (!number(1, &v) || !(v >= 0) || v > 1e9) return corrupt(std::string("bad '") + what + "'");
    return size_t(v);
  }

  Status material() {
    AcMaterial m;
    m.name = tokens_.size() > 1 ? tokens_[1].text : "";
    for (size_t i = 2; i < tokens_.size(); ++i) {
      const std::string& key = tokens_[i].text;
      if (key == "rgb" || key == "emis") {
        VT_RETURN_IF_ERROR(numbers(i + 1, key == "rgb" ? &m.rgb : &m.emissive, "MATERIAL"));
        i += 3;
      } else if (key == "trans") {
        double t;
        if (!number(i + 1, &t)) return corrupt("bad 'MATERIAL' line");
        m.trans = float(std::clamp(t, 0.0, 1.0));
        ++i;
      } else if (key == "amb" || key == "spec") {
        i += 3;  // fixed-function lighting terms: no place in a PBR material
      } else if (key == "shi") {
        ++i;
      }
    }
    materials_.push_back(m);
    return Status::Ok();
  }

  // The OBJECT whose header is the current line, its children included; returns its node.
  Expected<int> object(int depth) {
    if (depth > kMaxDepth) return corrupt("objects nested deeper than 1024 levels");
    const std::string kind = tokens_.size() > 1 ? tokens_[1].text : "";
    if (kind == "light") ++lights_;
    AcObject o;
    std::vector<AcTriangle> triangles;  // every surface's, made into primitives at `kids`
    const int node_index = int(scene_.nodes.size());
    scene_.nodes.emplace_back();
    while (true) {
      if (!next_line()) return corrupt("the file ends inside an OBJECT (no 'kids' line)");
      if (tokens_.empty()) continue;
      const std::string& key = tokens_[0].text;
      if (key == "name") {
        o.name = tokens_.size() > 1 ? tokens_[1].text : "";
      } else if (key == "data") {
        VT_ASSIGN_OR_RETURN(size_t bytes, count("data"));
        skip_bytes(bytes);
      } else if (key == "texture") {
        if (take_texture(&o, tokens_.size() > 1 ? tokens_[1].text : "")) ++ignored_layers_;
      } else if (key == "texrep" || key == "texoff") {
        std::array<float, 2> v{};
        VT_RETURN_IF_ERROR(numbers(1, &v, key.c_str()));
        (key == "texrep" ? o.texrep : o.texoff) = {v[0], v[1]};
      } else if (key == "rot") {
        VT_RETURN_IF_ERROR(numbers(1, &o.rot, "rot"));
      } else if (key == "loc") {
        VT_RETURN_IF_ERROR(numbers(1, &o.loc, "loc"));
      } else if (key == "crease") {
        double degrees;
        if (number(1, &degrees) && degrees >= 0 && degrees <= 180) o.crease = float(degrees);
      } else if (key == "subdiv") {
        double levels = 0;
        if (number(1, &levels) && levels > 0) ++subdivided_;
      } else if (key == "numvert") {
        VT_RETURN_IF_ERROR(vertices(&o));
      } else if (key == "numsurf") {
        VT_RETURN_IF_ERROR(surfaces(o, &triangles));
      } else if (key == "kids") {
        VT_ASSIGN_OR_RETURN(size_t kids, count("kids"));
        finish_object(node_index, o, triangles);
        for (size_t k = 0; k < kids; ++k) {
          // TORCS's track maker overcounts `kids`: PLIB and OpenSceneGraph draw what is there.
          do {
            if (!next_line()) {
              missing_children_ += kids - k;
              return node_index;
            }
          } while (tokens_.empty());
          if (tokens_[0].text != "OBJECT")
            return corrupt("'" + tokens_[0].text + "' where child " + std::to_string(k + 1) +
                           " of OBJECT '" + o.name + "' should start");
          VT_ASSIGN_OR_RETURN(int child, object(depth + 1));
          scene_.nodes[node_index].children.push_back(child);
        }
        return node_index;
      } else if (key != "url" && key != "hidden" && key != "locked" && key != "folded" &&
                 key != "shader") {
        unknown(key);
      }
    }
  }

  // The first texture line is the base layer; true for a later line that names an image (a
  // layer this bake ignores). ACC's placeholder and "(null)" (a track exporter printing a missing
  // name: TORCS's g-track-3) mean no texture.
  bool take_texture(AcObject* o, const std::string& file) {
    const bool none = file.empty() || file == kNoTexture || file == kNullName;
    if (o->texture_seen) return !none;
    o->texture_seen = true;
    null_textures_ += file == kNullName;
    if (!none) o->texture = file;
    return false;
  }

  // `data` is followed by a line break and that many bytes (which may hold line breaks).
  void skip_bytes(size_t bytes) {
    const size_t end = std::min(text_.size(), pos_ + bytes);
    line_number_ += size_t(std::count(text_.begin() + std::ptrdiff_t(pos_),
                                      text_.begin() + std::ptrdiff_t(end), '\n'));
    pos_ = end;
  }

  Status vertices(AcObject* o) {
    VT_ASSIGN_OR_RETURN(size_t n, count("numvert"));
    o->vertices.clear();
    o->normals.clear();
    bool all_normals = true;
    for (size_t i = 0; i < n; ++i) {
      if (!next_line())
        return corrupt("the file ends after " + std::to_string(i) + " of " + std::to_string(n) +
                       " vertices");
      double v[6];
      for (int k = 0; k < 3; ++k)
        if (!number(size_t(k), &v[k])) return corrupt("bad vertex");
      o->vertices.push_back({float(v[0]), float(v[1]), float(v[2])});
      all_normals = all_normals && number(3, &v[3]) && number(4, &v[4]) && number(5, &v[5]);
      if (all_normals) o->normals.push_back({float(v[3]), float(v[4]), float(v[5])});
    }
    if (!all_normals) o->normals.clear();
    return Status::Ok();
  }

  Status surfaces(const AcObject& o, std::vector<AcTriangle>* out) {
    VT_ASSIGN_OR_RETURN(size_t n, count("numsurf"));
    for (size_t s = 0; s < n; ++s) {
      do {
        if (!next_line()) return corrupt("the file ends inside surface " + std::to_string(s + 1));
      } while (tokens_.empty());
      if (tokens_[0].text != "SURF")
        return corrupt("'" + tokens_[0].text + "' where SURF should be");
      const unsigned flags =
          unsigned(std::strtoul(tokens_.size() > 1 ? tokens_[1].text.c_str() : "", nullptr, 0));
      int mat = 0;
      std::vector<uint32_t> refs;
      std::vector<Vec2> uvs;
      while (true) {
        if (!next_line()) return corrupt("the file ends inside surface " + std::to_string(s + 1));
        if (tokens_.empty()) continue;
        if (tokens_[0].text == "mat") {
          double m;
          if (!number(1, &m) || m < 0 || m >= double(materials_.size()))
            return corrupt("surface material '" + (tokens_.size() > 1 ? tokens_[1].text : "") +
                           "' is not one of the file's " + std::to_string(materials_.size()) +
                           " materials");
          mat = int(m);
        } else if (tokens_[0].text == "refs") {
          VT_ASSIGN_OR_RETURN(size_t count_refs, count("refs"));
          for (size_t r = 0; r < count_refs; ++r) {
            if (!next_line()) return corrupt("the file ends inside a surface's refs");
            double index, u = 0, v = 0;
            if (!number(0, &index) || index < 0 || index >= double(o.vertices.size()))
              return corrupt("surface refers to vertex '" +
                             (tokens_.empty() ? std::string() : tokens_[0].text) + "' of " +
                             std::to_string(o.vertices.size()));
            // ACC lists a pair for each texture layer: the first is the base's.
            if (tokens_.size() > 1 && (!number(1, &u) || !number(2, &v)))
              return corrupt("bad texture coordinates '" + tokens_[1].text + "'");
            refs.push_back(uint32_t(index));
            uvs.push_back({float(u), float(v)});
          }
          break;
        } else {
          return corrupt("'" + tokens_[0].text + "' inside a surface (expected mat or refs)");
        }
      }
      add_surface(o, flags, mat, refs, uvs, out);
    }
    return Status::Ok();
  }

  void add_surface(const AcObject& o, unsigned flags, int mat, const std::vector<uint32_t>& refs,
                   const std::vector<Vec2>& uvs, std::vector<AcTriangle>* out) {
    const unsigned type = flags & 0xf;
    if (type == kClosedLine || type == kLine) {
      ++lines_;
      return;
    }
    if (type != kPolygon && type != kTriangleStrip) {
      ++unknown_surfaces_;
      return;
    }
    if (refs.size() < 3) {
      ++short_surfaces_;
      return;
    }
    std::vector<std::array<size_t, 3>> triangles;
    if (type == kTriangleStrip) {
      for (size_t i = 0; i + 2 < refs.size(); ++i) {
        // A triangle that repeats a vertex joins two runs of the strip: no surface.
        if (refs[i] == refs[i + 1] || refs[i + 1] == refs[i + 2] || refs[i] == refs[i + 2])
          continue;
        triangles.push_back(i % 2 == 0 ? std::array<size_t, 3>{i, i + 1, i + 2}
                                       : std::array<size_t, 3>{i + 1, i, i + 2});
      }
    } else {
      if (refs.size() > kMaxClippedCorners) ++fanned_polygons_;
      std::vector<Vec3> corners;
      for (uint32_t r : refs) corners.push_back(o.vertices[r]);
      triangulate_polygon(corners, &triangles);
    }
    for (const auto& t : triangles) {
      AcTriangle& tri = out->emplace_back();
      tri.mat = mat;
      tri.flags = flags;
      tri.has_normals = !o.normals.empty();
      for (int k = 0; k < 3; ++k) {
        const uint32_t r = refs[t[size_t(k)]];
        const Vec2& uv = uvs[t[size_t(k)]];
        tri.vertex[size_t(k)] = r;
        tri.position[size_t(k)] = o.vertices[r];
        // AC3D's UVs have v up, and texrep/texoff scale and move them; the scene's have v down.
        tri.uv[size_t(k)] = {uv[0] * o.texrep[0] + o.texoff[0],
                             1.0f - (uv[1] * o.texrep[1] + o.texoff[1])};
        if (tri.has_normals) tri.normal[size_t(k)] = o.normals[r];
      }
    }
    triangles_ += triangles.size();
  }

  // Normals where the file gives none, as AC3D's renderers make them: a shaded surface's corner
  // takes the area-weighted normals of the object's shaded triangles at that vertex within the
  // crease angle of its own, a flat surface its triangle's.
  static void make_normals(const AcObject& o, std::vector<AcTriangle>* triangles) {
    // Each triangle's normal weighted by its area (twice it), and of unit length (zero when it
    // has no area).
    std::vector<Vec3d> face(triangles->size()), unit(triangles->size());
    std::multimap<uint32_t, size_t> at_vertex;
    for (size_t t = 0; t < triangles->size(); ++t) {
      const AcTriangle& tri = (*triangles)[t];
      const Vec3d p0 = v3(tri.position[0]);
      face[t] = cross(v3(tri.position[1]) - p0, v3(tri.position[2]) - p0);
      unit[t] = normalized(face[t], Vec3d{});
      if (tri.flags & kSurfaceShaded)
        for (uint32_t v : tri.vertex) at_vertex.emplace(v, t);
    }
    const double min_cos = std::cos(double(o.crease) * M_PI / 180.0);
    for (size_t t = 0; t < triangles->size(); ++t) {
      AcTriangle& tri = (*triangles)[t];
      if (tri.has_normals) continue;
      const Vec3d own = normalized(face[t], Vec3d{0, 0, 1});
      for (int k = 0; k < 3; ++k) {
        Vec3d sum = face[t];
        if (tri.flags & kSurfaceShaded) {
          sum = {};
          const auto [first, last] = at_vertex.equal_range(tri.vertex[size_t(k)]);
          for (auto it = first; it != last; ++it)
            if (dot(unit[t], unit[it->second]) >= min_cos - 1e-6) sum = sum + face[it->second];
        }
        const Vec3d n = normalized(sum, own);
        tri.normal[size_t(k)] = {float(n.x), float(n.y), float(n.z)};
      }
    }
  }

  // The node's transform and name, and a mesh of its primitives when it has any.
  void finish_object(int node_index, const AcObject& o, std::vector<AcTriangle>& triangles) {
    Node& node = scene_.nodes[size_t(node_index)];
    node.name = o.name;
    const auto& r = o.rot;  // row-major; Mat4 is column-major
    node.local = {r[0], r[3], r[6], 0, r[1],     r[4],     r[7],     0,
                  r[2], r[5], r[8], 0, o.loc[0], o.loc[1], o.loc[2], 1};
    if (triangles.empty()) return;
    make_normals(o, &triangles);
    std::map<std::pair<int, bool>, PrimitiveBuilder> builders;
    for (const AcTriangle& tri : triangles) {
      PrimitiveBuilder& b = builders[{tri.mat, (tri.flags & kSurfaceTwoSided) != 0}];
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = tri.vertex[size_t(k)];
        const Vec2& uv = tri.uv[size_t(k)];
        const Vec3& n = tri.normal[size_t(k)];
        // The position is in the key too: a second `numvert` list reuses the indices.
        const Vec3& p = tri.position[size_t(k)];
        auto [it, added] =
            b.index_of.try_emplace({v, uv[0], uv[1], n[0], n[1], n[2], p[0], p[1], p[2]},
                                   uint32_t(b.prim.positions.size()));
        if (added) {
          b.prim.positions.push_back(tri.position[size_t(k)]);
          b.prim.normals.push_back(n);
          b.prim.uvs.resize(1);
          b.prim.uvs[0].push_back(uv);
        }
        b.prim.indices.push_back(it->second);
      }
    }
    Mesh mesh;
    mesh.name = o.name;
    for (auto& [key, b] : builders) {
      b.prim.material = material_for(key.first, key.second, o.texture);
      mesh.primitives.push_back(std::move(b.prim));
    }
    triangles.clear();
    scene_.meshes.push_back(std::move(mesh));
    node.mesh = int(scene_.meshes.size() - 1);
  }

  int material_for(int mat, bool two_sided, const std::string& texture) {
    auto [it, added] = material_of_.try_emplace({mat, two_sided, texture}, 0);
    if (!added) return it->second;
    // A surface without a `mat` line in a file without MATERIAL lines: AC3D's default, white.
    const AcMaterial src = size_t(mat) < materials_.size() ? materials_[size_t(mat)] : AcMaterial{};
    Material m;
    m.name = src.name;
    m.base_color_factor = {src.rgb[0], src.rgb[1], src.rgb[2], 1.0f - src.trans};
    m.metallic_factor = 0;
    m.roughness_factor = 1;
    m.double_sided = two_sided;
    if (src.trans > 0) m.alpha_mode = AlphaMode::kBlend;
    if (src.trans >= 1 && transparent_warned_.insert(src.name).second)
      warn("material '" + src.name + "': trans 1: its surfaces bake fully transparent");
    if (!texture.empty()) {
      m.base_color_texture.image = image_for(texture);
      if (image_has_alpha_[size_t(m.base_color_texture.image)]) m.alpha_mode = AlphaMode::kBlend;
    }
    m.emissive_factor = src.emissive;
    if (m.base_color_texture.valid() && src.emissive != Vec3{0, 0, 0})
      m.emissive_texture = m.base_color_texture;
    scene_.materials.push_back(std::move(m));
    return it->second = int(scene_.materials.size() - 1);
  }

  int image_for(const std::string& written) {
    auto [it, added] = image_of_.try_emplace(written, 0);
    if (!added) return it->second;
    Image image;
    image.name = written;
    image.uri = written;
    std::string note;
    image.path = resolve_written_path(folder_, written, &note);
    if (!note.empty()) warn("texture " + note);
    image_has_alpha_.push_back(has_alpha_channel(image.path));
    scene_.images.push_back(std::move(image));
    return it->second = int(scene_.images.size() - 1);
  }

  void summarise() {
    if (missing_children_ > 0)
      warn("the file ends " + std::to_string(missing_children_) +
           " child objects short of what its 'kids' lines announce (miscounted or cut short): "
           "the objects read are baked");
    if (lines_ > 0) warn(std::to_string(lines_) + " line surfaces skipped (no area)");
    if (null_textures_ > 0)
      warn(std::to_string(null_textures_) +
           " objects name their texture \"(null)\" (an exporter's missing name): they bake "
           "untextured");
    if (fanned_polygons_ > 0)
      warn(std::to_string(fanned_polygons_) + " polygons of over " +
           std::to_string(kMaxClippedCorners) + " corners fanned from their first (right only " +
           "where they are convex)");
    if (short_surfaces_ > 0)
      warn(std::to_string(short_surfaces_) + " surfaces of fewer than 3 vertices skipped");
    if (unknown_surfaces_ > 0)
      warn(std::to_string(unknown_surfaces_) + " surfaces of an unknown type skipped");
    if (ignored_layers_ > 0)
      warn(std::to_string(ignored_layers_) +
           " ACC texture layers after the base texture ignored (only the base bakes)");
    if (subdivided_ > 0)
      warn(std::to_string(subdivided_) + " objects marked for subdivision baked unsubdivided");
    if (lights_ > 0)
      warn(std::to_string(lights_) +
           " lights ignored (only glTF KHR_lights_punctual lights are baked)");
  }

  std::string path_, folder_, text_;
  size_t pos_ = 0, line_number_ = 0;
  std::string line_;
  std::vector<Token> tokens_;
  Scene scene_;
  std::vector<AcMaterial> materials_;
  std::map<std::tuple<int, bool, std::string>, int> material_of_;
  std::map<std::string, int> image_of_;
  std::vector<bool> image_has_alpha_;  // per scene image
  std::set<std::string> unknown_, transparent_warned_;
  uint64_t triangles_ = 0, lines_ = 0, short_surfaces_ = 0, unknown_surfaces_ = 0;
  uint64_t ignored_layers_ = 0, subdivided_ = 0, lights_ = 0, missing_children_ = 0;
  uint64_t fanned_polygons_ = 0, null_textures_ = 0;
};

}  // namespace

Expected<Scene> load_ac3d(const std::string& path) {
  VT_ASSIGN_OR_RETURN(auto bytes, read_file(path));
  // A byte-order mark or UTF-16 text (assimp's test models have both) reads as UTF-8. Text that
  // is not UTF-8 stays as it is: the reader takes its names as Latin-1 and keeps texture file
  // names as the disk spells them.
  std::string note;
  VT_ASSIGN_OR_RETURN(std::string text, decode_text(bytes, path, &note));
  if (!note.empty()) text.assign(bytes.begin(), bytes.end());
  bytes = {};
  return Ac3dReader(path, std::move(text)).read();
}

}  // namespace vt::scene::detail
