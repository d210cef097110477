// Wavefront OBJ: one primitive per `usemtl` name (two where some of its faces have no `vt`),
// polygons fanned into triangles, vertices shared by identical (position, uv, normal) triples.
// OBJ's v-up UVs become glTF's v-down. Materials come from the MTL libraries
// (scene/mtl_import.cpp), resolved by name once the whole file is read, so `usemtl` may come
// before `mtllib`. Faces, too, are built once the whole file is read: a positive index may name
// a `v`, `vt` or `vn` written further down (Sweet Home 3D's catalogue has such files, and the
// readers that load everything first accept them); a negative one counts back from the line.
// A corner without `vn` gets its normal from the smoothing groups, as Blender and 3ds Max read
// them: the face's own under `s off` (flat), else the area-weighted mean over the faces of its
// group that share the `v`, so that the bake, the validator and the unwrapped scene all shade
// the model as its author saw it.
// Vertex colours (`v x y z r g b [a]`) are read as sRGB-encoded, the way MeshLab, ZBrush and
// Blender write them (8-bit colours over 255, what their viewports show), and stored linear.
// A file with a component above 1 wrote 0..255 and is scaled (with a warning).
#include <algorithm>
#include <filesystem>
#include <set>
#include <unordered_map>

#include "common/srgb.h"
#include "common/vec.h"
#include "scene/obj_mtl.h"
#include "scene/scene_io_util.h"
#include "scene/tangent_frame.h"

namespace vt::scene::detail {
namespace {

// A vertex: v, vt, vn (0 = none) and, for a normal made from the smoothing groups, the group
// (smooth) or the face (flat: -1 - face), else 0.
using VertexKey = std::array<int, 4>;
struct KeyHash {
  size_t operator()(const VertexKey& k) const {
    return (static_cast<size_t>(k[0]) * 73856093u) ^ (static_cast<size_t>(k[1]) * 19349663u) ^
           (static_cast<size_t>(k[2]) * 83492791u) ^ (static_cast<size_t>(k[3]) * 2654435761u);
  }
};

// The triangles of one `usemtl` name, with UVs or without: a face with no `vt` has no place in
// its material's textures, so it gets a primitive of its own that bakes from the factors
// (untexture_surfaces_without_uvs) instead of reading the texel at UV (0, 0).
struct Builder {
  std::string material_name;
  Primitive prim;
  std::unordered_map<VertexKey, uint32_t, KeyHash> map;
  std::vector<int> position_of;  // per vertex: its `v` (for colours, filled in at the end)
  bool any_uv = false;
};

class ObjReader {
 public:
  ObjReader(const std::string& path, const SceneLoadOptions& options)
      : path_(path), folder_(parent_folder(path)), options_(options) {
    scene_.source_path = path;
  }
  Status statement(const std::string& key, LineCursor* c);
  Expected<Scene> finish() &&;
  void warn(std::string what) { scene_.warnings.push_back(std::move(what)); }
  size_t line = 1;

 private:
  std::string where() const { return path_ + ":" + std::to_string(line); }
  Status vertex(LineCursor* c);
  Status face(LineCursor* c);
  Status build_faces();
  Status mtllib(const std::string& rest);
  Status load_library(const std::string& written);
  int material_index(const std::string& name);
  void fill_colors(Builder* b) const;

  std::string path_, folder_;
  SceneLoadOptions options_;
  Scene scene_;
  std::map<std::string, int> materials_;
  std::set<std::string> libraries_;  // loaded, by resolved path
  bool library_missing_ = false;
  std::vector<Vec3> v_, vn_;
  std::vector<Vec2> vt_;
  std::vector<Vec4> colors_;  // per `v`, as written; empty while no `v` had a colour
  float color_peak_ = 0.0f;
  std::vector<Builder> builders_;
  std::map<std::pair<std::string, bool>, size_t> builder_of_;  // (usemtl, has UVs) -> builder
  std::string current_;                                        // the current usemtl name
  size_t ignored_elements_ = 0;                                // points, lines, curves
  // Faces as read, built by build_faces: corners (v, vt, vn; 0 = none), 1-based and absolute.
  struct Face {
    size_t builder, line;
    uint32_t first, count;
    bool has_uv;    // every corner has a `vt`
    int smoothing;  // its `s` group, 0 = off
  };
  std::vector<std::array<int, 3>> corners_;
  std::vector<Face> faces_;
  int smoothing_ = 0;  // the current `s` group
};

Status ObjReader::vertex(LineCursor* c) {
  Vec3 p{};
  for (int k = 0; k < 3; ++k)
    if (!c->number(&p[k])) return Error(ErrorCode::kCorrupt, where() + ": bad vertex");
  float extra[4] = {1, 1, 1, 1};
  int n = 0;
  while (n < 4 && !c->at_line_end() && c->number(&extra[n])) ++n;
  v_.push_back(p);
  if (n >= 3) {  // x y z r g b [a]; a lone fourth number is the rational weight w
    if (colors_.empty()) colors_.assign(v_.size() - 1, Vec4{1, 1, 1, 1});
    if (n == 3) extra[3] = 1.0f;
    colors_.push_back({extra[0], extra[1], extra[2], extra[3]});
    color_peak_ = std::max({color_peak_, extra[0], extra[1], extra[2]});
  } else if (!colors_.empty()) {
    colors_.push_back({1, 1, 1, 1});
  }
  return Status::Ok();
}

Status ObjReader::face(LineCursor* c) {
  const size_t first = corners_.size();
  while (!c->at_line_end()) {
    std::string w = c->word();
    std::array<int, 3> idx = {0, 0, 0};
    int field = 0;
    size_t start = 0;
    for (size_t i = 0; i <= w.size(); ++i) {
      if (i == w.size() || w[i] == '/') {
        if (i > start && field < 3) idx[field] = std::atoi(w.c_str() + start);
        ++field;
        start = i + 1;
      }
    }
    const size_t counts[3] = {v_.size(), vt_.size(), vn_.size()};
    for (int k = 0; k < 3; ++k) {
      if (idx[k] < 0) idx[k] = static_cast<int>(counts[k]) + idx[k] + 1;
      // Positive indices past the elements read so far are checked once the file is read.
      if (idx[k] < 0 || (k == 0 && idx[k] == 0))
        return Error(ErrorCode::kCorrupt, where() + ": face index '" + w + "' out of range");
    }
    corners_.push_back(idx);
  }
  const size_t count = corners_.size() - first;
  if (count < 3) {
    corners_.resize(first);
    return Status::Ok();
  }
  const bool has_uv = std::all_of(corners_.begin() + first, corners_.end(),
                                  [](const auto& k) { return k[1] != 0; });
  auto [slot, added] = builder_of_.try_emplace({current_, has_uv}, builders_.size());
  if (added) builders_.emplace_back().material_name = current_;
  faces_.push_back({slot->second, line, uint32_t(first), uint32_t(count), has_uv, smoothing_});
  return Status::Ok();
}

Status ObjReader::build_faces() {
  const size_t counts[3] = {v_.size(), vt_.size(), vn_.size()};
  for (const Face& f : faces_) {
    for (uint32_t i = 0; i < f.count; ++i) {
      const auto& k = corners_[f.first + i];
      for (int e = 0; e < 3; ++e) {
        if (static_cast<size_t>(k[e]) <= counts[e]) continue;
        static const char* kNames[3] = {"v", "vt", "vn"};
        return Error(ErrorCode::kCorrupt,
                     path_ + ":" + std::to_string(f.line) + ": face index " + std::to_string(k[e]) +
                         " out of range (the file has " + std::to_string(counts[e]) + " '" +
                         kNames[e] + "' lines)");
      }
    }
  }
  // Normals for corners without `vn`: each face's (twice its area times its unit normal, summed
  // over its fan), and per (group, v) the sum over the group's faces.
  std::vector<Vec3d> face_normal(faces_.size());
  std::map<std::pair<int, int>, Vec3d> smooth;
  const double scale = unit_scale(v_);
  for (size_t i = 0; i < faces_.size(); ++i) {
    const Face& f = faces_[i];
    const auto* face = corners_.data() + f.first;
    bool wanted = false;
    for (uint32_t c = 0; c < f.count; ++c) wanted |= face[c][2] == 0;
    if (!wanted) continue;
    auto at = [&](uint32_t c) {
      const Vec3& p = v_[face[c][0] - 1];
      return Vec3d{p[0], p[1], p[2]} * scale;
    };
    for (uint32_t c = 1; c + 1 < f.count; ++c)
      face_normal[i] = face_normal[i] + cross(at(c) - at(0), at(c + 1) - at(0));
    if (f.smoothing == 0) continue;
    for (uint32_t c = 0; c < f.count; ++c) {
      Vec3d& sum = smooth[{f.smoothing, face[c][0]}];
      sum = sum + face_normal[i];
    }
  }
  for (size_t i = 0; i < faces_.size(); ++i) {
    const Face& f = faces_[i];
    Builder& b = builders_[f.builder];
    const auto* face = corners_.data() + f.first;
    auto vertex = [&](const std::array<int, 3>& k) {
      const int made = k[2] ? 0 : f.smoothing ? f.smoothing : -1 - static_cast<int>(i);
      const VertexKey key = {k[0], k[1], k[2], made};
      auto [it, inserted] = b.map.try_emplace(key, static_cast<uint32_t>(b.prim.positions.size()));
      if (inserted) {
        b.prim.positions.push_back(v_[k[0] - 1]);
        b.position_of.push_back(k[0] - 1);
        b.prim.uvs.resize(1);
        b.prim.uvs[0].push_back(f.has_uv ? vt_[k[1] - 1] : Vec2{0, 0});
        Vec3 n = k[2] ? vn_[k[2] - 1] : Vec3{0, 0, 0};
        if (!k[2]) {
          const Vec3d m = normalized(f.smoothing ? smooth[{f.smoothing, k[0]}] : face_normal[i],
                                     Vec3d{0, 0, 1});
          n = {float(m.x), float(m.y), float(m.z)};
        }
        b.prim.normals.push_back(n);
        b.any_uv |= f.has_uv;
      }
      return it->second;
    };
    const uint32_t first = vertex(face[0]);
    for (uint32_t c = 1; c + 1 < f.count; ++c) {
      b.prim.indices.push_back(first);
      b.prim.indices.push_back(vertex(face[c]));
      b.prim.indices.push_back(vertex(face[c + 1]));
    }
  }
  corners_ = {};
  faces_ = {};
  return Status::Ok();
}

Status ObjReader::load_library(const std::string& written) {
  std::string note;
  std::string file = resolve_written_path(folder_, written, &note);
  if (!libraries_.insert(file).second) return Status::Ok();
  VT_RETURN_IF_ERROR(
      check_inside_scene_tree(path_, file, "line " + std::to_string(line) + ": mtllib", options_));
  if (!note.empty()) scene_.warnings.push_back(where() + ": mtllib " + note);
  Status s = load_mtl(file, &scene_, &materials_);
  if (s.ok()) return Status::Ok();
  // As assimp does: a library that is not there is often the OBJ's own name with .mtl.
  std::string own = path_.substr(0, path_.size() - lower_extension(path_).size()) + "mtl";
  std::error_code ec;
  if (s.code() == ErrorCode::kNotFound && std::filesystem::is_regular_file(own, ec) &&
      libraries_.insert(own).second && load_mtl(own, &scene_, &materials_).ok()) {
    scene_.warnings.push_back(where() + ": mtllib '" + written + "' not found; using '" + own +
                              "' (the OBJ's name)");
    return Status::Ok();
  }
  library_missing_ = true;
  scene_.warnings.push_back(where() + ": mtllib '" + written + "': " + s.message() +
                            "; its materials are defaults");
  return Status::Ok();
}

// One library whose name has spaces, or several separated by blanks (both are written).
Status ObjReader::mtllib(const std::string& rest) {
  std::vector<Token> tokens = split_tokens(rest);
  std::string note;
  std::error_code ec;
  bool whole = tokens.size() > 1 && rest.front() != '"' &&
               std::filesystem::is_regular_file(resolve_written_path(folder_, rest, &note), ec);
  if (whole || tokens.size() == 1) return load_library(whole ? rest : tokens[0].text);
  for (const auto& t : tokens) VT_RETURN_IF_ERROR(load_library(t.text));
  return Status::Ok();
}

Status ObjReader::statement(const std::string& key, LineCursor* c) {
  if (key == "v") return vertex(c);
  if (key == "f" || key == "fo") return face(c);
  if (key == "vt") {
    Vec2 t{};
    c->number(&t[0]);
    c->number(&t[1]);
    t[1] = 1.0f - t[1];
    vt_.push_back(t);
  } else if (key == "vn") {
    Vec3 n{};
    for (int k = 0; k < 3; ++k) c->number(&n[k]);
    vn_.push_back(n);
  } else if (key == "usemtl") {
    current_ = c->rest_of_line();
  } else if (key == "s") {
    const std::string group = c->word();  // "off" or 0: flat
    smoothing_ = group == "off" ? 0 : std::max(0, std::atoi(group.c_str()));
  } else if (key == "mtllib") {
    std::string rest = c->rest_of_line();
    if (!rest.empty()) VT_RETURN_IF_ERROR(mtllib(rest));
  } else if (key == "l" || key == "p" || key == "curv" || key == "curv2" || key == "surf") {
    ++ignored_elements_;
  }
  return Status::Ok();
}

int ObjReader::material_index(const std::string& name) {
  if (name.empty()) return -1;
  auto it = materials_.find(name);
  if (it != materials_.end()) return it->second;
  std::string why = libraries_.empty() ? "the OBJ names no mtllib"
                    : library_missing_ ? "not in the MTL libraries that could be read"
                                       : "not in its MTL libraries";
  scene_.warnings.push_back(path_ + ": usemtl '" + name + "': " + why +
                            "; a default (untextured) material is used");
  return -1;
}

void ObjReader::fill_colors(Builder* b) const {
  if (colors_.empty()) return;
  const float scale = color_peak_ > 1.0f ? 1.0f / 255.0f : 1.0f;
  for (int pi : b->position_of) {
    Vec4 c = colors_[pi];
    for (int k = 0; k < 3; ++k) c[k] = srgb_to_linear(c[k] * scale);
    c[3] = std::min(c[3] * scale, 1.0f);
    b->prim.colors.push_back(c);
  }
}

Expected<Scene> ObjReader::finish() && {
  VT_RETURN_IF_ERROR(build_faces());
  if (!colors_.empty() && color_peak_ > 1.0f)
    scene_.warnings.push_back(path_ + ": vertex colours above 1 (up to " +
                              std::to_string(color_peak_) + ") read as 0..255");
  if (ignored_elements_ > 0)
    scene_.warnings.push_back(path_ + ": " + std::to_string(ignored_elements_) +
                              " point, line or curve elements ignored (only faces are baked)");
  std::vector<std::pair<int, size_t>> order;  // (material, builder): default material first
  for (size_t i = 0; i < builders_.size(); ++i)
    order.emplace_back(material_index(builders_[i].material_name), i);
  std::stable_sort(order.begin(), order.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  Mesh mesh;
  mesh.name = "obj";
  for (auto [material, i] : order) {
    Builder& b = builders_[i];
    if (!b.any_uv) b.prim.uvs.clear();
    fill_colors(&b);
    b.prim.material = material;
    mesh.primitives.push_back(std::move(b.prim));
  }
  scene_.meshes.push_back(std::move(mesh));
  Node node;
  node.name = "obj";
  node.mesh = 0;
  scene_.nodes.push_back(node);
  scene_.roots.push_back(0);
  untexture_surfaces_without_uvs(&scene_);
  return std::move(scene_);
}

}  // namespace

Expected<Scene> load_obj(const std::string& path, const SceneLoadOptions& options) {
  VT_ASSIGN_OR_RETURN(auto bytes, read_file(path));
  std::string note;
  VT_ASSIGN_OR_RETURN(std::string text, decode_text(bytes, path, &note));
  bytes = {};
  ObjReader reader(path, options);
  if (!note.empty()) reader.warn(path + ": " + note);
  LineCursor c{text.data(), text.data() + text.size()};
  while (c.p < c.end) {
    std::string key = c.word();
    if (!key.empty() && key[0] != '#') VT_RETURN_IF_ERROR(reader.statement(key, &c));
    c.next_line();
    ++reader.line;
  }
  return std::move(reader).finish();
}

}  // namespace vt::scene::detail
