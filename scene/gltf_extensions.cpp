// glTF versions and extensions: which vtbake reads, which it ignores (and what it bakes
// instead), which it refuses when a file requires them.
#include <algorithm>

#include "scene/gltf_import_steps.h"

namespace vt::scene::detail {

using json = nlohmann::json;

namespace {

// How vtbake treats an extension a file uses.
enum class Support {
  kRead,          // read for real: never a warning, fine when required
  kIgnored,       // ignored or approximated with a warning; refused when required
  kApproximated,  // approximated with a warning, fine when required (it is all the file has)
  kSilent,        // does not change what is baked (metadata, animation): no warning
};

struct ExtensionRule {
  const char* name;
  Support support;
  const char* instead;  // what vtbake does instead (kIgnored, kApproximated)
};

// The one list of the extensions vtbake knows.
constexpr ExtensionRule kExtensions[] = {
    {"KHR_draco_mesh_compression", Support::kRead, ""},
    {"KHR_texture_transform", Support::kRead, ""},
    {"KHR_materials_emissive_strength", Support::kRead, ""},
    {"KHR_mesh_quantization", Support::kRead, ""},
    {"EXT_meshopt_compression", Support::kRead, ""},
    {"EXT_texture_webp", Support::kRead, ""},     // OpenImageIO reads WebP
    {"KHR_lights_punctual", Support::kRead, ""},  // baked into the lighting layer
    {"EXT_lights_image_based", Support::kIgnored, "lighting is not baked yet"},
    {"KHR_materials_pbrSpecularGlossiness", Support::kIgnored,
     "diffuse is baked as base colour (metallic 0, roughness 1 - glossiness) where a material "
     "has no metallic-roughness block; specular colour and specularGlossinessTexture are not "
     "baked"},
    {"KHR_materials_clearcoat", Support::kIgnored, "clearcoat is not baked; the base layer is"},
    {"KHR_materials_sheen", Support::kIgnored, "sheen is not baked; the base layer is"},
    {"KHR_materials_transmission", Support::kIgnored,
     "transmission is not baked; the surface is baked as if opaque"},
    {"KHR_materials_diffuse_transmission", Support::kIgnored,
     "diffuse transmission is not baked; the surface is baked as if opaque"},
    {"KHR_materials_volume", Support::kIgnored, "volume is not baked (thin-walled surfaces)"},
    {"KHR_materials_ior", Support::kIgnored, "ior is not baked (1.5 assumed)"},
    {"KHR_materials_specular", Support::kIgnored,
     "specular is not baked (the metallic-roughness default, F0 0.04)"},
    {"KHR_materials_iridescence", Support::kIgnored, "iridescence is not baked"},
    {"KHR_materials_anisotropy", Support::kIgnored,
     "anisotropy is not baked (isotropic roughness)"},
    {"KHR_materials_dispersion", Support::kIgnored, "dispersion is not baked"},
    {"KHR_materials_unlit", Support::kIgnored,
     "baked like a lit material (base colour kept, lit by the validator)"},
    {"KHR_materials_variants", Support::kIgnored, "only the default materials are baked"},
    {"KHR_techniques_webgl", Support::kIgnored,
     "shaders are ignored; the metallic-roughness material is baked"},
    // The pre-release draft (glTF2/BoxTextured-glTF-techniqueWebGL): its materials are glTF 1.0
    // technique values with no metallic-roughness block; the common profile's are mapped
    // (gltf_materials.cpp).
    {"KHR_technique_webgl", Support::kApproximated,
     "shaders are ignored; where a material has no metallic-roughness block, its common-profile "
     "values are baked as metallic-roughness: diffuse as base colour, emission as emissive, "
     "transparency as alpha (BLEND below 1), metallic 0, roughness (2 / (shininess + 2))^(1/4) "
     "(Blinn-Phong to Beckmann); ambient and specular are not baked"},
    {"KHR_materials_cmnBlinnPhong", Support::kIgnored,
     "Blinn-Phong is ignored; the metallic-roughness material is baked"},
    {"KHR_texture_basisu", Support::kIgnored,
     "KTX2 images are not read; each texture's PNG/JPEG fallback source is baked"},
    {"EXT_texture_avif", Support::kIgnored,
     "AVIF images are not read; each texture's fallback source is baked"},
    {"MSFT_texture_dds", Support::kIgnored,
     "DDS images are not read; each texture's fallback source is baked"},
    {"EXT_mesh_gpu_instancing", Support::kIgnored,
     "instances are not expanded; each mesh is baked once at its node"},
    {"MSFT_lod", Support::kSilent, ""},  // the base mesh is the finest level
    {"KHR_animation_pointer", Support::kSilent, ""},
    {"KHR_xmp_json_ld", Support::kSilent, ""},
    {"KHR_xmp", Support::kSilent, ""},
};

const ExtensionRule* find_rule(const std::string& name) {
  for (const ExtensionRule& r : kExtensions)
    if (name == r.name) return &r;
  return nullptr;
}

}  // namespace

std::string gltf_version_text(const json& doc) {
  const auto asset = doc.find("asset");
  if (asset == doc.end() || !asset->is_object()) return "";
  const auto v = asset->find("version");
  if (v == asset->end()) return "";
  return v->is_string() ? v->get<std::string>() : v->dump();
}

bool is_gltf1_document(const json& doc) {
  if (!doc.is_object()) return false;
  for (const char* key : {"meshes", "materials", "nodes", "accessors", "buffers", "scenes"}) {
    auto it = doc.find(key);
    if (it != doc.end() && it->is_object()) return true;
  }
  const std::string v = gltf_version_text(doc);
  return v.rfind("1", 0) == 0 || v.rfind("0.", 0) == 0;
}

Status check_version(const Gltf& g, Warnings* warnings) {
  const char* kConvert =
      " (convert it to glTF 2.0, e.g. with `assimp export FILE out.glb -f glb2` from Debian's "
      "assimp-utils, or `gltf-pipeline -i FILE -o out.glb`)";
  if (is_gltf1_document(g.doc)) {
    const std::string v = gltf_version_text(g.doc);
    return Error(ErrorCode::kUnsupported,
                 g.path + ": glTF " + (v.empty() ? "1.0" : v) + " is not supported" + kConvert);
  }
  auto asset = g.doc.find("asset");
  const json* version = nullptr;
  if (asset != g.doc.end() && asset->is_object() && asset->contains("version"))
    version = &(*asset)["version"];
  if (!version) {
    warnings->push_back(g.path + ": asset.version is missing; read as glTF 2.0");
    return Status::Ok();
  }
  if (!version->is_string() || gltf_version_text(g.doc).rfind("2", 0) != 0)
    return Error(ErrorCode::kUnsupported, g.path + ": asset.version " + version->dump() +
                                              " is not supported (vtbake reads glTF 2.x)");
  return Status::Ok();
}

Status check_required_extensions(const JsonFields& root) {
  for (const std::string& name : root.strings("extensionsRequired")) {
    const ExtensionRule* rule = find_rule(name);
    bool ok = rule && (rule->support == Support::kRead || rule->support == Support::kApproximated);
    if (!ok)
      return Error(ErrorCode::kUnsupported,
                   root.errors()->gltf().path + ": required extension " + name +
                       " is not supported" +
                       (rule ? std::string(" (") + rule->instead + ")" : std::string()));
  }
  return root.errors()->status();
}

void warn_about_extensions(const JsonFields& root, const ExtensionUses& material_uses,
                           Warnings* warnings) {
  std::vector<std::string> names = root.strings("extensionsUsed");
  for (const std::string& n : root.strings("extensionsRequired")) names.push_back(n);
  for (const auto& [name, count] : material_uses) names.push_back(name);
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  const std::string& path = root.errors()->gltf().path;
  for (const std::string& name : names) {
    const ExtensionRule* rule = find_rule(name);
    if (rule && (rule->support == Support::kRead || rule->support == Support::kSilent)) continue;
    std::string line = path + ": " + name + ": ";
    auto uses = material_uses.find(name);
    if (!rule)
      line += "not known to vtbake; ignored";
    else
      line += rule->instead;
    if (uses != material_uses.end())
      line +=
          " (" + std::to_string(uses->second) + (uses->second == 1 ? " material)" : " materials)");
    warnings->push_back(line);
  }
}

}  // namespace vt::scene::detail
