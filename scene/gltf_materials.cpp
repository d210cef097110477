// glTF 2.0 materials: metallic-roughness with every textureInfo's sampler, texCoord and
// KHR_texture_transform, KHR_materials_emissive_strength, KHR_materials_pbrSpecularGlossiness
// approximated by its diffuse part, and the draft KHR_technique_webgl's common-profile values
// approximated likewise.
#include <algorithm>
#include <climits>
#include <cmath>

#include "scene/gltf_import_steps.h"

namespace vt::scene::detail {

namespace {

using json = nlohmann::json;

// The pre-release draft (COLLADA2GLTF writes it), not the later KHR_techniques_webgl.
constexpr const char* kTechniqueExtension = "KHR_technique_webgl";

// GL enums of technique parameter types and states (glTF 1.0).
constexpr size_t kGlFloat = 5126;
constexpr size_t kGlFloatVec3 = 35665;
constexpr size_t kGlFloatVec4 = 35666;
constexpr size_t kGlSampler2d = 35678;
constexpr size_t kGlCullFace = 2884;
constexpr size_t kGlBlend = 3042;

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
  const std::vector<JsonFields>& techniques;  // KHR_technique_webgl's
  bool reads_techniques;                      // the file declares KHR_technique_webgl
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
    return with_texture(ref, t, info, info.where());
  }

  // `ref` reading texture `t` (-1: none) with its image and sampler; `where` names the field
  // of `object` that gave `t`.
  TextureRef with_texture(TextureRef ref, int t, const JsonFields& object,
                          const std::string& where) const {
    if (t < 0) return ref;
    const Texture& tex = textures[t];
    if (tex.image < 0)
      warnings->push_back(object.errors()->gltf().path + ": " + where + ": texture " +
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

  // KHR_technique_webgl, for a material without a metallic-roughness block: its values are
  // glTF 1.0 technique parameters, here the common profile's (the names KHR_materials_common
  // uses: ambient, diffuse, emission, specular, shininess, transparency). Each value's type is
  // its parameter's; a material without the value takes the parameter's default `value`.
  // diffuse becomes base colour, emission emissive, transparency alpha, and shininess (a
  // Blinn-Phong exponent s) roughness: the Beckmann slope that matches s is
  // alpha = sqrt(2 / (s + 2)) (Walter et al. 2007) and glTF's alpha is roughness^2, so
  // roughness = (2 / (s + 2))^(1/4). It is a dielectric; ambient and specular are type-checked,
  // not baked.
  void technique_values(const JsonFields& m, Material* mat) const {
    const int t = m.index("technique", "techniques");
    if (t < 0 || static_cast<size_t>(t) >= techniques.size()) return;  // reported by index()
    const JsonFields& tech = techniques[t];
    const std::string technique_name = "technique " + std::to_string(t);
    JsonFields params = tech.object("parameters");
    JsonFields values = m.object("values");
    for (const std::string& key : values.keys())
      if (!params.has(key.c_str()))
        values.fail(key, "'" + key + "' is not a parameter of " + technique_name);
    JsonFields uniforms = tech.object("uniforms");
    for (const std::string& u : uniforms.keys()) {
      std::string p = uniforms.string(u.c_str());
      if (!p.empty() && !params.has(p.c_str()))
        uniforms.fail(u, "'" + p + "' is not a parameter of " + technique_name);
    }
    tech.index("program", "programs");

    // Every value in an object JsonFields reads with the usual checks and paths: the
    // material's under its own name (MATERIAL.values.diffuse), a default under "NAME.value"
    // (TECHNIQUE.parameters.diffuse.value). glTF 1.0 writes a scalar bare or as an array of
    // one (COLLADA2GLTF always wraps it): unwrapped here.
    json own = json::object(), defaults = json::object();
    std::map<std::string, size_t> types;
    const auto scalar = [](size_t type) { return type == kGlFloat || type == kGlSampler2d; };
    for (const char* name :
         {"ambient", "diffuse", "emission", "specular", "shininess", "transparency"}) {
      const bool in_values = values.has(name);
      if (!params.has(name)) continue;  // a value without a parameter failed above
      JsonFields p = params.object(name);
      if (!in_values && !p.has("value")) continue;
      if (!p.has("type")) {
        p.fail("type", "expected a GL type");
        continue;
      }
      const size_t type = p.count("type", 0);
      const bool is_float = std::string(name) == "shininess" || std::string(name) == "transparency";
      if (is_float ? type != kGlFloat
                   : type != kGlFloatVec3 && type != kGlFloatVec4 && type != kGlSampler2d) {
        p.fail("type", std::to_string(type) +
                           (is_float ? " is not 5126 FLOAT"
                                     : " is not 35665 FLOAT_VEC3, 35666 FLOAT_VEC4 or 35678 "
                                       "SAMPLER_2D"));
        continue;
      }
      types[name] = type;
      const json& v = in_values ? values.raw().at(name) : p.raw().at("value");
      const json unwrapped = scalar(type) && v.is_array() && v.size() == 1 ? v[0] : v;
      if (in_values)
        own[name] = unwrapped;
      else
        defaults[std::string(name) + ".value"] = unwrapped;
    }
    const JsonFields own_fields(m.errors(), own, values.where());
    const JsonFields default_fields(m.errors(), defaults, params.where());
    // Where value `name` is read from: (object, key), object null when absent.
    const auto at = [&](const std::string& name) -> std::pair<const JsonFields*, std::string> {
      if (own.contains(name)) return {&own_fields, name};
      if (defaults.contains(name + ".value")) return {&default_fields, name + ".value"};
      return {nullptr, ""};
    };
    // A colour value: a texture (SAMPLER_2D, texCoord 0) or an RGB(A) factor; false when absent.
    const auto colour = [&](const char* name, Vec4* factor, TextureRef* texture) {
      auto [object, key] = at(name);
      if (!object) return false;
      if (types[name] == kGlSampler2d) {
        *texture = with_texture(TextureRef{}, object->index(key.c_str(), "textures"), *object,
                                object->where(key));
        *factor = {1, 1, 1, 1};
      } else if (types[name] == kGlFloatVec4) {
        *factor = object->floats<4>(key.c_str(), *factor);
      } else {
        auto rgb = object->floats<3>(key.c_str(), {(*factor)[0], (*factor)[1], (*factor)[2]});
        *factor = {rgb[0], rgb[1], rgb[2], 1};
      }
      return true;
    };
    const auto number = [&](const char* name, double fallback, double low, double high,
                            const char* range) {
      auto [object, key] = at(name);
      if (!object) return fallback;
      double v = object->number(key.c_str(), fallback);
      if (v < low || v > high) object->fail(key, std::string("expected a number ") + range);
      return std::clamp(v, low, high);
    };

    mat->base_color_factor = {1, 1, 1, 1};
    colour("diffuse", &mat->base_color_factor, &mat->base_color_texture);
    Vec4 emission = {0, 0, 0, 1};
    if (colour("emission", &emission, &mat->emissive_texture))
      mat->emissive_factor = {emission[0], emission[1], emission[2]};
    Vec4 unused{};
    TextureRef unused_texture;
    colour("ambient", &unused, &unused_texture);  // checked, not baked
    colour("specular", &unused, &unused_texture);
    mat->metallic_factor = 0;
    if (at("shininess").first) {
      const double s = number("shininess", 0, 0, HUGE_VAL, "from 0 up");
      mat->roughness_factor = static_cast<float>(std::pow(2 / (s + 2), 0.25));
    }
    const double transparency = number("transparency", 1, 0, 1, "from 0 to 1");
    mat->base_color_factor[3] *= static_cast<float>(transparency);
    // glTF 1.0 states: every GL state not enabled is disabled, so without CULL_FACE both sides
    // are drawn, and alpha blends only with BLEND (or the common profile's transparency < 1).
    std::vector<double> enabled = enabled_states(tech);
    const auto on = [&](size_t state) {
      return std::find(enabled.begin(), enabled.end(), static_cast<double>(state)) != enabled.end();
    };
    mat->double_sided = !on(kGlCullFace);
    if (on(kGlBlend) || transparency < 1) mat->alpha_mode = AlphaMode::kBlend;
  }

  // A technique's states.enable: GL enums.
  static std::vector<double> enabled_states(const JsonFields& tech) {
    JsonFields states = tech.object("states");
    if (!states.has("enable")) return {};
    const json& enable = states.raw().at("enable");
    if (!enable.is_array()) {
      states.fail("enable", "expected an array of GL enums");
      return {};
    }
    return states.numbers("enable", enable.size());
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
    if (reads_techniques && m.has("technique") && !m.has("pbrMetallicRoughness")) {
      technique_values(m, &mat);
      ++(*uses)[kTechniqueExtension];
    }
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
  // The draft's techniques, read only when the file declares it: without it a material's
  // `technique` is an unknown property, ignored as glTF 2.0 says.
  std::vector<std::string> declared = root.strings("extensionsUsed");
  for (const std::string& n : root.strings("extensionsRequired")) declared.push_back(n);
  const bool reads_techniques =
      std::find(declared.begin(), declared.end(), kTechniqueExtension) != declared.end();
  std::vector<JsonFields> techniques;
  if (reads_techniques) techniques = root.objects("techniques");
  MaterialReader reader{textures, techniques, reads_techniques, warnings};
  std::vector<Material> materials;
  for (const JsonFields& m : root.objects("materials")) materials.push_back(reader.read(m, uses));
  return materials;
}

}  // namespace vt::scene::detail
