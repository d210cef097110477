// The glTF exporter's one document in its two containers: a .glb and a .gltf + .bin of the same
// scene carry the same JSON and the same buffer, both load back as the scene, and the write
// options change only the values glTF would default.
#include <gtest/gtest.h>
#include <cmath>
#include <cstring>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <tuple>

#include "scene/gltf_export.h"
#include "scene/tangent_frame.h"
#include "tests/unwrap/mesh_gen.h"

namespace vt::test {
namespace {

using nlohmann::json;

std::string temp(const std::string& name) {
  return ::testing::TempDir() + "vt_gltf_export_" + name;
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

uint32_t u32_at(const std::string& bytes, size_t offset) {
  uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = v << 8 | uint8_t(bytes[offset + k]);
  return v;
}

// A ball with every attribute, a file image, an embedded image and two materials.
Scene textured_ball() {
  Scene s = scene_of(sphere(8, 4), "ball");
  auto& p = s.meshes[0].primitives[0];
  p.normals = p.positions;
  p.uvs.assign(2, {});
  for (const auto& v : p.positions) p.uvs[0].push_back({v[0], v[1]});
  for (const auto& v : p.positions) p.uvs[1].push_back({v[1], v[2]});
  p.tangents.assign(p.positions.size(), {1, 0, 0, -1});
  p.colors.assign(p.positions.size(), {0.25f, 0.5f, 0.75f, 1});
  p.material = 1;
  scene::Image file;
  file.name = "albedo";
  file.path = ::testing::TempDir() + "textures/albedo.png";
  file.mime_type = "image/png";
  scene::Image embedded;
  embedded.mime_type = "image/jpeg";
  embedded.bytes = {0xFF, 0xD8, 0xFF, 1, 2};  // not a multiple of 4: the buffer pads after it
  s.images = {file, embedded};
  scene::Material plain;
  plain.name = "plain";
  scene::Material textured;
  textured.name = "textured";
  textured.base_color_texture.image = 0;
  textured.normal_texture.image = 1;
  textured.normal_texture.texcoord = 1;
  textured.normal_texture.wrap_t = scene::WrapMode::kMirroredRepeat;
  textured.alpha_mode = scene::AlphaMode::kMask;
  textured.alpha_cutoff = 0.25f;
  textured.double_sided = true;
  s.materials = {plain, textured};
  s.nodes[0].local[12] = -2.5;
  return s;
}

json glb_json(const std::string& bytes) {
  EXPECT_EQ(bytes.substr(0, 4), "glTF");
  EXPECT_EQ(u32_at(bytes, 8), bytes.size());
  return json::parse(bytes.substr(20, u32_at(bytes, 12)));
}

TEST(GltfExport, GlbAndGltfHoldTheSameDocumentAndBuffer) {
  const Scene s = textured_ball();
  ASSERT_TRUE(scene::save_glb(s, temp("same.glb")).ok());
  ASSERT_TRUE(scene::save_gltf(s, temp("same.gltf")).ok());
  const std::string glb = read_all(temp("same.glb"));
  json from_glb = glb_json(glb);
  json from_gltf = json::parse(read_all(temp("same.gltf")));
  EXPECT_EQ(from_gltf["buffers"][0]["uri"], "vt_gltf_export_same.bin");
  from_gltf["buffers"][0].erase("uri");
  EXPECT_EQ(from_glb, from_gltf);

  const size_t json_size = u32_at(glb, 12);
  const size_t bin_size = u32_at(glb, 20 + json_size);
  EXPECT_EQ(u32_at(glb, 24 + json_size), 0x004E4942u);  // "BIN\0"
  EXPECT_EQ(glb.substr(28 + json_size, bin_size), read_all(temp("same.bin")));
  EXPECT_EQ(bin_size % 4, 0u);
  EXPECT_EQ(from_glb["images"][0]["uri"], "textures/albedo.png");
  EXPECT_FALSE(std::filesystem::exists(temp("same.gltf.tmp")));
}

TEST(GltfExport, ImageUrisArePercentEncoded) {
  // A texture path with a space, a '#' and a byte that is not UTF-8 (a Latin-1 file name): the
  // uri is ASCII that decodes to the same bytes (the JSON writer refused the raw byte).
  Scene s = textured_ball();
  s.images[0].path = ::testing::TempDir() +
                     "textures/my d\xe9"
                     "cor #1.png";
  ASSERT_TRUE(scene::save_gltf(s, temp("uri.gltf")).ok());
  const json doc = json::parse(read_all(temp("uri.gltf")));
  EXPECT_EQ(doc["images"][0]["uri"], "textures/my%20d%E9cor%20%231.png");
  auto back = scene::load_scene(temp("uri.gltf"));
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->images[0].path, s.images[0].path);
}

// An image the scene holds no data for is written with neither uri nor bufferView (a view of
// zero bytes would break the schema) and reads back the same, a missing image.
TEST(GltfExport, AnImageWithoutDataStaysWithout) {
  Scene s = textured_ball();
  s.images[1].bytes.clear();
  ASSERT_TRUE(s.images[1].has_no_data());
  ASSERT_TRUE(scene::save_gltf(s, temp("no_data.gltf")).ok());
  const json doc = json::parse(read_all(temp("no_data.gltf")));
  EXPECT_FALSE(doc["images"][1].contains("bufferView"));
  EXPECT_FALSE(doc["images"][1].contains("uri"));
  auto back = scene::load_scene(temp("no_data.gltf"));
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_TRUE(back->images[1].has_no_data());
  EXPECT_EQ(back->images[0].path, s.images[0].path);
}

TEST(GltfExport, GltfLoadsBackAsTheScene) {
  const Scene s = textured_ball();
  ASSERT_TRUE(scene::save_gltf(s, temp("back.gltf")).ok());
  auto back = scene::load_scene(temp("back.gltf"));
  ASSERT_TRUE(back.ok()) << back.status().message();
  // Every attribute, the indices and the material, bit for bit.
  auto contents = [](const scene::Primitive& p) {
    return std::tie(p.positions, p.normals, p.tangents, p.uvs, p.colors, p.indices, p.material);
  };
  EXPECT_TRUE(contents(back->meshes[0].primitives[0]) == contents(s.meshes[0].primitives[0]));
  ASSERT_EQ(back->images.size(), 2u);
  EXPECT_EQ(back->images[0].path, s.images[0].path);
  EXPECT_EQ(back->images[1].bytes, s.images[1].bytes);
  EXPECT_EQ(back->images[1].mime_type, "image/jpeg");
  const scene::Material& m = back->materials[1];
  EXPECT_EQ(m.normal_texture.texcoord, 1);
  EXPECT_EQ(m.normal_texture.wrap_t, scene::WrapMode::kMirroredRepeat);
  EXPECT_EQ(m.alpha_mode, scene::AlphaMode::kMask);
  EXPECT_FLOAT_EQ(m.alpha_cutoff, 0.25f);
  EXPECT_TRUE(m.double_sided);
  EXPECT_FALSE(back->materials[0].double_sided);
  EXPECT_DOUBLE_EQ(back->nodes[0].local[12], -2.5);
}

// A node with nothing to say (no name, mesh, children or transform: a Half-Life model's empty
// bone controllers, as assimp gives them) is written as {}, which loads back; it was null, and
// the validator could not read the unwrapped scene.
TEST(GltfExport, BareNodesLoadBack) {
  Scene s = textured_ball();
  s.nodes.push_back({});
  s.nodes[0].children.push_back(int(s.nodes.size() - 1));
  ASSERT_TRUE(scene::save_gltf(s, temp("bare.glb")).ok());
  auto back = scene::load_scene(temp("bare.glb"));
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_EQ(back->nodes.size(), s.nodes.size());
  EXPECT_EQ(back->nodes.back().mesh, -1);
  EXPECT_TRUE(back->nodes.back().children.empty());
}

// KHR_lights_punctual round trip: the unwrapped scene keeps the lights a lit bake used, with
// their nodes (placement), types, units, range and cone angles.
TEST(GltfExport, LightsLoadBackWithTheirNodes) {
  Scene s = textured_ball();
  scene::Light sun;
  sun.name = "sun";
  sun.type = scene::LightType::kDirectional;
  sun.intensity = 3.5f;
  sun.color = {1, 0.5f, 0.25f};
  scene::Light bulb;  // infinite range: written without one
  bulb.intensity = 40;
  scene::Light spot;
  spot.type = scene::LightType::kSpot;
  spot.range = 12;
  spot.inner_cone_angle = 0.25f;
  spot.outer_cone_angle = 0.5f;
  s.lights = {sun, bulb, spot};
  for (int l = 0; l < 3; ++l) {
    scene::Node n;
    n.light = l;
    n.local[12] = double(l);  // translation x
    s.roots.push_back(int(s.nodes.size()));
    s.nodes.push_back(n);
  }
  ASSERT_TRUE(scene::save_glb(s, temp("lights.glb")).ok());
  auto back = scene::load_scene(temp("lights.glb"));
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_TRUE(back->warnings.empty()) << back->warnings.front();
  ASSERT_EQ(back->lights.size(), 3u);
  EXPECT_EQ(back->lights[0].name, "sun");
  EXPECT_EQ(back->lights[0].type, scene::LightType::kDirectional);
  EXPECT_FLOAT_EQ(back->lights[0].intensity, 3.5f);
  EXPECT_EQ(back->lights[0].color, sun.color);
  EXPECT_TRUE(std::isinf(back->lights[1].range));
  EXPECT_FLOAT_EQ(back->lights[1].intensity, 40);
  EXPECT_EQ(back->lights[2].type, scene::LightType::kSpot);
  EXPECT_FLOAT_EQ(back->lights[2].range, 12);
  EXPECT_FLOAT_EQ(back->lights[2].inner_cone_angle, 0.25f);
  EXPECT_FLOAT_EQ(back->lights[2].outer_cone_angle, 0.5f);
  const auto placed = back->placed_lights();
  ASSERT_EQ(placed.size(), 3u);
  for (int l = 0; l < 3; ++l) {
    EXPECT_EQ(placed[l].light, l);
    EXPECT_DOUBLE_EQ(placed[l].position[0], double(l));
  }
  // A scene without lights writes no extension at all.
  ASSERT_TRUE(scene::save_gltf(textured_ball(), temp("unlit.gltf")).ok());
  EXPECT_EQ(read_all(temp("unlit.gltf")).find("KHR_lights_punctual"), std::string::npos);
}

TEST(GltfExport, OptionsSpellOutOnlyWhatGltfDefaults) {
  const Scene s = textured_ball();
  ASSERT_TRUE(scene::save_gltf(s, temp("compact.gltf")).ok());
  scene::GltfWriteOptions o;
  o.generator = "test";
  o.write_texcoord_0 = true;
  o.write_single_sided = true;
  o.write_opaque = false;
  o.sampler_filters = true;
  ASSERT_TRUE(scene::save_gltf(s, temp("spelled.gltf"), o).ok());
  const json compact = json::parse(read_all(temp("compact.gltf")));
  const json spelled = json::parse(read_all(temp("spelled.gltf")));

  EXPECT_EQ(compact["asset"]["generator"], "vtbake");
  EXPECT_EQ(spelled["asset"]["generator"], "test");
  const json& base_compact = compact["materials"][1]["pbrMetallicRoughness"]["baseColorTexture"];
  const json& base_spelled = spelled["materials"][1]["pbrMetallicRoughness"]["baseColorTexture"];
  EXPECT_FALSE(base_compact.contains("texCoord"));
  EXPECT_EQ(base_spelled["texCoord"], 0);
  EXPECT_EQ(compact["materials"][1]["normalTexture"]["texCoord"], 1);  // never a default
  EXPECT_FALSE(compact["materials"][0].contains("doubleSided"));
  EXPECT_EQ(spelled["materials"][0]["doubleSided"], false);
  EXPECT_EQ(compact["materials"][0]["alphaMode"], "OPAQUE");
  EXPECT_FALSE(spelled["materials"][0].contains("alphaMode"));
  EXPECT_EQ(spelled["materials"][1]["alphaMode"], "MASK");  // only the default is dropped
  EXPECT_FALSE(compact["samplers"][0].contains("minFilter"));
  EXPECT_EQ(spelled["samplers"][0]["minFilter"], 9987);
  EXPECT_EQ(spelled["samplers"][0]["magFilter"], 9729);
  // Same geometry either way: the options touch no accessor.
  EXPECT_EQ(compact["accessors"], spelled["accessors"]);
  EXPECT_EQ(compact["samplers"].size(), 2u);  // repeat/repeat and repeat/mirrored
}

TEST(GltfExport, BadIndexIsAnErrorAndLeavesNoFile) {
  Scene s = textured_ball();
  s.meshes[0].primitives[0].indices[4] = 100000;
  for (const std::string name : {"bad.glb", "bad.gltf"}) {
    std::filesystem::remove(temp(name));
    const Status st =
        name.ends_with(".glb") ? scene::save_glb(s, temp(name)) : scene::save_gltf(s, temp(name));
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.message().find("mesh 0 primitive 0: index 100000 out of range"), std::string::npos)
        << st.message();
    EXPECT_FALSE(std::filesystem::exists(temp(name)));
    EXPECT_FALSE(std::filesystem::exists(temp(name) + ".tmp"));
  }
  EXPECT_FALSE(std::filesystem::exists(temp("bad.bin")));
}

// A flat 2 x 1 grid in the XY plane with a source UV set and an atlas set (last) that maps +x
// to +u (or -u, mirrored) and +y up the atlas image (v down, as in glTF).
Scene atlas_grid(bool mirrored) {
  Scene s = scene_of(flat_grid(2, 1, 2, 1), "grid");
  auto& p = s.meshes[0].primitives[0];
  p.uvs.assign(2, {});
  for (const auto& v : p.positions) p.uvs[0].push_back({v[1], v[0]});  // a rotated source set
  for (const auto& v : p.positions)
    p.uvs[1].push_back({(mirrored ? 1 - v[0] : v[0]) * 0.5f, 0.5f - v[1] * 0.5f});
  p.tangents.assign(p.positions.size(), {0, 1, 0, 1});  // the source set's frame
  return s;
}

// The VEC4 float accessor `index` of a GLB (tightly packed, as the exporter writes it).
std::vector<scene::Vec4> vec4_accessor(const std::string& glb, const json& doc, int index) {
  const size_t json_len = u32_at(glb, 12);
  const size_t bin = 20 + json_len + 8;
  const json& a = doc["accessors"][index];
  const json& view = doc["bufferViews"][a["bufferView"].get<int>()];
  size_t at = bin + view.value("byteOffset", size_t(0)) + a.value("byteOffset", size_t(0));
  std::vector<scene::Vec4> out(a["count"].get<size_t>());
  for (auto& v : out) {
    std::memcpy(v.data(), glb.data() + at, sizeof(v));
    at += sizeof(v);
  }
  return out;
}

TEST(GltfExport, UnwrappedGlbCarriesTheAtlasTangentFrame) {
  for (bool mirrored : {false, true}) {
    const Scene s = atlas_grid(mirrored);
    scene::GltfWriteOptions o;
    o.atlas_tangents = true;
    ASSERT_TRUE(scene::save_glb(s, temp("atlas.glb"), o).ok());
    const json doc = glb_json(read_all(temp("atlas.glb")));
    const json& attrs = doc["meshes"][0]["primitives"][0]["attributes"];
    EXPECT_TRUE(attrs.contains("NORMAL"));  // glTF ignores TANGENT without NORMAL
    EXPECT_TRUE(attrs.contains("_SOURCE_TANGENT"));
    auto back = scene::load_scene(temp("atlas.glb"));
    ASSERT_TRUE(back.ok()) << back.status().message();
    const scene::Primitive& p = back->meshes[0].primitives[0];
    // Read back, the primitive keeps the frame its material's maps are decoded in.
    EXPECT_EQ(p.tangents, s.meshes[0].primitives[0].tangents);
    ASSERT_EQ(p.normals.size(), p.positions.size());
    const std::vector<scene::Vec4> atlas =
        vec4_accessor(read_all(temp("atlas.glb")), doc, attrs["TANGENT"].get<int>());
    ASSERT_EQ(atlas.size(), p.positions.size());
    EXPECT_EQ(atlas, scene::compute_tangents(s.meshes[0].primitives[0],
                                             scene::compute_normals(s.meshes[0].primitives[0]), 1));
    for (size_t i = 0; i < p.positions.size(); ++i) {
      const auto& n = p.normals[i];
      const auto& t = atlas[i];
      // Tangent along +u of the atlas; bitangent = cross(n, t) * w up the atlas image (+y).
      EXPECT_NEAR(t[0], mirrored ? -1 : 1, 1e-6);
      EXPECT_NEAR(t[1], 0, 1e-6);
      const float by = (n[2] * t[0] - n[0] * t[2]) * t[3];
      EXPECT_NEAR(by, 1, 1e-6) << "vertex " << i << (mirrored ? " (mirrored)" : "");
    }
  }
  // Without the option the primitive's own tangents are written.
  ASSERT_TRUE(scene::save_glb(atlas_grid(false), temp("own.glb")).ok());
  auto own = scene::load_scene(temp("own.glb"));
  ASSERT_TRUE(own.ok());
  EXPECT_EQ(own->meshes[0].primitives[0].tangents,
            atlas_grid(false).meshes[0].primitives[0].tangents);
}

TEST(GltfExport, TextureTransformEmissiveStrengthAndNearestFilterRoundTrip) {
  Scene s = textured_ball();
  scene::Material& m = s.materials[1];
  m.base_color_texture.transform.offset = {0.25f, -0.5f};
  m.base_color_texture.transform.rotation = 0.5f;
  m.base_color_texture.transform.scale = {2, 3};
  m.base_color_texture.texcoord = 1;
  m.base_color_texture.mag_filter = scene::FilterMode::kNearest;
  m.emissive_factor = {1, 0.5f, 0};
  m.emissive_strength = 8;
  ASSERT_TRUE(scene::save_glb(s, temp("ext.glb")).ok());
  const json doc = glb_json(read_all(temp("ext.glb")));
  EXPECT_EQ(doc["extensionsUsed"],
            json({"KHR_texture_transform", "KHR_materials_emissive_strength"}));
  EXPECT_FALSE(doc.contains("extensionsRequired"));  // a reader without them still works
  auto back = scene::load_scene(temp("ext.glb"));
  ASSERT_TRUE(back.ok()) << back.status().message();
  const scene::TextureRef& t = back->materials[1].base_color_texture;
  EXPECT_EQ(t.texcoord, 1);
  EXPECT_EQ(t.transform.offset, m.base_color_texture.transform.offset);
  EXPECT_EQ(t.transform.rotation, 0.5f);
  EXPECT_EQ(t.transform.scale, m.base_color_texture.transform.scale);
  EXPECT_EQ(t.mag_filter, scene::FilterMode::kNearest);
  EXPECT_EQ(back->materials[1].emissive_strength, 8.0f);
  EXPECT_TRUE(back->materials[0].base_color_texture.transform.identity());
  EXPECT_EQ(back->materials[0].emissive_strength, 1.0f);
}

}  // namespace
}  // namespace vt::test
