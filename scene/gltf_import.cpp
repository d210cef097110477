// glTF 2.0 import (.gltf with external or data: buffers, .glb), KHR_draco_mesh_compression.
// Every offset, size and index from the file is checked before use.
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>

#include "scene/scene_io_util.h"

namespace vt::scene::detail {
namespace {

using json = nlohmann::json;

struct Gltf {
  std::string path;
  json doc;
  std::vector<std::vector<uint8_t>> buffers;

  Status fail(const std::string& what) const {
    return Error(ErrorCode::kCorrupt, path + ": " + what);
  }
};

uint32_t read_u32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

Status load_buffers(Gltf* g, std::vector<uint8_t>* glb_bin) {
  std::string folder = parent_folder(g->path);
  for (const json& b : g->doc.value("buffers", json::array())) {
    if (!b.contains("uri")) {
      if (!glb_bin) return g->fail("buffer without uri outside a .glb");
      g->buffers.push_back(std::move(*glb_bin));
      glb_bin = nullptr;
      continue;
    }
    std::string uri = b["uri"].get<std::string>();
    if (uri.rfind("data:", 0) == 0) {
      auto data = decode_data_uri(uri, nullptr);
      if (!data.ok()) return data.status().with_context(g->path);
      g->buffers.push_back(std::move(data).value());
    } else {
      auto data = read_file(folder + percent_decode(uri));
      if (!data.ok()) return data.status().with_context(g->path + ": buffer");
      g->buffers.push_back(std::move(data).value());
    }
    size_t declared = b.value("byteLength", size_t{0});
    if (g->buffers.back().size() < declared)
      return g->fail("buffer '" + uri.substr(0, 64) + "' is shorter than its byteLength");
  }
  return Status::Ok();
}

// The bytes of a buffer view, bounds-checked.
Status view_bytes(const Gltf& g, size_t view_index, const uint8_t** data, size_t* size,
                  size_t* stride) {
  const json& views = g.doc["bufferViews"];
  if (!views.is_array() || view_index >= views.size())
    return g.fail("bufferView " + std::to_string(view_index) + " does not exist");
  const json& v = views[view_index];
  size_t buffer = v.value("buffer", size_t{0});
  size_t offset = v.value("byteOffset", size_t{0});
  size_t length = v.value("byteLength", size_t{0});
  if (buffer >= g.buffers.size())
    return g.fail("bufferView " + std::to_string(view_index) + ": no buffer");
  if (offset > g.buffers[buffer].size() || length > g.buffers[buffer].size() - offset)
    return g.fail("bufferView " + std::to_string(view_index) + " runs past its buffer");
  *data = g.buffers[buffer].data() + offset;
  *size = length;
  if (stride) *stride = v.value("byteStride", size_t{0});
  return Status::Ok();
}

int component_count(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4") return 4;
  if (type == "MAT4") return 16;
  return 0;
}

size_t component_size(int ct) {
  switch (ct) {
    case 5120:
    case 5121:
      return 1;
    case 5122:
    case 5123:
      return 2;
    case 5125:
    case 5126:
      return 4;
  }
  return 0;
}

double read_component(const uint8_t* p, int ct, bool normalized) {
  switch (ct) {
    case 5120: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case 5121:
      return normalized ? *p / 255.0 : *p;
    case 5122: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case 5123: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case 5125:
      return read_u32(p);
    case 5126: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
  return 0;
}

// Reads accessor `index` as doubles, `comps` per element (missing components left 0).
Status read_accessor(const Gltf& g, size_t index, int comps, std::vector<double>* out,
                     size_t* count) {
  const json& accessors = g.doc["accessors"];
  if (!accessors.is_array() || index >= accessors.size())
    return g.fail("accessor " + std::to_string(index) + " does not exist");
  const json& a = accessors[index];
  std::string where = "accessor " + std::to_string(index);
  size_t n = a.value("count", size_t{0});
  int ct = a.value("componentType", 0);
  int nc = component_count(a.value("type", std::string()));
  size_t cs = component_size(ct);
  if (nc == 0 || cs == 0) return g.fail(where + ": unknown type or componentType");
  if (a.contains("sparse"))
    return Error(ErrorCode::kUnsupported,
                 g.path + ": " + where + ": sparse accessors are not supported");
  bool normalized = a.value("normalized", false);
  *count = n;
  if (n > (size_t{1} << 31)) return g.fail(where + ": count too large");
  out->assign(n * comps, 0.0);
  if (!a.contains("bufferView")) return Status::Ok();  // all zeros, per the spec
  const uint8_t* data;
  size_t size, stride;
  VT_RETURN_IF_ERROR(view_bytes(g, a["bufferView"].get<size_t>(), &data, &size, &stride));
  size_t offset = a.value("byteOffset", size_t{0});
  size_t elem = cs * nc;
  if (stride == 0) stride = elem;
  if (n > 0 && (offset > size || (n - 1) > (size - offset) / stride ||
                (n - 1) * stride + elem > size - offset))
    return g.fail(where + " runs past its bufferView");
  int take = std::min(comps, nc);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* e = data + offset + i * stride;
    for (int k = 0; k < take; ++k)
      (*out)[i * comps + k] = read_component(e + k * cs, ct, normalized);
  }
  return Status::Ok();
}

template <int N>
Status read_vec(const Gltf& g, size_t index, std::vector<std::array<float, N>>* out) {
  std::vector<double> raw;
  size_t n;
  VT_RETURN_IF_ERROR(read_accessor(g, index, N, &raw, &n));
  out->resize(n);
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < N; ++k) (*out)[i][k] = static_cast<float>(raw[i * N + k]);
  return Status::Ok();
}

WrapMode wrap(int v) {
  return v == 33071   ? WrapMode::kClampToEdge
         : v == 33648 ? WrapMode::kMirroredRepeat
                      : WrapMode::kRepeat;
}

TextureRef texture_ref(const Gltf& g, const json& info) {
  TextureRef ref;
  if (!info.is_object() || !info.contains("index")) return ref;
  size_t t = info["index"].get<size_t>();
  const json& textures = g.doc.value("textures", json::array());
  if (t >= textures.size()) return ref;
  const json& tex = textures[t];
  int source = tex.value("source", -1);
  if (source < 0 || source >= static_cast<int>(g.doc.value("images", json::array()).size()))
    return ref;
  ref.image = source;
  ref.texcoord = info.value("texCoord", 0);
  if (tex.contains("sampler")) {
    size_t s = tex["sampler"].get<size_t>();
    const json& samplers = g.doc.value("samplers", json::array());
    if (s < samplers.size()) {
      ref.wrap_s = wrap(samplers[s].value("wrapS", 10497));
      ref.wrap_t = wrap(samplers[s].value("wrapT", 10497));
    }
  }
  return ref;
}

template <int N>
std::array<float, N> float_array(const json& j, std::array<float, N> fallback) {
  if (!j.is_array() || j.size() != N) return fallback;
  std::array<float, N> r;
  for (int i = 0; i < N; ++i) r[i] = j[i].get<float>();
  return r;
}

Mat4 node_matrix(const json& n) {
  if (n.contains("matrix") && n["matrix"].is_array() && n["matrix"].size() == 16) {
    Mat4 m;
    for (int i = 0; i < 16; ++i) m[i] = n["matrix"][i].get<double>();
    return m;
  }
  double t[3] = {0, 0, 0}, s[3] = {1, 1, 1}, q[4] = {0, 0, 0, 1};
  if (n.contains("translation"))
    for (int i = 0; i < 3; ++i) t[i] = n["translation"][i].get<double>();
  if (n.contains("scale"))
    for (int i = 0; i < 3; ++i) s[i] = n["scale"][i].get<double>();
  if (n.contains("rotation"))
    for (int i = 0; i < 4; ++i) q[i] = n["rotation"][i].get<double>();
  double x = q[0], y = q[1], z = q[2], w = q[3];
  double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),
                 2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                 2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y)};
  Mat4 m = kIdentity;
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row) m[c * 4 + row] = r[c * 3 + row] * s[c];
  for (int i = 0; i < 3; ++i) m[12 + i] = t[i];
  return m;
}

Expected<Primitive> load_primitive(const Gltf& g, const json& p, const std::string& where) {
  Primitive prim;
  int mode = p.value("mode", 4);
  const json& attrs = p.value("attributes", json::object());
  if (p.contains("extensions") && p["extensions"].contains("KHR_draco_mesh_compression")) {
    const json& ext = p["extensions"]["KHR_draco_mesh_compression"];
    const uint8_t* data;
    size_t size;
    VT_RETURN_IF_ERROR(view_bytes(g, ext.value("bufferView", size_t{0}), &data, &size, nullptr));
    std::vector<DracoAttribute> ids;
    for (auto it = ext["attributes"].begin(); it != ext["attributes"].end(); ++it)
      ids.push_back({it.key(), it.value().get<int>()});
    auto decoded = decode_draco(data, size, ids);
    if (!decoded.ok()) return decoded.status().with_context(g.path + ": " + where);
    prim = std::move(decoded).value();
  } else {
    if (!attrs.contains("POSITION")) return g.fail(where + ": no POSITION attribute");
    VT_RETURN_IF_ERROR(read_vec<3>(g, attrs["POSITION"].get<size_t>(), &prim.positions));
    if (attrs.contains("NORMAL"))
      VT_RETURN_IF_ERROR(read_vec<3>(g, attrs["NORMAL"].get<size_t>(), &prim.normals));
    if (attrs.contains("TANGENT"))
      VT_RETURN_IF_ERROR(read_vec<4>(g, attrs["TANGENT"].get<size_t>(), &prim.tangents));
    if (attrs.contains("COLOR_0")) {
      const json& a = g.doc["accessors"][attrs["COLOR_0"].get<size_t>()];
      VT_RETURN_IF_ERROR(read_vec<4>(g, attrs["COLOR_0"].get<size_t>(), &prim.colors));
      if (a.value("type", std::string()) == "VEC3")
        for (auto& c : prim.colors) c[3] = 1.0f;
    }
    for (int n = 0; attrs.contains("TEXCOORD_" + std::to_string(n)); ++n) {
      prim.uvs.emplace_back();
      VT_RETURN_IF_ERROR(
          read_vec<2>(g, attrs["TEXCOORD_" + std::to_string(n)].get<size_t>(), &prim.uvs.back()));
    }
    std::vector<uint32_t> idx;
    if (p.contains("indices")) {
      std::vector<double> raw;
      size_t n;
      VT_RETURN_IF_ERROR(read_accessor(g, p["indices"].get<size_t>(), 1, &raw, &n));
      idx.resize(n);
      for (size_t i = 0; i < n; ++i) idx[i] = static_cast<uint32_t>(raw[i]);
    } else {
      idx.resize(prim.positions.size());
      for (size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<uint32_t>(i);
    }
    if (mode == 4) {
      idx.resize(idx.size() / 3 * 3);
      prim.indices = std::move(idx);
    } else if (mode == 5) {  // strip: alternate winding so every triangle faces the same way
      for (size_t i = 2; i < idx.size(); ++i) {
        if (i % 2 == 0)
          prim.indices.insert(prim.indices.end(), {idx[i - 2], idx[i - 1], idx[i]});
        else
          prim.indices.insert(prim.indices.end(), {idx[i - 1], idx[i - 2], idx[i]});
      }
    } else if (mode == 6) {
      for (size_t i = 2; i < idx.size(); ++i)
        prim.indices.insert(prim.indices.end(), {idx[0], idx[i - 1], idx[i]});
    } else {
      prim.indices.clear();  // points and lines carry no surface
    }
  }
  prim.material = p.value("material", -1);
  if (prim.material >= static_cast<int>(g.doc.value("materials", json::array()).size()))
    prim.material = -1;
  return prim;
}

}  // namespace

Expected<Scene> load_gltf(const std::string& path) {
  VT_ASSIGN_OR_RETURN(auto bytes, read_file(path));
  Gltf g;
  g.path = path;
  std::vector<uint8_t> bin;
  bool glb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  try {
    if (glb) {
      if (bytes.size() < 20) return g.fail("truncated .glb header");
      size_t total = std::min<size_t>(read_u32(&bytes[8]), bytes.size());
      size_t pos = 12;
      bool have_json = false;
      while (pos + 8 <= total) {
        size_t len = read_u32(&bytes[pos]);
        uint32_t type = read_u32(&bytes[pos + 4]);
        pos += 8;
        if (len > total - pos) return g.fail(".glb chunk runs past the end of the file");
        if (type == 0x4E4F534A) {
          g.doc = json::parse(bytes.begin() + pos, bytes.begin() + pos + len);
          have_json = true;
        } else if (type == 0x004E4942 && bin.empty()) {
          bin.assign(bytes.begin() + pos, bytes.begin() + pos + len);
        }
        pos += (len + 3) & ~size_t{3};
      }
      if (!have_json) return g.fail(".glb has no JSON chunk");
    } else {
      g.doc = json::parse(bytes.begin(), bytes.end());
    }
    if (!g.doc.is_object()) return g.fail("not a glTF JSON object");
    for (const json& e : g.doc.value("extensionsRequired", json::array())) {
      std::string name = e.get<std::string>();
      if (name != "KHR_draco_mesh_compression" && name != "KHR_materials_emissive_strength" &&
          name != "KHR_texture_transform")
        return Error(ErrorCode::kUnsupported,
                     path + ": required extension " + name + " is not supported");
    }
    VT_RETURN_IF_ERROR(load_buffers(&g, glb ? &bin : nullptr));

    Scene scene;
    scene.source_path = path;
    std::string folder = parent_folder(path);
    for (const json& im : g.doc.value("images", json::array())) {
      Image image;
      image.name = im.value("name", std::string());
      image.mime_type = im.value("mimeType", std::string());
      if (im.contains("uri")) {
        std::string uri = im["uri"].get<std::string>();
        if (uri.rfind("data:", 0) == 0) {
          auto data = decode_data_uri(uri, &image.mime_type);
          if (!data.ok()) return data.status().with_context(path + ": image");
          image.bytes = std::move(data).value();
        } else {
          image.uri = uri;
          image.path = folder + percent_decode(uri);
        }
      } else if (im.contains("bufferView")) {
        const uint8_t* data;
        size_t size;
        VT_RETURN_IF_ERROR(view_bytes(g, im["bufferView"].get<size_t>(), &data, &size, nullptr));
        image.bytes.assign(data, data + size);
      }
      scene.images.push_back(std::move(image));
    }
    for (const json& m : g.doc.value("materials", json::array())) {
      Material mat;
      mat.name = m.value("name", std::string());
      const json& pbr = m.value("pbrMetallicRoughness", json::object());
      mat.base_color_factor = float_array<4>(pbr.value("baseColorFactor", json()), {1, 1, 1, 1});
      mat.base_color_texture = texture_ref(g, pbr.value("baseColorTexture", json()));
      mat.metallic_factor = pbr.value("metallicFactor", 1.0f);
      mat.roughness_factor = pbr.value("roughnessFactor", 1.0f);
      mat.metallic_roughness_texture =
          texture_ref(g, pbr.value("metallicRoughnessTexture", json()));
      mat.normal_texture = texture_ref(g, m.value("normalTexture", json()));
      if (m.contains("normalTexture")) mat.normal_scale = m["normalTexture"].value("scale", 1.0f);
      mat.occlusion_texture = texture_ref(g, m.value("occlusionTexture", json()));
      if (m.contains("occlusionTexture"))
        mat.occlusion_strength = m["occlusionTexture"].value("strength", 1.0f);
      mat.emissive_factor = float_array<3>(m.value("emissiveFactor", json()), {0, 0, 0});
      mat.emissive_texture = texture_ref(g, m.value("emissiveTexture", json()));
      std::string alpha = m.value("alphaMode", std::string("OPAQUE"));
      mat.alpha_mode = alpha == "MASK"    ? AlphaMode::kMask
                       : alpha == "BLEND" ? AlphaMode::kBlend
                                          : AlphaMode::kOpaque;
      mat.alpha_cutoff = m.value("alphaCutoff", 0.5f);
      mat.double_sided = m.value("doubleSided", false);
      scene.materials.push_back(mat);
    }
    const json& meshes = g.doc.value("meshes", json::array());
    for (size_t mi = 0; mi < meshes.size(); ++mi) {
      Mesh mesh;
      mesh.name = meshes[mi].value("name", std::string());
      const json& prims = meshes[mi].value("primitives", json::array());
      for (size_t pi = 0; pi < prims.size(); ++pi) {
        std::string where = "mesh " + std::to_string(mi) + " primitive " + std::to_string(pi);
        auto prim = load_primitive(g, prims[pi], where);
        if (!prim.ok()) return prim.status();
        mesh.primitives.push_back(std::move(prim).value());
      }
      scene.meshes.push_back(std::move(mesh));
    }
    for (const json& n : g.doc.value("nodes", json::array())) {
      Node node;
      node.name = n.value("name", std::string());
      node.local = node_matrix(n);
      node.mesh = n.value("mesh", -1);
      if (node.mesh >= static_cast<int>(scene.meshes.size())) node.mesh = -1;
      for (const json& c : n.value("children", json::array()))
        node.children.push_back(c.get<int>());
      scene.nodes.push_back(std::move(node));
    }
    const json& scenes = g.doc.value("scenes", json::array());
    size_t which = g.doc.value("scene", size_t{0});
    if (which < scenes.size()) {
      for (const json& r : scenes[which].value("nodes", json::array()))
        scene.roots.push_back(r.get<int>());
    } else {
      // No scene: every node that is nobody's child is a root.
      std::vector<char> child(scene.nodes.size(), 0);
      for (const Node& n : scene.nodes)
        for (int c : n.children)
          if (c >= 0 && c < static_cast<int>(child.size())) child[c] = 1;
      for (size_t i = 0; i < child.size(); ++i)
        if (!child[i]) scene.roots.push_back(static_cast<int>(i));
    }
    return scene;
  } catch (const json::exception& e) {
    return g.fail(std::string("malformed glTF JSON: ") + e.what());
  }
}

}  // namespace vt::scene::detail
