// glTF 2.0 materials: metallic-roughness with every textureInfo's sampler, texCoord and
// KHR_texture_transform, KHR_materials_emissive_strength, and KHR_materials_pbrSpecularGlossiness
// approximated by its diffuse part.
#include <algorithm>
#include <climits>

#include "scene/gltf_import_steps.h"

namespace vt::scene::detail {

namespace {

// A texture with its sampler applied; image -1 when it has no image vtbake reads.
struct Texture {
  int image = -1;
  std::string no_image_reason;  // why image is -1
  WrapMode wrap_s = WrapMode::kRepeat;
  WrapMode wrap_t = WrapMode::kRepeat;
  FilterMode mag_filter = FilterMode::kLinear;
};

WrapMode wrap_mode(const JsonFields& sampler, const char* key) {
  size_t v = sampler.count(key, 10497);
  if (v == 10497) return WrapMode::kRepeat;
  if (v == 33071) return WrapMode::kClampToEdge;
  if (v == 33648) return WrapMode::kMirroredRepeat;
  sampler.fail(key, std::to_string(v) +
                        " is not a wrap mode (10497 REPEAT, 33071 CLAMP_TO_EDGE or 33648 "
                        "MIRRORED_REPEAT)");
  return WrapMode::kRepeat;
}

FilterMode mag_filter(const JsonFields& sampler) {
  size_t v = sampler.count("magFilter", 9729);
  if (v == 9728) return FilterMode::kNearest;
  if (v != 9729)
    sampler.fail("magFilter", std::to_string(v) + " is not 9728 NEAREST or 9729 LINEAR");
  return FilterMode::kLinear;
}

std::vector<Texture> load_textures(const JsonFields& root) {
  struct Sampler {
    WrapMode s, t;
    FilterMode mag;
  };
  std::vector<Sampler> samplers;
  for (const JsonFields& s : root.objects("samplers")) {
    s.count("minFilter", 0);  // mip filtering is the baker's own
    samplers.push_back({wrap_mode(s, "wrapS"), wrap_mode(s, "wrapT"), mag_filter(s)});
  }
  std::vector<Texture> textures;
  for (const JsonFields& t : root.objects("textures")) {
    Texture tex;
    JsonFields ext = t.object("extensions");
    tex.image = t.index("source", "images");
    // The image of an extension this texture alone provides (no fallback `source`).
    int webp = ext.object("EXT_texture_webp").index("source", "images");
    if (tex.image < 0) tex.image = webp;
    for (const char* unread : {"KHR_texture_basisu", "EXT_texture_avif", "MSFT_texture_dds"})
      if (ext.object(unread).index("source", "images") >= 0 && tex.image < 0)
        tex.no_image_reason = std::string("its only image is a ") + unread + " one";
    if (tex.image < 0 && tex.no_image_reason.empty()) tex.no_image_reason = "it has no source";
    int s = t.index("sampler", "samplers");
    if (s >= 0 && s < static_cast<int>(samplers.size())) {
      tex.wrap_s = samplers[s].s;
      tex.wrap_t = samplers[s].t;
      tex.mag_filter = samplers[s].mag;
    }
    textures.push_back(tex);
  }
  return textures;
}

struct MaterialReader {
  const std::vector<Texture>& textures;
  Warnings* warnings;

  // The textureInfo `key` of `parent`; unused when absent.
  TextureRef slot(const JsonFields& parent, const char* key) const {
    TextureRef ref;
    if (!parent.has(key)) return ref;
    JsonFields info = parent.object(key);
    if (!info.has("index")) info.fail("index", "expected a texture index");
    int t = info.index("index", "textures");
    auto set = [](size_t v) { return static_cast<int>(std::min<size_t>(v, INT_MAX)); };
    ref.texcoord = set(info.count("texCoord", 0));
    JsonFields ext = info.object("extensions");
    if (ext.has("KHR_texture_transform")) {
      JsonFields tt = ext.object("KHR_texture_transform");
      ref.transform.offset = tt.floats<2>("offset", {0, 0});
      ref.transform.rotation = static_cast<float>(tt.number("rotation", 0));
      ref.transform.scale = tt.floats<2>("scale", {1, 1});
      ref.texcoord = set(tt.count("texCoord", ref.texcoord));
    }
    if (t < 0) return ref;
    const Texture& tex = textures[t];
    if (tex.image < 0)
      warnings->push_back(info.errors()->gltf().path + ": " + info.where() + ": texture " +
                          std::to_string(t) + " has no image vtbake reads (" + tex.no_image_reason +
                          "); the slot bakes its factor alone");
    ref.image = tex.image;
    ref.wrap_s = tex.wrap_s;
    ref.wrap_t = tex.wrap_t;
    ref.mag_filter = tex.mag_filter;
    return ref;
  }

  float non_negative(const JsonFields& object, const char* key, double fallback) const {
    double v = object.number(key, fallback);
    if (v < 0) object.fail(key, "expected a non-negative number");
    return static_cast<float>(std::max(v, 0.0));
  }

  // KHR_materials_pbrSpecularGlossiness, for a material without a metallic-roughness block:
  // diffuse becomes base colour, glossiness becomes 1 - roughness, and it is a dielectric.
  void specular_glossiness(const JsonFields& sg, Material* mat) const {
    mat->base_color_factor = sg.floats<4>("diffuseFactor", {1, 1, 1, 1});
    mat->base_color_texture = slot(sg, "diffuseTexture");
    mat->metallic_factor = 0;
    mat->roughness_factor =
        1 - std::clamp(static_cast<float>(sg.number("glossinessFactor", 1)), 0.0f, 1.0f);
    sg.numbers("specularFactor", 3);        // type-checked, not baked
    slot(sg, "specularGlossinessTexture");  // index-checked, not baked
  }

  Material read(const JsonFields& m, ExtensionUses* uses) const {
    Material mat;
    mat.name = m.string("name");
    JsonFields pbr = m.object("pbrMetallicRoughness");
    mat.base_color_factor = pbr.floats<4>("baseColorFactor", {1, 1, 1, 1});
    mat.base_color_texture = slot(pbr, "baseColorTexture");
    mat.metallic_factor = static_cast<float>(pbr.number("metallicFactor", 1));
    mat.roughness_factor = static_cast<float>(pbr.number("roughnessFactor", 1));
    mat.metallic_roughness_texture = slot(pbr, "metallicRoughnessTexture");
    mat.normal_texture = slot(m, "normalTexture");
    mat.normal_scale = static_cast<float>(m.object("normalTexture").number("scale", 1));
    mat.occlusion_texture = slot(m, "occlusionTexture");
    mat.occlusion_strength = static_cast<float>(m.object("occlusionTexture").number("strength", 1));
    mat.emissive_factor = m.floats<3>("emissiveFactor", {0, 0, 0});
    mat.emissive_texture = slot(m, "emissiveTexture");
    std::string alpha = m.string("alphaMode", "OPAQUE");
    if (alpha == "MASK")
      mat.alpha_mode = AlphaMode::kMask;
    else if (alpha == "BLEND")
      mat.alpha_mode = AlphaMode::kBlend;
    else if (alpha != "OPAQUE")
      m.fail("alphaMode", "'" + alpha + "' is not OPAQUE, MASK or BLEND");
    mat.alpha_cutoff = non_negative(m, "alphaCutoff", 0.5);
    mat.double_sided = m.boolean("doubleSided", false);
    mat.texels_per_unit = density_extra(m);

    JsonFields ext = m.object("extensions");
    for (const std::string& name : ext.keys()) ++(*uses)[name];
    mat.emissive_strength =
        non_negative(ext.object("KHR_materials_emissive_strength"), "emissiveStrength", 1);
    if (ext.has("KHR_materials_pbrSpecularGlossiness") && !m.has("pbrMetallicRoughness"))
      specular_glossiness(ext.object("KHR_materials_pbrSpecularGlossiness"), &mat);
    return mat;
  }
};

}  // namespace

double density_extra(const JsonFields& object) {
  const auto& raw = object.raw();
  if (!raw.is_object() || !raw.contains("extras") || !raw["extras"].is_object()) return 0;
  JsonFields extras = object.object("extras");
  if (!extras.has("vtbake_texels_per_unit")) return 0;
  const double v = extras.number("vtbake_texels_per_unit", 0);
  if (!(v > 0))
    extras.fail("vtbake_texels_per_unit", "expected a positive number (texels per world unit)");
  return std::max(v, 0.0);
}

std::vector<Material> load_materials(const JsonFields& root, ExtensionUses* uses,
                                     Warnings* warnings) {
  std::vector<Texture> textures = load_textures(root);
  MaterialReader reader{textures, warnings};
  std::vector<Material> materials;
  for (const JsonFields& m : root.objects("materials")) materials.push_back(reader.read(m, uses));
  return materials;
}

}  // namespace vt::scene::detail
