// Wavefront OBJ + MTL: one primitive per material, polygons fanned into triangles, vertices
// shared by identical (position, uv, normal) triples. OBJ's v-up UVs become glTF's v-down.
#include <charconv>
#include <cmath>
#include <cstring>
#include <map>
#include <unordered_map>

#include "scene/scene_io_util.h"

namespace vt::scene::detail {
namespace {

struct Cursor {
  const char* p;
  const char* end;
  void skip_space() {
    while (p < end && (*p == ' ' || *p == '\t' || *p == '\r')) ++p;
  }
  bool at_line_end() {
    skip_space();
    return p >= end || *p == '\n' || *p == '#';
  }
  std::string word() {
    skip_space();
    const char* s = p;
    while (p < end && !std::isspace(static_cast<unsigned char>(*p))) ++p;
    return std::string(s, p);
  }
  std::string rest_of_line() {
    skip_space();
    const char* s = p;
    while (p < end && *p != '\n') ++p;
    const char* e = p;
    while (e > s && (e[-1] == '\r' || e[-1] == ' ' || e[-1] == '\t')) --e;
    return std::string(s, e);
  }
  bool number(float* out) {
    skip_space();
    auto r = std::from_chars(p, end, *out);
    if (r.ec == std::errc::result_out_of_range) {  // keep huge values as inf, not an error
      double d = std::strtod(std::string(p, r.ptr).c_str(), nullptr);
      *out = static_cast<float>(d);
    } else if (r.ec != std::errc()) {
      // from_chars rejects "nan"/"inf" spellings some exporters use with a sign or case.
      std::string w = word();
      if (w.empty()) return false;
      char* e = nullptr;
      *out = std::strtof(w.c_str(), &e);
      return e && *e == 0;
    }
    p = r.ptr;
    return true;
  }
  void next_line() {
    while (p < end && *p != '\n') ++p;
    if (p < end) ++p;
  }
};

// The last whitespace-separated token of an MTL map statement is the file (options come first).
std::string map_file(const std::string& rest) {
  size_t pos = rest.find_last_of(" \t");
  return pos == std::string::npos ? rest : rest.substr(pos + 1);
}

void parse_mtl(const std::string& path, Scene* scene, std::map<std::string, int>* by_name) {
  auto bytes = read_file(path);
  if (!bytes.ok()) return;  // a missing .mtl leaves default materials, as most tools do
  std::string folder = parent_folder(path);
  auto image_for = [&](const std::string& file) {
    for (size_t i = 0; i < scene->images.size(); ++i)
      if (scene->images[i].uri == file) return static_cast<int>(i);
    Image img;
    img.uri = file;
    img.path = folder + file;
    img.name = file;
    scene->images.push_back(img);
    return static_cast<int>(scene->images.size() - 1);
  };
  Cursor c{reinterpret_cast<const char*>(bytes->data()),
           reinterpret_cast<const char*>(bytes->data()) + bytes->size()};
  Material* m = nullptr;
  while (c.p < c.end) {
    std::string key = c.word();
    if (key == "newmtl") {
      Material mat;
      mat.name = c.rest_of_line();
      mat.metallic_factor = 0.0f;  // OBJ materials are dielectric unless Pm says otherwise
      scene->materials.push_back(mat);
      (*by_name)[mat.name] = static_cast<int>(scene->materials.size() - 1);
      m = &scene->materials.back();
    } else if (m && key == "Kd") {
      for (int k = 0; k < 3; ++k) c.number(&m->base_color_factor[k]);
    } else if (m && key == "d") {
      c.number(&m->base_color_factor[3]);
      if (m->base_color_factor[3] < 1.0f) m->alpha_mode = AlphaMode::kBlend;
    } else if (m && key == "Tr") {
      float tr = 0;
      c.number(&tr);
      m->base_color_factor[3] = 1.0f - tr;
      if (tr > 0.0f) m->alpha_mode = AlphaMode::kBlend;
    } else if (m && key == "Ke") {
      for (int k = 0; k < 3; ++k) c.number(&m->emissive_factor[k]);
    } else if (m && key == "Pr") {
      c.number(&m->roughness_factor);
    } else if (m && key == "Pm") {
      c.number(&m->metallic_factor);
    } else if (m && key == "map_Kd") {
      m->base_color_texture.image = image_for(map_file(c.rest_of_line()));
    } else if (m && (key == "map_Bump" || key == "map_bump" || key == "bump" || key == "norm")) {
      m->normal_texture.image = image_for(map_file(c.rest_of_line()));
    } else if (m && key == "map_Ke") {
      m->emissive_texture.image = image_for(map_file(c.rest_of_line()));
    }
    c.next_line();
  }
}

struct KeyHash {
  size_t operator()(const std::array<int, 3>& k) const {
    return (static_cast<size_t>(k[0]) * 73856093u) ^ (static_cast<size_t>(k[1]) * 19349663u) ^
           (static_cast<size_t>(k[2]) * 83492791u);
  }
};

}  // namespace

Expected<Scene> load_obj(const std::string& path) {
  VT_ASSIGN_OR_RETURN(auto bytes, read_file(path));
  Scene scene;
  scene.source_path = path;
  std::map<std::string, int> materials;
  std::vector<Vec3> v, vn;
  std::vector<Vec2> vt;
  struct Builder {
    Primitive prim;
    std::unordered_map<std::array<int, 3>, uint32_t, KeyHash> map;
    bool any_uv = false, any_normal = false;
  };
  std::map<int, Builder> builders;  // by material, so output order is deterministic
  int current_material = -1;
  Cursor c{reinterpret_cast<const char*>(bytes.data()),
           reinterpret_cast<const char*>(bytes.data()) + bytes.size()};
  size_t line = 1;
  std::vector<std::array<int, 3>> face;
  while (c.p < c.end) {
    std::string key = c.word();
    if (key == "v") {
      Vec3 p{};
      for (int k = 0; k < 3; ++k)
        if (!c.number(&p[k]))
          return Error(ErrorCode::kCorrupt, path + ":" + std::to_string(line) + ": bad vertex");
      v.push_back(p);
    } else if (key == "vt") {
      Vec2 t{};
      c.number(&t[0]);
      c.number(&t[1]);
      t[1] = 1.0f - t[1];
      vt.push_back(t);
    } else if (key == "vn") {
      Vec3 n{};
      for (int k = 0; k < 3; ++k) c.number(&n[k]);
      vn.push_back(n);
    } else if (key == "f") {
      face.clear();
      while (!c.at_line_end()) {
        std::string w = c.word();
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
        const size_t counts[3] = {v.size(), vt.size(), vn.size()};
        for (int k = 0; k < 3; ++k) {
          if (idx[k] < 0) idx[k] = static_cast<int>(counts[k]) + idx[k] + 1;
          if (idx[k] < 0 || static_cast<size_t>(idx[k]) > counts[k] || (k == 0 && idx[k] == 0))
            return Error(ErrorCode::kCorrupt, path + ":" + std::to_string(line) + ": face index '" +
                                                  w + "' out of range");
        }
        face.push_back(idx);
      }
      if (face.size() >= 3) {
        Builder& b = builders[current_material];
        auto vertex = [&](const std::array<int, 3>& k) {
          auto [it, inserted] =
              b.map.try_emplace(k, static_cast<uint32_t>(b.prim.positions.size()));
          if (inserted) {
            b.prim.positions.push_back(v[k[0] - 1]);
            b.prim.uvs.resize(1);
            b.prim.uvs[0].push_back(k[1] ? vt[k[1] - 1] : Vec2{0, 0});
            b.prim.normals.push_back(k[2] ? vn[k[2] - 1] : Vec3{0, 0, 0});
            b.any_uv |= k[1] != 0;
            b.any_normal |= k[2] != 0;
          }
          return it->second;
        };
        uint32_t first = vertex(face[0]);
        for (size_t i = 1; i + 1 < face.size(); ++i) {
          b.prim.indices.push_back(first);
          b.prim.indices.push_back(vertex(face[i]));
          b.prim.indices.push_back(vertex(face[i + 1]));
        }
      }
    } else if (key == "usemtl") {
      std::string name = c.rest_of_line();
      auto it = materials.find(name);
      current_material = it == materials.end() ? -1 : it->second;
    } else if (key == "mtllib") {
      parse_mtl(parent_folder(path) + c.rest_of_line(), &scene, &materials);
    }
    c.next_line();
    ++line;
  }
  Mesh mesh;
  mesh.name = "obj";
  for (auto& [material, b] : builders) {
    if (!b.any_uv) b.prim.uvs.clear();
    if (!b.any_normal) b.prim.normals.clear();
    b.prim.material = material;
    mesh.primitives.push_back(std::move(b.prim));
  }
  scene.meshes.push_back(std::move(mesh));
  Node node;
  node.name = "obj";
  node.mesh = 0;
  scene.nodes.push_back(node);
  scene.roots.push_back(0);
  return scene;
}

}  // namespace vt::scene::detail
