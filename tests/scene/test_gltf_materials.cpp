// The glTF 2.0 material model and document rules on small files written by the tests:
// textureInfo samplers, texCoord sets and KHR_texture_transform, emissive strength, the
// specular-glossiness and KHR_technique_webgl fallbacks, extension rules and warnings, glTF 1.0,
// node-graph and index checks, and typed errors that name the file and the field.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "scene/scene.h"
#include "scene/scene_io_util.h"

namespace vt::test {
namespace {

using json = nlohmann::json;
using scene::FilterMode;
using scene::WrapMode;

std::string temp(const std::string& name) {
  return ::testing::TempDir() + "vt_gltf_mat_" + name;
}

// One triangle (positions, two UV sets) in a data: buffer, a material using texture 0 for
// base colour, one image, texture and sampler, and two nodes (parent "a" with child "b").
json triangle_doc() {
  float data[3 * 3 + 2 * 3 * 2] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  std::string uri =
      "data:application/octet-stream;base64," +
      scene::detail::base64_encode(reinterpret_cast<const uint8_t*>(data), sizeof(data));
  json doc = {{"asset", {{"version", "2.0"}}},
              {"buffers", {{{"uri", uri}, {"byteLength", sizeof(data)}}}},
              {"bufferViews",
               {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
                {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 24}},
                {{"buffer", 0}, {"byteOffset", 60}, {"byteLength", 24}}}},
              {"accessors",
               {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}},
                {{"bufferView", 1}, {"componentType", 5126}, {"count", 3}, {"type", "VEC2"}},
                {{"bufferView", 2}, {"componentType", 5126}, {"count", 3}, {"type", "VEC2"}}}},
              {"images", {{{"uri", "albedo.png"}}}},
              {"samplers", {json::object()}},
              {"textures", {{{"source", 0}, {"sampler", 0}}}},
              {"materials",
               {{{"name", "m"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}}},
              {"meshes",
               {{{"name", "tri"},
                 {"primitives",
                  {{{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}, {"TEXCOORD_1", 2}}},
                    {"material", 0}}}}}}},
              {"nodes", {{{"name", "a"}, {"children", {1}}}, {{"name", "b"}, {"mesh", 0}}}},
              {"scenes", {{{"nodes", {0}}}}},
              {"scene", 0}};
  return doc;
}

Expected<scene::Scene> load_text(const std::string& name, const std::string& text) {
  std::ofstream(temp(name), std::ios::binary) << text;
  return scene::load_scene(temp(name));
}
Expected<scene::Scene> load(const std::string& name, const json& doc) {
  return load_text(name, doc.dump());
}

// The load fails with `code` and a message that names the file and contains `part`.
void expect_error(const Expected<scene::Scene>& s, const std::string& name, ErrorCode code,
                  const std::string& part) {
  ASSERT_FALSE(s.ok()) << name << " loaded";
  EXPECT_EQ(s.status().code(), code) << s.status().message();
  EXPECT_EQ(s.status().message().rfind(temp(name) + ": ", 0), 0u) << s.status().message();
  EXPECT_NE(s.status().message().find(part), std::string::npos) << s.status().message();
  EXPECT_EQ(s.status().message().find("json.exception"), std::string::npos) << s.status().message();
}

// The load succeeded with exactly these warnings (each after "FILE: ").
void expect_warnings(const Expected<scene::Scene>& s, const std::string& name,
                     const std::vector<std::string>& texts) {
  ASSERT_TRUE(s.ok()) << s.status().message();
  std::vector<std::string> expected;
  for (const std::string& t : texts) expected.push_back(temp(name) + ": " + t);
  EXPECT_EQ(s->warnings, expected);
}

// triangle_doc() with one field replaced, and the error that must name it.
struct BadField {
  const char* name;
  json::json_pointer field;
  json value;
  const char* message;
};

void expect_each_fails(const std::vector<BadField>& cases, const std::string& prefix) {
  for (const BadField& c : cases) {
    json doc = triangle_doc();
    doc[c.field] = c.value;
    std::string file = prefix + c.name + ".gltf";
    expect_error(load(file, doc), file, ErrorCode::kCorrupt, c.message);
  }
}

TEST(GltfMaterials, SamplerModesTexCoordAndTextureTransformParsedExactly) {
  json doc = triangle_doc();
  doc["samplers"] = {{{"wrapS", 33648}, {"wrapT", 33071}, {"magFilter", 9728}, {"minFilter", 9987}},
                     json::object()};
  doc["textures"].push_back({{"source", 0}, {"sampler", 1}});
  json& m = doc["materials"][0];
  m["pbrMetallicRoughness"]["baseColorTexture"] = {
      {"index", 0},
      {"texCoord", 1},
      {"extensions",
       {{"KHR_texture_transform",
         {{"offset", {0.25, -0.5}}, {"rotation", 0.75}, {"scale", {2, 3}}}}}}};
  // texCoord 0 in the textureInfo, overridden to 1 by the extension.
  m["occlusionTexture"] = {{"index", 1},
                           {"strength", 0.5},
                           {"extensions", {{"KHR_texture_transform", {{"texCoord", 1}}}}}};
  m["emissiveTexture"] = {{"index", 1}, {"texCoord", 1}};
  doc["extensionsUsed"] = {"KHR_texture_transform"};
  auto s = load("transform.gltf", doc);
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_TRUE(s->warnings.empty());
  const scene::Material& mat = s->materials[0];
  const scene::TextureRef& base = mat.base_color_texture;
  EXPECT_EQ(base.image, 0);
  EXPECT_EQ(base.texcoord, 1);
  EXPECT_EQ(base.wrap_s, WrapMode::kMirroredRepeat);
  EXPECT_EQ(base.wrap_t, WrapMode::kClampToEdge);
  EXPECT_EQ(base.mag_filter, FilterMode::kNearest);
  EXPECT_EQ(base.transform.offset, (scene::Vec2{0.25f, -0.5f}));
  EXPECT_EQ(base.transform.rotation, 0.75f);
  EXPECT_EQ(base.transform.scale, (scene::Vec2{2.0f, 3.0f}));
  const scene::TextureRef& occ = mat.occlusion_texture;
  EXPECT_EQ(occ.texcoord, 1);
  EXPECT_TRUE(occ.transform.identity());
  EXPECT_EQ(occ.wrap_s, WrapMode::kRepeat);
  EXPECT_EQ(occ.mag_filter, FilterMode::kLinear);
  EXPECT_EQ(mat.occlusion_strength, 0.5f);
  EXPECT_EQ(mat.emissive_texture.texcoord, 1);
  EXPECT_FALSE(mat.normal_texture.valid());
  EXPECT_EQ(s->meshes[0].primitives[0].uvs.size(), 2u);
}

TEST(GltfMaterials, EmissiveStrength) {
  json doc = triangle_doc();
  doc["materials"][0]["emissiveFactor"] = {1, 0.5, 0.25};
  doc["materials"][0]["extensions"] = {
      {"KHR_materials_emissive_strength", {{"emissiveStrength", 4}}}};
  doc["extensionsUsed"] = {"KHR_materials_emissive_strength"};
  doc["extensionsRequired"] = {"KHR_materials_emissive_strength"};
  auto s = load("emissive.gltf", doc);
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->materials[0].emissive_strength, 4.0f);
  EXPECT_EQ(s->materials[0].emissive_factor, (scene::Vec3{1, 0.5f, 0.25f}));
  EXPECT_TRUE(s->warnings.empty());

  doc["materials"][0]["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] = -1;
  expect_error(load("emissive_neg.gltf", doc), "emissive_neg.gltf", ErrorCode::kCorrupt,
               "materials[0] 'm'.extensions.KHR_materials_emissive_strength.emissiveStrength: "
               "expected a non-negative number");
}

// KHR_lights_punctual, required as Blender writes it: read without a warning, in the
// extension's units, placed by nodes (a node's world transform moves and turns its light).
json lights_doc() {
  json doc = triangle_doc();
  doc["extensionsUsed"] = {"KHR_lights_punctual"};
  doc["extensionsRequired"] = {"KHR_lights_punctual"};
  doc["extensions"] = {
      {"KHR_lights_punctual",
       {{"lights",
         {{{"name", "Sun"}, {"type", "directional"}, {"intensity", 3}, {"color", {1, 0.5, 0.25}}},
          {{"name", "Bulb"}, {"type", "point"}, {"intensity", 100}, {"range", 20}},
          {{"name", "Cone"},
           {"type", "spot"},
           {"spot", {{"innerConeAngle", 0.25}, {"outerConeAngle", 0.5}}}}}}}}};
  // Node "a" (the parent) moves by (1, 2, 3); node "c", its child, turns 90 degrees about +X
  // (quaternion x = sin 45) and holds the spot; "b" holds the sun, "d" (not shown) the bulb.
  doc["nodes"][0]["translation"] = {1, 2, 3};
  doc["nodes"][0]["children"] = {1, 2};
  doc["nodes"][1]["extensions"]["KHR_lights_punctual"]["light"] = 0;
  doc["nodes"].push_back({{"name", "c"},
                          {"rotation", {0.70710678, 0, 0, 0.70710678}},
                          {"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}});
  doc["nodes"].push_back(
      {{"name", "d"}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  return doc;
}

TEST(GltfMaterials, LightsAreReadWithoutWarningEvenWhenRequired) {
  auto s = load("lights.gltf", lights_doc());
  ASSERT_NO_FATAL_FAILURE(expect_warnings(s, "lights.gltf", {}));
  ASSERT_EQ(s->lights.size(), 3u);
  const scene::Light& sun = s->lights[0];
  EXPECT_EQ(sun.type, scene::LightType::kDirectional);
  EXPECT_EQ(sun.intensity, 3.0f);
  EXPECT_EQ(sun.color, (scene::Vec3{1, 0.5f, 0.25f}));
  const scene::Light& bulb = s->lights[1];
  EXPECT_EQ(bulb.type, scene::LightType::kPoint);
  EXPECT_EQ(bulb.intensity, 100.0f);
  EXPECT_EQ(bulb.range, 20.0f);
  const scene::Light& cone = s->lights[2];
  EXPECT_EQ(cone.type, scene::LightType::kSpot);
  EXPECT_EQ(cone.intensity, 1.0f);  // the extension's default
  EXPECT_TRUE(std::isinf(cone.range));
  EXPECT_EQ(cone.inner_cone_angle, 0.25f);
  EXPECT_EQ(cone.outer_cone_angle, 0.5f);

  // Only displayed nodes place lights: "d" is in no scene.
  std::vector<scene::PlacedLight> placed = s->placed_lights();
  ASSERT_EQ(placed.size(), 2u);
  EXPECT_EQ(placed[0].light, 0);
  EXPECT_EQ(placed[0].position, (std::array<double, 3>{1, 2, 3}));
  EXPECT_EQ(placed[0].direction, (std::array<double, 3>{0, 0, -1}));
  EXPECT_EQ(placed[1].light, 2);
  EXPECT_EQ(placed[1].position, (std::array<double, 3>{1, 2, 3}));
  // -Z turned 90 degrees about +X points along +Y.
  EXPECT_NEAR(placed[1].direction[0], 0, 1e-7);
  EXPECT_NEAR(placed[1].direction[1], 1, 1e-7);
  EXPECT_NEAR(placed[1].direction[2], 0, 1e-7);
}

TEST(GltfMaterials, BadLightValuesAreErrorsNamingTheLight) {
  const char* kLights = "/extensions/KHR_lights_punctual/lights";
  struct Case {
    std::string pointer;
    json value;
    const char* part;
  } cases[] = {
      {"/1/intensity", -2, "lights[1] 'Bulb': intensity -2 is not a number >= 0"},
      {"/0/color", {1, -1, 0}, "lights[0] 'Sun': color component -1 is not >= 0"},
      {"/1/range", 0, "lights[1] 'Bulb': range 0 is not > 0"},
      {"/1/range", -5, "lights[1] 'Bulb': range -5 is not > 0"},
      {"/2/spot/innerConeAngle", 0.75, "lights[2] 'Cone': innerConeAngle 0.75 is not below"},
      {"/2/spot/outerConeAngle", 2, "lights[2] 'Cone': outerConeAngle 2 is not <= pi / 2"},
      {"/2/spot/innerConeAngle", -0.1, "innerConeAngle -0.1 is not >= 0"},
      {"/0/type", "sun", "lights[0] 'Sun'.type: 'sun' is not directional, point or spot"},
      {"/0/intensity", "bright", "lights[0] 'Sun'.intensity: expected a number"},
  };
  for (const Case& c : cases) {
    json doc = lights_doc();
    doc[json::json_pointer(kLights + c.pointer)] = c.value;
    SCOPED_TRACE(c.part);
    expect_error(load("bad_light.gltf", doc), "bad_light.gltf", ErrorCode::kCorrupt, c.part);
  }
  json doc = lights_doc();
  doc["nodes"][2]["extensions"]["KHR_lights_punctual"]["light"] = 7;
  expect_error(load("bad_light.gltf", doc), "bad_light.gltf", ErrorCode::kCorrupt,
               "light 7 does not exist (the file has 3 KHR_lights_punctual lights)");
}

TEST(GltfMaterials, UnsupportedRequiredExtensionIsRefusedByName) {
  json doc = triangle_doc();
  doc["extensionsRequired"] = {"KHR_texture_transform", "VENDOR_magic"};
  expect_error(load("required.gltf", doc), "required.gltf", ErrorCode::kUnsupported,
               "required extension VENDOR_magic is not supported");
  doc["extensionsRequired"] = {"KHR_materials_clearcoat"};
  expect_error(load("required2.gltf", doc), "required2.gltf", ErrorCode::kUnsupported,
               "required extension KHR_materials_clearcoat is not supported");
}

TEST(GltfMaterials, UsedAppearanceExtensionsWarnOnceEach) {
  json doc = triangle_doc();
  json clearcoat = {{"KHR_materials_clearcoat", {{"clearcoatFactor", 1}}}};
  doc["materials"][0]["extensions"] = clearcoat;
  doc["materials"].push_back({{"name", "n"}, {"extensions", clearcoat}});
  doc["extensionsUsed"] = {"KHR_materials_clearcoat", "KHR_materials_sheen", "VENDOR_thing",
                           "KHR_xmp_json_ld"};
  auto s = load("used.gltf", doc);
  ASSERT_NO_FATAL_FAILURE(
      expect_warnings(s, "used.gltf",
                      {"KHR_materials_clearcoat: clearcoat is not baked; the base layer is (2 "
                       "materials)",
                       "KHR_materials_sheen: sheen is not baked; the base layer is",
                       "VENDOR_thing: not known to vtbake; ignored"}));
}

TEST(GltfMaterials, SpecularGlossinessFallsBackToDiffuse) {
  json doc = triangle_doc();
  doc["materials"][0] = {{"name", "sg"},
                         {"extensions",
                          {{"KHR_materials_pbrSpecularGlossiness",
                            {{"diffuseFactor", {0.5, 0.25, 1, 0.75}},
                             {"diffuseTexture", {{"index", 0}, {"texCoord", 1}}},
                             {"specularFactor", {1, 1, 1}},
                             {"glossinessFactor", 0.25}}}}}};
  doc["extensionsUsed"] = {"KHR_materials_pbrSpecularGlossiness"};
  auto s = load("specgloss.gltf", doc);
  ASSERT_NO_FATAL_FAILURE(expect_warnings(
      s, "specgloss.gltf",
      {"KHR_materials_pbrSpecularGlossiness: diffuse is baked as base colour (metallic 0, "
       "roughness 1 - glossiness) where a material has no metallic-roughness block; specular "
       "colour and specularGlossinessTexture are not baked (1 material)"}));
  const scene::Material& m = s->materials[0];
  EXPECT_EQ(m.base_color_factor, (scene::Vec4{0.5f, 0.25f, 1, 0.75f}));
  EXPECT_EQ(m.base_color_texture.image, 0);
  EXPECT_EQ(m.base_color_texture.texcoord, 1);
  EXPECT_EQ(m.metallic_factor, 0.0f);
  EXPECT_EQ(m.roughness_factor, 0.75f);

  // A material with its own metallic-roughness block keeps it.
  doc["materials"][0]["pbrMetallicRoughness"] = {{"baseColorFactor", {1, 0, 0, 1}},
                                                 {"metallicFactor", 0.5}};
  auto kept = load("specgloss_mr.gltf", doc);
  ASSERT_TRUE(kept.ok()) << kept.status().message();
  EXPECT_EQ(kept->materials[0].base_color_factor, (scene::Vec4{1, 0, 0, 1}));
  EXPECT_EQ(kept->materials[0].metallic_factor, 0.5f);
  EXPECT_FALSE(kept->materials[0].base_color_texture.valid());
}

// triangle_doc() with its material as the draft KHR_technique_webgl writes it
// (COLLADA2GLTF, glTF2/BoxTextured-glTF-techniqueWebGL): common-profile values typed by
// technique 0's parameters, diffuse a texture, every value wrapped in an array.
json technique_doc() {
  json doc = triangle_doc();
  doc["materials"][0] = {{"name", "t"},
                         {"technique", 0},
                         {"values",
                          {{"diffuse", {0}},
                           {"specular", {0.2, 0.2, 0.2, 1}},
                           {"shininess", {256}},
                           {"transparency", {1}}}}};
  doc["techniques"] = {{{"parameters",
                         {{"diffuse", {{"type", 35678}}},
                          {"specular", {{"type", 35666}}},
                          {"shininess", {{"type", 5126}}},
                          {"transparency", {{"type", 5126}}},
                          {"modelViewMatrix", {{"semantic", "MODELVIEW"}, {"type", 35676}}}}},
                        {"uniforms",
                         {{"u_diffuse", "diffuse"},
                          {"u_specular", "specular"},
                          {"u_shininess", "shininess"},
                          {"u_transparency", "transparency"},
                          {"u_modelViewMatrix", "modelViewMatrix"}}},
                        {"program", 0},
                        {"states", {{"enable", {2884, 2929}}}}}};
  doc["programs"] = {{{"fragmentShader", 1}, {"vertexShader", 0}}};
  doc["extensionsUsed"] = {"KHR_technique_webgl"};
  doc["extensionsRequired"] = {"KHR_technique_webgl"};
  return doc;
}

const char* kTechniqueWarning =
    "KHR_technique_webgl: shaders are ignored; where a material has no metallic-roughness block, "
    "its common-profile values are baked as metallic-roughness: diffuse as base colour, emission "
    "as emissive, transparency as alpha (BLEND below 1), metallic 0, roughness (2 / (shininess + "
    "2))^(1/4) (Blinn-Phong to Beckmann); ambient and specular are not baked (1 material)";

TEST(GltfMaterials, TechniqueWebglTextureDiffuseBecomesBaseColourTexture) {
  json doc = technique_doc();
  doc["samplers"][0] = {{"wrapS", 33071}, {"wrapT", 33648}, {"magFilter", 9728}};
  auto s = load("technique_tex.gltf", doc);
  ASSERT_NO_FATAL_FAILURE(expect_warnings(s, "technique_tex.gltf", {kTechniqueWarning}));
  const scene::Material& m = s->materials[0];
  EXPECT_EQ(m.base_color_texture.image, 0);
  EXPECT_EQ(m.base_color_texture.texcoord, 0);
  EXPECT_EQ(m.base_color_texture.wrap_s, WrapMode::kClampToEdge);
  EXPECT_EQ(m.base_color_texture.wrap_t, WrapMode::kMirroredRepeat);
  EXPECT_EQ(m.base_color_texture.mag_filter, FilterMode::kNearest);
  EXPECT_EQ(m.base_color_factor, (scene::Vec4{1, 1, 1, 1}));
  EXPECT_EQ(m.metallic_factor, 0.0f);
  // (2 / 258)^(1/4): Beckmann alpha sqrt(2 / (s + 2)) = roughness^2.
  EXPECT_NEAR(m.roughness_factor, 0.2967239, 1e-6);
  EXPECT_EQ(m.alpha_mode, scene::AlphaMode::kOpaque);
  EXPECT_FALSE(m.double_sided);  // CULL_FACE enabled
  EXPECT_EQ(m.emissive_factor, (scene::Vec3{0, 0, 0}));
  EXPECT_FALSE(m.emissive_texture.valid());
  EXPECT_FALSE(m.metallic_roughness_texture.valid());

  // A material with its own metallic-roughness block keeps it.
  doc["materials"][0]["pbrMetallicRoughness"] = {{"metallicFactor", 0.5}};
  auto kept = load("technique_mr.gltf", doc);
  ASSERT_TRUE(kept.ok()) << kept.status().message();
  EXPECT_EQ(kept->materials[0].metallic_factor, 0.5f);
  EXPECT_FALSE(kept->materials[0].base_color_texture.valid());

  // Without the extension declared, `technique` is an unknown property: ignored.
  doc = technique_doc();
  doc.erase("extensionsUsed");
  doc.erase("extensionsRequired");
  auto plain = load("technique_undeclared.gltf", doc);
  ASSERT_NO_FATAL_FAILURE(expect_warnings(plain, "technique_undeclared.gltf", {}));
  EXPECT_FALSE(plain->materials[0].base_color_texture.valid());
  EXPECT_EQ(plain->materials[0].metallic_factor, 1.0f);
}

TEST(GltfMaterials, TechniqueWebglColourDiffuseTransparencyAndDefaults) {
  json doc = technique_doc();
  json& tech = doc["techniques"][0];
  tech["parameters"]["diffuse"]["type"] = 35666;
  // emission only as the parameter's default, an RGB colour.
  tech["parameters"]["emission"] = {{"type", 35665}, {"value", {0.125, 0.25, 0.5}}};
  tech.erase("states");  // glTF 1.0: no CULL_FACE, both sides drawn
  doc["materials"][0]["values"] = {{"diffuse", {0.5, 0.25, 1, 1}},
                                   {"transparency", 0.5}};  // a bare scalar, as glTF 1.0 allows
  auto s = load("technique_colour.gltf", doc);
  ASSERT_NO_FATAL_FAILURE(expect_warnings(s, "technique_colour.gltf", {kTechniqueWarning}));
  const scene::Material& m = s->materials[0];
  EXPECT_FALSE(m.base_color_texture.valid());
  EXPECT_EQ(m.base_color_factor, (scene::Vec4{0.5f, 0.25f, 1, 0.5f}));
  EXPECT_EQ(m.alpha_mode, scene::AlphaMode::kBlend);
  EXPECT_TRUE(m.double_sided);
  EXPECT_EQ(m.emissive_factor, (scene::Vec3{0.125f, 0.25f, 0.5f}));
  EXPECT_EQ(m.metallic_factor, 0.0f);
  EXPECT_EQ(m.roughness_factor, 1.0f);  // no shininess: a Lambert surface

  // An emission texture and BLEND from the states alone.
  doc["materials"][0]["values"] = {{"emission", {0}}, {"diffuse", {0.5, 0.25, 1, 1}}};
  tech["parameters"]["emission"] = {{"type", 35678}};
  tech["states"] = {{"enable", {3042}}};
  auto e = load("technique_emission.gltf", doc);
  ASSERT_TRUE(e.ok()) << e.status().message();
  EXPECT_EQ(e->materials[0].emissive_texture.image, 0);
  EXPECT_EQ(e->materials[0].emissive_factor, (scene::Vec3{1, 1, 1}));
  EXPECT_EQ(e->materials[0].base_color_factor, (scene::Vec4{0.5f, 0.25f, 1, 1}));
  EXPECT_EQ(e->materials[0].alpha_mode, scene::AlphaMode::kBlend);
}

TEST(GltfMaterials, TechniqueWebglBadValuesNameTheirPlace) {
  struct Case {
    const char* pointer;
    json value;
    const char* part;
  };
  const std::vector<Case> cases = {
      {"/materials/0/values/diffuse",
       {5},
       "materials[0] 't'.values.diffuse: texture 5 does not exist (the file has 1 texture)"},
      {"/materials/0/values/diffuse",
       {"x"},
       "materials[0] 't'.values.diffuse: expected a "
       "texture index"},
      {"/materials/0/technique", 3,
       "materials[0] 't'.technique: technique 3 does not exist (the file has 1 technique)"},
      {"/techniques/0/parameters/diffuse/type", 5126,
       "techniques[0].parameters.diffuse.type: 5126 is not 35665 FLOAT_VEC3, 35666 FLOAT_VEC4 "
       "or 35678 SAMPLER_2D"},
      {"/techniques/0/parameters/shininess/type", 35666,
       "techniques[0].parameters.shininess.type: 35666 is not 5126 FLOAT"},
      {"/techniques/0/parameters/diffuse", json::object(),
       "techniques[0].parameters.diffuse.type: expected a GL type"},
      {"/materials/0/values/specular",
       {1, 2},
       "materials[0] 't'.values.specular: expected an array of 4 numbers"},
      {"/materials/0/values/shininess",
       {-1},
       "materials[0] 't'.values.shininess: expected a number from 0 up"},
      {"/materials/0/values/transparency",
       {1.5},
       "materials[0] 't'.values.transparency: expected a number from 0 to 1"},
      {"/materials/0/values/bogus",
       {1},
       "materials[0] 't'.values.bogus: 'bogus' is not a parameter of technique 0"},
      {"/techniques/0/uniforms/u_x", "nothing",
       "techniques[0].uniforms.u_x: 'nothing' is not a parameter of technique 0"},
      {"/techniques/0/program", 2,
       "techniques[0].program: program 2 does not exist (the file has 1 program)"},
      {"/techniques/0/states/enable", "x",
       "techniques[0].states.enable: expected an array of GL enums"},
      {"/techniques", json::object(), "techniques: expected an array"},
  };
  for (const Case& c : cases) {
    json doc = technique_doc();
    doc[json::json_pointer(c.pointer)] = c.value;
    SCOPED_TRACE(c.part);
    expect_error(load("bad_technique.gltf", doc), "bad_technique.gltf", ErrorCode::kCorrupt,
                 c.part);
  }
}

TEST(GltfMaterials, TextureSourcesFromImageExtensions) {
  json doc = triangle_doc();
  doc["images"].push_back({{"uri", "albedo.ktx2"}});
  doc["images"].push_back({{"uri", "albedo.webp"}});
  doc["textures"] = {{{"extensions", {{"KHR_texture_basisu", {{"source", 1}}}}}},
                     {{"extensions", {{"EXT_texture_webp", {{"source", 2}}}}}}};
  doc["materials"][0]["emissiveTexture"] = {{"index", 1}};
  doc["extensionsUsed"] = {"KHR_texture_basisu", "EXT_texture_webp"};
  auto s = load("sources.gltf", doc);
  ASSERT_NO_FATAL_FAILURE(expect_warnings(
      s, "sources.gltf",
      {"materials[0] 'm'.pbrMetallicRoughness.baseColorTexture: texture 0 has no image vtbake "
       "reads (its only image is a KHR_texture_basisu one); the slot bakes its factor alone",
       "KHR_texture_basisu: KTX2 images are not read; each texture's PNG/JPEG fallback source "
       "is baked"}));
  EXPECT_FALSE(s->materials[0].base_color_texture.valid());
  EXPECT_EQ(s->materials[0].emissive_texture.image, 2);
}

TEST(GltfMaterials, Gltf1IsRefusedWithAMessage) {
  json doc = triangle_doc();
  doc["asset"]["version"] = "1.0";
  expect_error(load("v1.gltf", doc), "v1.gltf", ErrorCode::kUnsupported,
               "glTF 1.0 is not supported (convert it to glTF 2.0");
  // glTF 1.0 without an asset block: its collections are objects keyed by id.
  expect_error(
      load_text("v1_maps.gltf", R"({"meshes": {"m": {"primitives": []}}, "materials": {}})"),
      "v1_maps.gltf", ErrorCode::kUnsupported, "glTF 1.0 is not supported");
  // A glTF 1.0 binary container (header version 1).
  std::string glb = "glTF";
  uint32_t header[4] = {1, 20, 0, 0};
  glb.append(reinterpret_cast<const char*>(header), sizeof(header));
  expect_error(load_text("v1.glb", glb), "v1.glb", ErrorCode::kUnsupported,
               "glTF 1.0 binary is not supported");
  doc["asset"]["version"] = "3.0";
  expect_error(load("v3.gltf", doc), "v3.gltf", ErrorCode::kUnsupported,
               "asset.version \"3.0\" is not supported");
  doc.erase("asset");
  auto s = load("noversion.gltf", doc);
  ASSERT_NO_FATAL_FAILURE(
      expect_warnings(s, "noversion.gltf", {"asset.version is missing; read as glTF 2.0"}));
}

TEST(GltfMaterials, MorphTargetsAndSkinsWarn) {
  json doc = triangle_doc();
  doc["meshes"][0]["primitives"][0]["targets"] = {{{"POSITION", 0}}};
  doc["skins"] = {{{"joints", {0}}}};
  auto s = load("morph.gltf", doc);
  ASSERT_NO_FATAL_FAILURE(
      expect_warnings(s, "morph.gltf",
                      {"morph targets ignored: 1 primitive baked in the base shape (bind pose), "
                       "target weights not applied",
                       "1 skin ignored: skinned meshes baked in bind pose at "
                       "their nodes"}));
}

TEST(GltfMaterials, NodeGraphMustBeAForest) {
  json doc = triangle_doc();
  doc.erase("scenes");
  doc.erase("scene");
  doc["nodes"][1]["children"] = {0};
  expect_error(load("cycle.gltf", doc), "cycle.gltf", ErrorCode::kCorrupt,
               "nodes: the node graph has a cycle: node 0 'a' -> node 1 'b' -> node 0 'a'");
  doc = triangle_doc();
  doc["nodes"][1]["children"] = {1};
  expect_error(load("self.gltf", doc), "self.gltf", ErrorCode::kCorrupt,
               "nodes[1].children: node 1 'b' lists itself as a child");
  doc = triangle_doc();
  doc["nodes"].push_back({{"name", "c"}, {"children", {1}}});
  expect_error(load("parents.gltf", doc), "parents.gltf", ErrorCode::kCorrupt,
               "nodes[2].children: node 1 'b' has two parents, node 0 'a' and node 2 'c'");
  doc = triangle_doc();
  doc["scenes"][0]["nodes"] = {0, 1};
  expect_error(load("nonroot.gltf", doc), "nonroot.gltf", ErrorCode::kCorrupt,
               "scenes[0].nodes: node 1 'b' is not a root node (node 0 'a' lists it as a child)");

  // A three-node cycle below a valid root is found too; a forest loads with its roots.
  doc = triangle_doc();
  doc["nodes"].push_back({{"name", "c"}, {"children", {3}}});
  doc["nodes"].push_back({{"name", "d"}, {"children", {2}}});
  expect_error(load("cycle2.gltf", doc), "cycle2.gltf", ErrorCode::kCorrupt,
               "the node graph has a cycle: node 2 'c' -> node 3 'd' -> node 2 'c'");
  doc = triangle_doc();
  doc.erase("scenes");
  doc.erase("scene");
  doc["nodes"].push_back({{"name", "lone"}, {"mesh", 0}});
  auto s = load("forest.gltf", doc);
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->roots, (std::vector<int>{0, 2}));
  EXPECT_EQ(s->instances().size(), 2u);
}

// gltfpack writes `{}` for an image it could not read: the textures naming it are missing
// textures, which the bake refuses or bakes from their factors (--missing-textures), not a
// refusal of the whole file.
TEST(GltfMaterials, AnImageWithoutDataLoadsAsAMissingImage) {
  json doc = triangle_doc();
  doc["images"][0] = json::object();
  const auto s = load("image_without_data.gltf", doc);
  expect_warnings(s, "image_without_data.gltf",
                  {"images[0]: neither uri nor bufferView (the image's data was left out)"});
  ASSERT_TRUE(s.ok());
  EXPECT_TRUE(s->images[0].has_no_data());
  EXPECT_EQ(s->materials[0].base_color_texture.image, 0);
}

TEST(GltfMaterials, OutOfRangeIndicesNameTheirPlace) {
  const std::vector<BadField> cases = {
      {"tex", "/materials/0/pbrMetallicRoughness/baseColorTexture/index"_json_pointer, 5,
       "materials[0] 'm'.pbrMetallicRoughness.baseColorTexture.index: texture 5 does not exist "
       "(the file has 1 texture)"},
      {"source", "/textures/0/source"_json_pointer, 3,
       "textures[0].source: image 3 does not exist (the file has 1 image)"},
      {"sampler", "/textures/0/sampler"_json_pointer, 2,
       "textures[0].sampler: sampler 2 does not exist (the file has 1 sampler)"},
      {"mesh", "/nodes/1/mesh"_json_pointer, 4,
       "nodes[1] 'b'.mesh: mesh 4 does not exist (the file has 1 mesh)"},
      {"child", "/nodes/0/children/0"_json_pointer, 9,
       "nodes[0] 'a'.children[0]: node 9 does not exist (the file has 2 nodes)"},
      {"root", "/scenes/0/nodes/0"_json_pointer, 7,
       "scenes[0].nodes[0]: node 7 does not exist (the file has 2 nodes)"},
      {"material", "/meshes/0/primitives/0/material"_json_pointer, 1,
       "meshes[0] 'tri'.primitives[0].material: material 1 does not exist (the file has 1 "
       "material)"},
      {"attribute", "/meshes/0/primitives/0/attributes/TEXCOORD_0"_json_pointer, 3,
       "meshes[0] 'tri'.primitives[0].attributes.TEXCOORD_0: accessor 3 does not exist"},
      {"view", "/accessors/1/bufferView"_json_pointer, 3,
       "accessors[1].bufferView: bufferView 3 does not exist (the file has 3 bufferViews)"},
      {"scene", "/scene"_json_pointer, 1, "scene: scene 1 does not exist (the file has 1 scene)"},
      {"negative", "/nodes/1/mesh"_json_pointer, -1, "nodes[1] 'b'.mesh: expected a mesh index"},
  };
  expect_each_fails(cases, "range_");
}

TEST(GltfMaterials, BadTypesAndValuesSayWhatWasExpected) {
  const std::vector<BadField> cases = {
      {"number", "/materials/0/pbrMetallicRoughness/metallicFactor"_json_pointer, "high",
       "materials[0] 'm'.pbrMetallicRoughness.metallicFactor: expected a number"},
      {"array", "/materials/0/emissiveFactor"_json_pointer, json::array({1, 2}),
       "materials[0] 'm'.emissiveFactor: expected an array of 3 numbers"},
      {"string", "/accessors/0/name"_json_pointer, 42, "accessors[0].name: expected a string"},
      {"object", "/materials/0/pbrMetallicRoughness"_json_pointer, json::array(),
       "materials[0] 'm'.pbrMetallicRoughness: expected an object"},
      {"bool", "/materials/0/doubleSided"_json_pointer, "yes",
       "materials[0] 'm'.doubleSided: expected true or false"},
      {"count", "/accessors/0/count"_json_pointer, 2.5,
       "accessors[0].count: expected a non-negative integer"},
      {"trs", "/nodes/0/translation"_json_pointer, json::array({1, 2}),
       "nodes[0] 'a'.translation: expected an array of 3 numbers"},
      {"meshes", "/meshes/0/primitives"_json_pointer, json::object(),
       "meshes[0] 'tri'.primitives: expected an array"},
      {"alpha", "/materials/0/alphaMode"_json_pointer, "CUTOUT",
       "materials[0] 'm'.alphaMode: 'CUTOUT' is not OPAQUE, MASK or BLEND"},
      {"wrap", "/samplers/0/wrapS"_json_pointer, 1234,
       "samplers[0].wrapS: 1234 is not a wrap mode"},
      {"filter", "/samplers/0/magFilter"_json_pointer, 9986,
       "samplers[0].magFilter: 9986 is not 9728 NEAREST or 9729 LINEAR"},
      {"noindex", "/materials/0/pbrMetallicRoughness/baseColorTexture"_json_pointer,
       json::object({{"texCoord", 0}}),
       "materials[0] 'm'.pbrMetallicRoughness.baseColorTexture.index: expected a texture index"},
      {"required", "/extensionsRequired"_json_pointer, "KHR_texture_transform",
       "extensionsRequired: expected an array of strings"},
      {"image", "/images/0"_json_pointer,
       json::object({{"name", "both"}, {"uri", "a.png"}, {"bufferView", 0}}),
       "images[0] 'both': an image has both a uri and a bufferView"},
  };
  expect_each_fails(cases, "type_");
  expect_error(load_text("syntax.gltf", "{\"asset\": "), "syntax.gltf", ErrorCode::kCorrupt,
               "malformed JSON: parse error");
}

}  // namespace
}  // namespace vt::test
