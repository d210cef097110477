// glTF 2.0 import (.gltf with external or data: buffers, .glb), KHR_draco_mesh_compression.
// Every offset, size and index from the file is checked before use.
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>

#include "scene/gltf_document.h"
#include "scene/scene_io_util.h"

namespace vt::scene::detail {
namespace {

using json = nlohmann::json;

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
