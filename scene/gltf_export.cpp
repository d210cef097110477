// glTF 2.0 export: DocumentBuilder makes the one document; save_glb and save_gltf only choose
// its container (see gltf_export.h).
#include "scene/gltf_export.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <utility>
#include <vector>

#include "format/atomic_output.h"
#include "scene/scene_io_util.h"
#include "scene/tangent_frame.h"

namespace vt::scene {
namespace {

using json = nlohmann::json;

constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;  // bufferView targets
constexpr int kFloat = 5126, kUnsignedInt = 5125;                 // accessor component types
constexpr int kNearest = 9728, kLinear = 9729, kLinearMipmapLinear = 9987;  // sampler filters

int wrap_code(WrapMode m) {
  return m == WrapMode::kClampToEdge ? 33071 : m == WrapMode::kMirroredRepeat ? 33648 : 10497;
}

// The document and the one buffer its views point into: embedded images first, then every
// primitive's attributes and indices, each view 4-byte aligned.
class DocumentBuilder {
 public:
  DocumentBuilder(const GltfWriteOptions& options, std::string out_folder)
      : options_(options), out_folder_(std::move(out_folder)) {
    doc_["asset"] = {{"version", "2.0"}, {"generator", options.generator}};
    doc_["bufferViews"] = json::array();
    doc_["accessors"] = json::array();
  }

  // `path` names the output in errors.
  Status add(const Scene& scene, const std::string& path) {
    add_images(scene);
    add_materials(scene);
    VT_RETURN_IF_ERROR(add_meshes(scene, path));
    add_nodes(scene);
    doc_["scenes"] = json::array({json{{"nodes", scene.roots}}});
    doc_["scene"] = 0;
    return Status::Ok();
  }

  // Pads the buffer and records its length; `bin_uri` is empty for a .glb's BIN chunk.
  std::pair<json, std::vector<uint8_t>> finish(const std::string& bin_uri) && {
    while (bin_.size() % 4) bin_.push_back(0);
    json buffer = {{"byteLength", bin_.size()}};
    if (!bin_uri.empty()) buffer["uri"] = bin_uri;
    doc_["buffers"] = json::array({buffer});
    if (doc_["bufferViews"].empty()) doc_.erase("bufferViews");
    if (doc_["accessors"].empty()) doc_.erase("accessors");
    return {std::move(doc_), std::move(bin_)};
  }

 private:
  size_t add_view(const void* data, size_t size, int target) {
    while (bin_.size() % 4) bin_.push_back(0);
    size_t offset = bin_.size();
    const auto* p = static_cast<const uint8_t*>(data);
    bin_.insert(bin_.end(), p, p + size);
    json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", size}};
    if (target) view["target"] = target;
    doc_["bufferViews"].push_back(view);
    return doc_["bufferViews"].size() - 1;
  }

  // min/max (POSITION) skip non-finite values, which glTF bounds cannot hold.
  template <int N>
  size_t add_floats(const std::vector<std::array<float, N>>& values, bool min_max) {
    static const char* kTypes[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
    size_t view = add_view(values.data(), values.size() * sizeof(values[0]), kArrayBuffer);
    json acc = {{"bufferView", view},
                {"componentType", kFloat},
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
    doc_["accessors"].push_back(acc);
    return doc_["accessors"].size() - 1;
  }

  size_t add_indices(const std::vector<uint32_t>& indices) {
    size_t view = add_view(indices.data(), indices.size() * 4, kElementArrayBuffer);
    doc_["accessors"].push_back({{"bufferView", view},
                                 {"componentType", kUnsignedInt},
                                 {"count", indices.size()},
                                 {"type", "SCALAR"}});
    return doc_["accessors"].size() - 1;
  }

  void add_images(const Scene& scene) {
    for (const Image& im : scene.images) {
      json j = json::object();
      if (!im.name.empty()) j["name"] = im.name;
      if (im.has_no_data()) {
        // Written as read, with neither (a zero-length bufferView would break the schema).
      } else if (im.embedded()) {
        j["bufferView"] = add_view(im.bytes.data(), im.bytes.size(), 0);
        j["mimeType"] = im.mime_type.empty() ? "image/png" : im.mime_type;
      } else {
        std::error_code ec;
        auto base = std::filesystem::absolute(out_folder_.empty() ? "." : out_folder_, ec);
        auto rel = std::filesystem::relative(std::filesystem::absolute(im.path, ec), base, ec);
        j["uri"] = detail::percent_encode_path(ec || rel.empty() ? im.path : rel.generic_string());
        if (!im.mime_type.empty()) j["mimeType"] = im.mime_type;
      }
      doc_["images"].push_back(j);
    }
  }

  // One texture per slot use; samplers shared by equal wrap modes.
  json texture(const TextureRef& ref) {
    json sampler = {{"wrapS", wrap_code(ref.wrap_s)}, {"wrapT", wrap_code(ref.wrap_t)}};
    if (ref.mag_filter == FilterMode::kNearest) sampler["magFilter"] = kNearest;
    if (options_.sampler_filters) {
      if (ref.mag_filter != FilterMode::kNearest) sampler["magFilter"] = kLinear;
      sampler["minFilter"] = kLinearMipmapLinear;
    }
    size_t s = 0;
    auto& samplers = doc_["samplers"];
    for (; s < samplers.size(); ++s)
      if (samplers[s] == sampler) break;
    if (s == samplers.size()) samplers.push_back(sampler);
    doc_["textures"].push_back({{"source", ref.image}, {"sampler", s}});
    json info = {{"index", doc_["textures"].size() - 1}};
    if (ref.texcoord || options_.write_texcoord_0) info["texCoord"] = ref.texcoord;
    // `texcoord` is the set after the transform's override, so the extension names none.
    if (!ref.transform.identity()) {
      const TextureTransform& t = ref.transform;
      info["extensions"]["KHR_texture_transform"] = {
          {"offset", t.offset}, {"rotation", t.rotation}, {"scale", t.scale}};
      use_extension("KHR_texture_transform");
    }
    return info;
  }

  void add_materials(const Scene& scene) {
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
      if (m.emissive_strength != 1.0f) {
        j["extensions"]["KHR_materials_emissive_strength"] = {
            {"emissiveStrength", m.emissive_strength}};
        use_extension("KHR_materials_emissive_strength");
      }
      if (m.alpha_mode != AlphaMode::kOpaque || options_.write_opaque)
        j["alphaMode"] = m.alpha_mode == AlphaMode::kMask    ? "MASK"
                         : m.alpha_mode == AlphaMode::kBlend ? "BLEND"
                                                             : "OPAQUE";
      if (m.alpha_mode == AlphaMode::kMask) j["alphaCutoff"] = m.alpha_cutoff;
      if (m.double_sided || options_.write_single_sided) j["doubleSided"] = m.double_sided;
      doc_["materials"].push_back(j);
    }
  }

  Status add_meshes(const Scene& scene, const std::string& path) {
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
                         path + ": mesh " + std::to_string(mi) + " primitive " +
                             std::to_string(pi) + ": index " + std::to_string(i) + " out of range");
        const int normal_set = p.material >= 0 && size_t(p.material) < scene.materials.size() &&
                                       scene.materials[p.material].normal_texture.valid()
                                   ? scene.materials[p.material].normal_texture.texcoord
                                   : -1;
        jm["primitives"].push_back(primitive(p, normal_set));
      }
      doc_["meshes"].push_back(jm);
    }
    return Status::Ok();
  }

  // Attributes whose count differs from the positions' are left out, as glTF requires.
  // `normal_set`: the UV set the material's normal map reads (-1: none).
  json primitive(const Primitive& p, int normal_set) {
    const size_t n = p.positions.size();
    json attrs;
    attrs["POSITION"] = add_floats<3>(p.positions, true);
    const bool atlas_frame =
        options_.atlas_tangents && n && !p.uvs.empty() && p.uvs.back().size() == n;
    // A primitive without normals is shaded smooth here (compute_normals), where a glTF reader
    // makes it flat and ignores its TANGENT: the normals the bake used are written.
    std::vector<Vec3> computed;
    if (p.normals.size() != n) computed = compute_normals(p);
    const std::vector<Vec3>& normals = computed.empty() ? p.normals : computed;
    if (normals.size() == n && n) attrs["NORMAL"] = add_floats<3>(normals, false);
    if (atlas_frame) {
      const int atlas_set = static_cast<int>(p.uvs.size()) - 1;
      attrs["TANGENT"] = add_floats<4>(compute_tangents(p, normals, atlas_set), false);
      // The frame the source normal map is decoded in (given, or derived as the transfer
      // derives it), so that the glb re-imports -- for validation or a re-bake -- with the
      // material's own frame; TANGENT is the atlas frame for engines.
      if (p.tangents.size() == n) {
        attrs["_SOURCE_TANGENT"] = add_floats<4>(p.tangents, false);
      } else if (normal_set >= 0 && size_t(normal_set) + 1 < p.uvs.size()) {
        attrs["_SOURCE_TANGENT"] = add_floats<4>(compute_tangents(p, normals, normal_set), false);
      }
    } else if (p.tangents.size() == n && n) {
      attrs["TANGENT"] = add_floats<4>(p.tangents, false);
    }
    for (size_t k = 0; k < p.uvs.size(); ++k)
      attrs["TEXCOORD_" + std::to_string(k)] = add_floats<2>(p.uvs[k], false);
    if (p.colors.size() == n && n) attrs["COLOR_0"] = add_floats<4>(p.colors, false);
    json jp = {{"attributes", attrs}, {"mode", 4}};
    jp["indices"] = add_indices(p.indices);
    if (p.material >= 0) jp["material"] = p.material;
    return jp;
  }

  void add_nodes(const Scene& scene) {
    for (const Node& n : scene.nodes) {
      json j = json::object();  // a bare node (no name, mesh or children) is {}, not null
      if (!n.name.empty()) j["name"] = n.name;
      if (n.local != kIdentity) j["matrix"] = n.local;
      if (n.mesh >= 0) j["mesh"] = n.mesh;
      if (n.light >= 0) j["extensions"]["KHR_lights_punctual"]["light"] = n.light;
      if (!n.children.empty()) j["children"] = n.children;
      doc_["nodes"].push_back(j);
    }
    add_lights(scene);
  }

  // KHR_lights_punctual, as gltf_lights.cpp reads it: the unwrapped scene keeps the lights a
  // lit bake was baked with (the validator's reference and a re-bake need them).
  void add_lights(const Scene& scene) {
    if (scene.lights.empty()) return;
    json lights = json::array();
    for (const Light& l : scene.lights) {
      static constexpr const char* kType[] = {"directional", "point", "spot"};
      json j = {{"type", kType[int(l.type)]},
                {"color", {l.color[0], l.color[1], l.color[2]}},
                {"intensity", l.intensity}};
      if (!l.name.empty()) j["name"] = l.name;
      if (l.type != LightType::kDirectional && std::isfinite(l.range)) j["range"] = l.range;
      if (l.type == LightType::kSpot)
        j["spot"] = {{"innerConeAngle", l.inner_cone_angle},
                     {"outerConeAngle", l.outer_cone_angle}};
      lights.push_back(std::move(j));
    }
    doc_["extensions"]["KHR_lights_punctual"]["lights"] = std::move(lights);
    use_extension("KHR_lights_punctual");
    if (options_.lights_required) doc_["extensionsRequired"].push_back("KHR_lights_punctual");
  }

  void use_extension(const char* name) {
    auto& used = doc_["extensionsUsed"];
    for (const auto& e : used)
      if (e == name) return;
    used.push_back(name);
  }

  const GltfWriteOptions& options_;
  std::string out_folder_;  // image uris are written relative to it
  json doc_;
  std::vector<uint8_t> bin_;
};

struct Bytes {
  const void* data;
  size_t size;
};

// Writes `parts` as the whole of PATH through the atomic writer: PATH is never half-written.
Status write_file(const std::string& path, std::initializer_list<Bytes> parts) {
  return write_output(path, [&](const std::string& temp) -> Status {
    std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(temp.c_str(), "wb"), &std::fclose);
    if (!f) return Error(ErrorCode::kIo, path + ": cannot create file");
    bool ok = true;
    for (const Bytes& part : parts)
      ok = ok && (part.size == 0 || std::fwrite(part.data, 1, part.size, f.get()) == part.size);
    ok = std::fclose(f.release()) == 0 && ok;
    return ok ? Status::Ok() : Error(ErrorCode::kIo, path + ": write failed");
  });
}

}  // namespace

Status save_glb(const Scene& scene, const std::string& path) {
  return save_glb(scene, path, GltfWriteOptions{});
}

Status save_glb(const Scene& scene, const std::string& path, const GltfWriteOptions& options) {
  DocumentBuilder builder(options, detail::parent_folder(path));
  VT_RETURN_IF_ERROR(builder.add(scene, path));
  auto [doc, bin] = std::move(builder).finish("");
  std::string text = doc.dump();
  while (text.size() % 4) text.push_back(' ');
  // Header (magic, version, total length), then the JSON and BIN chunks (length, type, data).
  const uint32_t header[5] = {0x46546C67, 2,
                              static_cast<uint32_t>(12 + 8 + text.size() + 8 + bin.size()),
                              static_cast<uint32_t>(text.size()), 0x4E4F534A};
  const uint32_t bin_header[2] = {static_cast<uint32_t>(bin.size()), 0x004E4942};
  return write_file(path, {{header, sizeof(header)},
                           {text.data(), text.size()},
                           {bin_header, sizeof(bin_header)},
                           {bin.data(), bin.size()}});
}

Status save_gltf(const Scene& scene, const std::string& path, const GltfWriteOptions& options) {
  const std::string folder = detail::parent_folder(path);
  const std::string bin_name = std::filesystem::path(path).stem().string() + ".bin";
  DocumentBuilder builder(options, folder);
  VT_RETURN_IF_ERROR(builder.add(scene, path));
  auto [doc, bin] = std::move(builder).finish(bin_name);
  VT_RETURN_IF_ERROR(write_file(folder + bin_name, {{bin.data(), bin.size()}}));
  std::string text = doc.dump(1) + "\n";
  return write_file(path, {{text.data(), text.size()}});
}

}  // namespace vt::scene
