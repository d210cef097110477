// glTF 2.0 binary export: one BIN chunk holding every attribute, index list and embedded image.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>

#include "scene/scene_io_util.h"

namespace vt::scene {
namespace {

using json = nlohmann::json;

struct Writer {
  json doc;
  std::vector<uint8_t> bin;

  size_t add_view(const void* data, size_t size, int target) {
    while (bin.size() % 4) bin.push_back(0);
    size_t offset = bin.size();
    const auto* p = static_cast<const uint8_t*>(data);
    bin.insert(bin.end(), p, p + size);
    json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", size}};
    if (target) view["target"] = target;
    doc["bufferViews"].push_back(view);
    return doc["bufferViews"].size() - 1;
  }

  template <int N>
  size_t add_floats(const std::vector<std::array<float, N>>& values, bool min_max) {
    static const char* kTypes[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
    size_t view = add_view(values.data(), values.size() * sizeof(values[0]), 34962);
    json acc = {{"bufferView", view},
                {"componentType", 5126},
                {"count", values.size()},
                {"type", kTypes[N]}};
    if (min_max && !values.empty()) {
      std::array<float, N> lo, hi;
      lo.fill(std::numeric_limits<float>::max());
      hi.fill(std::numeric_limits<float>::lowest());
      for (const auto& v : values)
        for (int k = 0; k < N; ++k) {
          if (!std::isfinite(v[k])) continue;
          lo[k] = std::min(lo[k], v[k]);
          hi[k] = std::max(hi[k], v[k]);
        }
      acc["min"] = lo;
      acc["max"] = hi;
    }
    doc["accessors"].push_back(acc);
    return doc["accessors"].size() - 1;
  }
};

int wrap_code(WrapMode m) {
  return m == WrapMode::kClampToEdge ? 33071 : m == WrapMode::kMirroredRepeat ? 33648 : 10497;
}

}  // namespace

Status save_glb(const Scene& scene, const std::string& path) {
  Writer w;
  w.doc["asset"] = {{"version", "2.0"}, {"generator", "vtbake"}};
  w.doc["bufferViews"] = json::array();
  w.doc["accessors"] = json::array();
  std::string out_folder = detail::parent_folder(path);

  for (const Image& im : scene.images) {
    json j;
    if (!im.name.empty()) j["name"] = im.name;
    if (im.embedded()) {
      j["bufferView"] = w.add_view(im.bytes.data(), im.bytes.size(), 0);
      j["mimeType"] = im.mime_type.empty() ? "image/png" : im.mime_type;
    } else {
      std::error_code ec;
      auto base = std::filesystem::absolute(out_folder.empty() ? "." : out_folder, ec);
      auto rel = std::filesystem::relative(std::filesystem::absolute(im.path, ec), base, ec);
      j["uri"] = ec || rel.empty() ? im.path : rel.generic_string();
      if (!im.mime_type.empty()) j["mimeType"] = im.mime_type;
    }
    w.doc["images"].push_back(j);
  }
  // One texture (and sampler) per distinct slot use.
  auto texture = [&](const TextureRef& ref) -> json {
    json sampler = {{"wrapS", wrap_code(ref.wrap_s)}, {"wrapT", wrap_code(ref.wrap_t)}};
    size_t s = 0;
    auto& samplers = w.doc["samplers"];
    for (; s < samplers.size(); ++s)
      if (samplers[s] == sampler) break;
    if (s == samplers.size()) samplers.push_back(sampler);
    w.doc["textures"].push_back({{"source", ref.image}, {"sampler", s}});
    json info = {{"index", w.doc["textures"].size() - 1}};
    if (ref.texcoord) info["texCoord"] = ref.texcoord;
    return info;
  };
  for (const Material& m : scene.materials) {
    json j;
    if (!m.name.empty()) j["name"] = m.name;
    json pbr = {{"baseColorFactor", m.base_color_factor},
                {"metallicFactor", m.metallic_factor},
                {"roughnessFactor", m.roughness_factor}};
    if (m.base_color_texture.valid()) pbr["baseColorTexture"] = texture(m.base_color_texture);
    if (m.metallic_roughness_texture.valid())
      pbr["metallicRoughnessTexture"] = texture(m.metallic_roughness_texture);
    j["pbrMetallicRoughness"] = pbr;
    if (m.normal_texture.valid()) {
      j["normalTexture"] = texture(m.normal_texture);
      j["normalTexture"]["scale"] = m.normal_scale;
    }
    if (m.occlusion_texture.valid()) {
      j["occlusionTexture"] = texture(m.occlusion_texture);
      j["occlusionTexture"]["strength"] = m.occlusion_strength;
    }
    j["emissiveFactor"] = m.emissive_factor;
    if (m.emissive_texture.valid()) j["emissiveTexture"] = texture(m.emissive_texture);
    j["alphaMode"] = m.alpha_mode == AlphaMode::kMask    ? "MASK"
                     : m.alpha_mode == AlphaMode::kBlend ? "BLEND"
                                                         : "OPAQUE";
    if (m.alpha_mode == AlphaMode::kMask) j["alphaCutoff"] = m.alpha_cutoff;
    if (m.double_sided) j["doubleSided"] = true;
    w.doc["materials"].push_back(j);
  }
  for (size_t mi = 0; mi < scene.meshes.size(); ++mi) {
    const Mesh& mesh = scene.meshes[mi];
    json jm;
    if (!mesh.name.empty()) jm["name"] = mesh.name;
    jm["primitives"] = json::array();
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const Primitive& p = mesh.primitives[pi];
      for (uint32_t i : p.indices)
        if (i >= p.positions.size())
          return Error(ErrorCode::kInvalidArgument,
                       path + ": mesh " + std::to_string(mi) + " primitive " + std::to_string(pi) +
                           ": index " + std::to_string(i) + " out of range");
      json attrs;
      attrs["POSITION"] = w.add_floats<3>(p.positions, true);
      if (p.normals.size() == p.positions.size() && !p.normals.empty())
        attrs["NORMAL"] = w.add_floats<3>(p.normals, false);
      if (p.tangents.size() == p.positions.size() && !p.tangents.empty())
        attrs["TANGENT"] = w.add_floats<4>(p.tangents, false);
      for (size_t n = 0; n < p.uvs.size(); ++n)
        attrs["TEXCOORD_" + std::to_string(n)] = w.add_floats<2>(p.uvs[n], false);
      if (p.colors.size() == p.positions.size() && !p.colors.empty())
        attrs["COLOR_0"] = w.add_floats<4>(p.colors, false);
      json jp = {{"attributes", attrs}, {"mode", 4}};
      size_t view = w.add_view(p.indices.data(), p.indices.size() * 4, 34963);
      w.doc["accessors"].push_back({{"bufferView", view},
                                    {"componentType", 5125},
                                    {"count", p.indices.size()},
                                    {"type", "SCALAR"}});
      jp["indices"] = w.doc["accessors"].size() - 1;
      if (p.material >= 0) jp["material"] = p.material;
      jm["primitives"].push_back(jp);
    }
    w.doc["meshes"].push_back(jm);
  }
  for (const Node& n : scene.nodes) {
    json j;
    if (!n.name.empty()) j["name"] = n.name;
    if (n.local != kIdentity) j["matrix"] = n.local;
    if (n.mesh >= 0) j["mesh"] = n.mesh;
    if (!n.children.empty()) j["children"] = n.children;
    w.doc["nodes"].push_back(j);
  }
  w.doc["scenes"] = json::array({json{{"nodes", scene.roots}}});
  w.doc["scene"] = 0;
  while (w.bin.size() % 4) w.bin.push_back(0);
  w.doc["buffers"] = json::array({json{{"byteLength", w.bin.size()}}});
  if (w.doc["bufferViews"].empty()) w.doc.erase("bufferViews");
  if (w.doc["accessors"].empty()) w.doc.erase("accessors");

  std::string text = w.doc.dump();
  while (text.size() % 4) text.push_back(' ');
  uint32_t total = static_cast<uint32_t>(12 + 8 + text.size() + 8 + w.bin.size());
  std::string tmp = path + ".tmp";
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(tmp.c_str(), "wb"), &std::fclose);
  if (!f) return Error(ErrorCode::kIo, path + ": cannot create file");
  auto put32 = [&](uint32_t v) { return std::fwrite(&v, 4, 1, f.get()) == 1; };
  bool ok = std::fwrite("glTF", 4, 1, f.get()) == 1 && put32(2) && put32(total) &&
            put32(static_cast<uint32_t>(text.size())) && put32(0x4E4F534A) &&
            std::fwrite(text.data(), 1, text.size(), f.get()) == text.size() &&
            put32(static_cast<uint32_t>(w.bin.size())) && put32(0x004E4942) &&
            (w.bin.empty() || std::fwrite(w.bin.data(), 1, w.bin.size(), f.get()) == w.bin.size());
  ok = std::fclose(f.release()) == 0 && ok;
  if (!ok) {
    std::remove(tmp.c_str());
    return Error(ErrorCode::kIo, path + ": write failed");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    return Error(ErrorCode::kIo, path + ": cannot rename into place");
  }
  return Status::Ok();
}

}  // namespace vt::scene
