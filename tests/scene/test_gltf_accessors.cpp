// glTF accessors on small files the tests write: sparse accessors (with and without a base
// bufferView, u8/u16/u32 indices), KHR_mesh_quantization attribute types and the types glTF
// forbids, COLOR_0 formats, EXT_meshopt_compression views (encoded here with meshoptimizer,
// every filter), and hostile counts refused before any big allocation.
#include <gtest/gtest.h>
#include <meshoptimizer.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>

#include "scene/scene.h"
#include "scene/tangent_frame.h"
#include "tests/scene/alloc_probe.h"

namespace vt::test {
namespace {

using json = nlohmann::json;

std::string temp(const std::string& name) {
  return ::testing::TempDir() + "vt_gltf_acc_" + name;
}

// A one-primitive glTF: views and accessors are added, then the primitive's attributes.
struct GltfFile {
  json doc = {{"asset", {{"version", "2.0"}}},
              {"bufferViews", json::array()},
              {"accessors", json::array()},
              {"nodes", {{{"mesh", 0}}}},
              {"scenes", {{{"nodes", {0}}}}},
              {"meshes", {{{"primitives", {{{"attributes", json::object()}}}}}}}};
  std::vector<uint8_t> bin;

  json& primitive() { return doc["meshes"][0]["primitives"][0]; }
  size_t view(const void* data, size_t size, size_t stride = 0) {
    while (bin.size() % 4) bin.push_back(0);
    json v = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", size}};
    if (stride) v["byteStride"] = stride;
    const auto* p = static_cast<const uint8_t*>(data);
    bin.insert(bin.end(), p, p + size);
    doc["bufferViews"].push_back(v);
    return doc["bufferViews"].size() - 1;
  }
  size_t accessor(json a) {
    doc["accessors"].push_back(std::move(a));
    return doc["accessors"].size() - 1;
  }
  size_t accessor(size_t view, int component_type, const char* type, size_t count,
                  bool normalized = false) {
    json a = {
        {"bufferView", view}, {"componentType", component_type}, {"type", type}, {"count", count}};
    if (normalized) a["normalized"] = true;
    return accessor(a);
  }
  // Writes NAME.gltf and NAME.bin; extra buffers (such as placeholders) follow buffer 0.
  std::string write(const std::string& name, const json& extra_buffers = json::array()) {
    std::ofstream(temp(name + ".bin"), std::ios::binary)
        .write(reinterpret_cast<const char*>(bin.data()), static_cast<std::streamsize>(bin.size()));
    doc["buffers"] = {{{"uri", "vt_gltf_acc_" + name + ".bin"}, {"byteLength", bin.size()}}};
    for (const json& b : extra_buffers) doc["buffers"].push_back(b);
    std::ofstream(temp(name + ".gltf")) << doc.dump();
    return temp(name + ".gltf");
  }
  Expected<scene::Scene> load(const std::string& name, const json& extra = json::array()) {
    return scene::load_scene(write(name, extra));
  }
};

const float kTriangle[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};

// A file with a float triangle as POSITION (accessor 0).
GltfFile triangle_file() {
  GltfFile f;
  f.primitive()["attributes"]["POSITION"] =
      f.accessor(f.view(kTriangle, sizeof(kTriangle)), 5126, "VEC3", 3);
  return f;
}

const scene::Primitive& only_primitive(const scene::Scene& s) {
  return s.meshes[0].primitives[0];
}

TEST(GltfAccessors, SparseOverABaseViewWithEveryIndexType) {
  const float base[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const float values[6] = {5, 6, 7, -1, -2, -3};
  for (int ict : {5121, 5123, 5125}) {
    GltfFile f;
    size_t bv = f.view(base, sizeof(base));
    uint8_t idx[8] = {};
    size_t isize = ict == 5121 ? 1 : ict == 5123 ? 2 : 4;
    uint32_t at[2] = {1, 3};
    for (int j = 0; j < 2; ++j) std::memcpy(idx + j * isize, &at[j], isize);  // little endian
    size_t iv = f.view(idx, 2 * isize), vv = f.view(values, sizeof(values));
    json a = {{"bufferView", bv},
              {"componentType", 5126},
              {"type", "VEC3"},
              {"count", 4},
              {"sparse",
               {{"count", 2},
                {"indices", {{"bufferView", iv}, {"componentType", ict}}},
                {"values", {{"bufferView", vv}}}}}};
    f.primitive()["attributes"]["POSITION"] = f.accessor(a);
    auto s = f.load("sparse" + std::to_string(ict));
    ASSERT_TRUE(s.ok()) << s.status().message();
    const auto& p = only_primitive(*s);
    EXPECT_EQ(p.positions,
              (std::vector<scene::Vec3>{{0, 0, 0}, {5, 6, 7}, {1, 1, 0}, {-1, -2, -3}}))
        << ict;
    EXPECT_EQ(p.indices, (std::vector<uint32_t>{0, 1, 2}));  // 4 vertices, one whole triangle
  }
}

// glTF: a primitive without NORMAL is shaded flat and its TANGENT ignored. A tent (faces +Z and
// -Y sharing the edge v0 v1), a flat quad (two faces, +Z) and a zero-area face along the quad's
// edge out to v8, which nothing else touches; in metres and in units of 1e-18, whose cross
// products are far below what a normal is taken from unscaled.
void expect_flat_tent_and_quad(float unit) {
  float pos[27] = {0, 0, 0, 1, 0, 0, 0.5f, 1, 0, 0.5f, 0, -1,  // tent
                   0, 0, 5, 1, 0, 5, 1,    1, 5, 0,    1, 5,   // quad
                   2, 0, 5};
  for (float& c : pos) c *= unit;
  float uv[18], tangent[36];
  for (int v = 0; v < 9; ++v) uv[2 * v] = v * 0.1f, uv[2 * v + 1] = 1 - v * 0.1f;
  for (int v = 0; v < 9; ++v)
    tangent[4 * v] = 1, tangent[4 * v + 1] = tangent[4 * v + 2] = 0, tangent[4 * v + 3] = 1;
  const uint16_t idx[15] = {0, 1, 2, 1, 0, 3, 4, 5, 6, 4, 6, 7, 4, 5, 8};
  GltfFile f;
  json& attrs = f.primitive()["attributes"];
  attrs["POSITION"] = f.accessor(f.view(pos, sizeof(pos)), 5126, "VEC3", 9);
  attrs["TEXCOORD_0"] = f.accessor(f.view(uv, sizeof(uv)), 5126, "VEC2", 9);
  attrs["TANGENT"] = f.accessor(f.view(tangent, sizeof(tangent)), 5126, "VEC4", 9);
  f.primitive()["indices"] = f.accessor(f.view(idx, sizeof(idx)), 5123, "SCALAR", 15);
  auto s = f.load(unit == 1 ? "flat" : "flat_tiny");
  ASSERT_TRUE(s.ok()) << s.status().message();
  const auto& p = only_primitive(*s);
  // The tent's shared edge is split (two more vertices); the quad stays four vertices.
  ASSERT_EQ(p.positions.size(), 11u);
  ASSERT_EQ(p.normals.size(), 11u);
  EXPECT_TRUE(p.tangents.empty());
  ASSERT_EQ(p.indices.size(), 15u);
  const scene::Vec3 up = {0, 0, 1}, down_y = {0, -1, 0};
  const scene::Vec3 face_normal[5] = {up, down_y, up, up, up};
  for (size_t c = 0; c < 15; ++c) {
    // Every corner keeps its position and UV, and has its face's normal.
    const uint32_t v = p.indices[c], was = idx[c];
    EXPECT_EQ(p.positions[v], (scene::Vec3{pos[3 * was], pos[3 * was + 1], pos[3 * was + 2]})) << c;
    EXPECT_EQ(p.uvs[0][v], (scene::Vec2{uv[2 * was], uv[2 * was + 1]})) << c;
    EXPECT_EQ(p.normals[v], face_normal[c / 3]) << c;
  }
  for (size_t c : {6, 7, 8, 9, 10, 11}) EXPECT_EQ(p.indices[c], idx[c]) << c;  // the quad's own
  EXPECT_EQ(p.indices[13], p.indices[7]);  // the zero-area face takes v5's normal, splits nothing
  // The smooth normals other formats get are as free of the unit: the quad's corners face +Z.
  const std::vector<scene::Vec3> smooth = scene::compute_normals(p);
  for (uint32_t v : {4, 5, 6, 7}) EXPECT_EQ(smooth[v], up) << v;
}

TEST(GltfPrimitive, WithoutNormalsIsFlatAndSplitOnlyWhereItsFacesTurn) {
  expect_flat_tent_and_quad(1);
}

TEST(GltfPrimitive, NormalsDoNotDependOnTheSceneUnit) {
  expect_flat_tent_and_quad(1e-18f);
}

TEST(GltfPrimitive, WithoutNormalsAnIndexPastTheEndIsStillNamed) {
  GltfFile f = triangle_file();
  const uint16_t idx[6] = {0, 1, 2, 2, 1, 40000};
  f.primitive()["indices"] = f.accessor(f.view(idx, sizeof(idx)), 5123, "SCALAR", 6);
  auto s = f.load("flat_bad_index");
  ASSERT_TRUE(s.ok()) << s.status().message();  // geometry is checked by those who use it
  const Status checked = scene::validate_geometry(*s);
  ASSERT_FALSE(checked.ok());
  EXPECT_NE(checked.message().find("triangle 1 uses vertex 40000 of 3"), std::string::npos)
      << checked.message();
}

TEST(GltfAccessors, SparseWithoutBaseViewStartsFromZeros) {
  GltfFile f = triangle_file();
  const uint16_t idx[1] = {2};
  const float uv[2] = {0.25f, 0.75f};
  size_t iv = f.view(idx, sizeof(idx)), vv = f.view(uv, sizeof(uv));
  json a = {{"componentType", 5126},
            {"type", "VEC2"},
            {"count", 3},
            {"sparse",
             {{"count", 1},
              {"indices", {{"bufferView", iv}, {"componentType", 5123}}},
              {"values", {{"bufferView", vv}}}}}};
  f.primitive()["attributes"]["TEXCOORD_0"] = f.accessor(a);
  auto s = f.load("sparse_zero");
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(only_primitive(*s).uvs.size(), 1u);
  EXPECT_EQ(only_primitive(*s).uvs[0], (std::vector<scene::Vec2>{{0, 0}, {0, 0}, {0.25f, 0.75f}}));
}

TEST(GltfAccessors, SparseIndexOutOfRangeAndShortViewsAreErrors) {
  GltfFile f = triangle_file();
  const uint8_t idx[2] = {7, 1};
  const float uv[2] = {1, 1};
  size_t iv = f.view(idx, sizeof(idx)), vv = f.view(uv, sizeof(uv));
  json sparse = {{"count", 1},
                 {"indices", {{"bufferView", iv}, {"componentType", 5121}}},
                 {"values", {{"bufferView", vv}}}};
  f.primitive()["attributes"]["TEXCOORD_0"] =
      f.accessor({{"componentType", 5126}, {"type", "VEC2"}, {"count", 3}, {"sparse", sparse}});
  auto s = f.load("sparse_bad");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.status().message().find("accessor 1: sparse index 7 (entry 0) is outside the "
                                      "accessor's 3 elements"),
            std::string::npos)
      << s.status().message();

  sparse["count"] = 2;  // two values need 16 bytes; the view holds 8
  f.doc["accessors"][1]["sparse"] = sparse;
  auto t = f.load("sparse_short");
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.status().message().find("accessor 1: sparse values: count 2 x 8 bytes needs 16 "
                                      "bytes but bufferView 2 holds 8 bytes"),
            std::string::npos)
      << t.status().message();
}

TEST(GltfAccessors, QuantizedAttributesReadAsTheExtensionSays) {
  GltfFile f;
  const int16_t pos[9] = {-3, 7, 300, 1000, 0, 0, 0, 1000, 0};
  const int8_t nrm[12] = {0, 0, 127, 0, 0, -128, 0, 0, 0, 0, 64, 0};  // stride 4
  const int16_t tan[12] = {32767, 0, 0, 32767, 0, -32767, 0, -32767, 0, 0, 16384, 32767};
  const uint16_t uv[6] = {0, 65535, 32768, 0, 65535, 65535};
  const uint8_t uv1[6] = {0, 1, 2, 3, 250, 255};
  auto& attrs = f.primitive()["attributes"];
  attrs["POSITION"] = f.accessor(f.view(pos, sizeof(pos)), 5122, "VEC3", 3);
  attrs["NORMAL"] = f.accessor(f.view(nrm, sizeof(nrm), 4), 5120, "VEC3", 3, true);
  attrs["TANGENT"] = f.accessor(f.view(tan, sizeof(tan)), 5122, "VEC4", 3, true);
  attrs["TEXCOORD_0"] = f.accessor(f.view(uv, sizeof(uv)), 5123, "VEC2", 3, true);
  attrs["TEXCOORD_1"] = f.accessor(f.view(uv1, sizeof(uv1)), 5121, "VEC2", 3);
  f.doc["extensionsUsed"] = {"KHR_mesh_quantization"};
  auto s = f.load("quantized");
  ASSERT_TRUE(s.ok()) << s.status().message();
  const auto& p = only_primitive(*s);
  EXPECT_EQ(p.positions, (std::vector<scene::Vec3>{{-3, 7, 300}, {1000, 0, 0}, {0, 1000, 0}}));
  EXPECT_EQ(p.normals[0], (scene::Vec3{0, 0, 1}));
  EXPECT_EQ(p.normals[1], (scene::Vec3{0, -1, 0}));  // -128 clamps to -1
  EXPECT_FLOAT_EQ(p.normals[2][2], float(64 / 127.0));
  EXPECT_EQ(p.tangents[0], (scene::Vec4{1, 0, 0, 1}));
  EXPECT_EQ(p.tangents[1], (scene::Vec4{0, -1, 0, -1}));
  EXPECT_FLOAT_EQ(p.tangents[2][2], float(16384 / 32767.0));
  EXPECT_FLOAT_EQ(p.uvs[0][1][0], float(32768 / 65535.0));
  EXPECT_EQ(p.uvs[0][2], (scene::Vec2{1, 1}));
  EXPECT_EQ(p.uvs[1], (std::vector<scene::Vec2>{{0, 1}, {2, 3}, {250, 255}}));
}

TEST(GltfAccessors, ColorsInEveryAllowedFormat) {
  const uint8_t c8[9] = {255, 0, 51, 0, 255, 0, 0, 0, 255};
  const uint16_t c16[12] = {65535, 0, 0, 32768, 0, 65535, 0, 65535, 0, 0, 65535, 0};
  const float cf[12] = {0.5f, 0.25f, 2.0f, 1, 0, 0, 0, 0.5f, 0, 0, 0, 0};
  struct Case {
    const void* data;
    size_t size;
    int ct;
    const char* type;
    scene::Vec4 first;
  } cases[] = {{c8, sizeof(c8), 5121, "VEC3", {1, 0, 0.2f, 1}},
               {c16, sizeof(c16), 5123, "VEC4", {1, 0, 0, float(32768 / 65535.0)}},
               {cf, sizeof(cf), 5126, "VEC4", {0.5f, 0.25f, 2.0f, 1}}};
  for (const Case& c : cases) {
    GltfFile f = triangle_file();
    f.primitive()["attributes"]["COLOR_0"] =
        f.accessor(f.view(c.data, c.size), c.ct, c.type, 3, c.ct != 5126);
    auto s = f.load("color" + std::to_string(c.ct));
    ASSERT_TRUE(s.ok()) << s.status().message();
    const auto& colors = only_primitive(*s).colors;
    ASSERT_EQ(colors.size(), 3u) << c.ct;
    EXPECT_EQ(colors[0], c.first) << c.ct;
    EXPECT_EQ(colors[2][3], c.ct == 5121 ? 1.0f : 0.0f) << c.ct;  // VEC3 is opaque
  }
}

// Types glTF forbids are errors naming the attribute, the accessor and what was found.
TEST(GltfAccessors, ForbiddenAttributeTypesAreNamed) {
  const uint8_t bytes[12] = {};
  struct Case {
    const char* attribute;
    int ct;
    const char* type;
    bool normalized;
    const char* found;
  } cases[] = {
      {"NORMAL", 5121, "VEC3", true, "NORMAL (accessor 1) is VEC3 of normalized unsigned byte"},
      {"NORMAL", 5120, "VEC3", false, "NORMAL (accessor 1) is VEC3 of byte"},
      {"COLOR_0", 5121, "VEC4", false, "COLOR_0 (accessor 1) is VEC4 of unsigned byte"},
      {"COLOR_0", 5120, "VEC3", true, "COLOR_0 (accessor 1) is VEC3 of normalized byte"},
      {"TEXCOORD_0", 5126, "VEC3", false, "TEXCOORD_0 (accessor 1) is VEC3 of float"},
      {"TANGENT", 5126, "VEC3", false, "TANGENT (accessor 1) is VEC3 of float"},
  };
  for (const Case& c : cases) {
    GltfFile f = triangle_file();
    f.primitive()["attributes"][c.attribute] =
        f.accessor(f.view(bytes, sizeof(bytes)), c.ct, c.type, 1, c.normalized);
    auto s = f.load("forbidden");
    ASSERT_FALSE(s.ok()) << c.found;
    EXPECT_NE(s.status().message().find(c.found), std::string::npos) << s.status().message();
    EXPECT_NE(s.status().message().find("glTF allows"), std::string::npos);
  }
  GltfFile f = triangle_file();
  f.primitive()["indices"] = f.accessor(f.view(kTriangle, sizeof(kTriangle)), 5126, "SCALAR", 3);
  auto s = f.load("float_indices");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(
      s.status().message().find("mesh 0 primitive 0: indices (accessor 1) is SCALAR of float"),
      std::string::npos)
      << s.status().message();
  // An attribute with a different count from POSITION's.
  GltfFile g = triangle_file();
  g.primitive()["attributes"]["NORMAL"] =
      g.accessor(g.view(kTriangle, sizeof(kTriangle)), 5126, "VEC3", 2);
  auto t = g.load("short_normal");
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.status().message().find("NORMAL (accessor 1) has 2 entries for 3 vertices"),
            std::string::npos)
      << t.status().message();
}

// Adds an EXT_meshopt_compression view: `compressed` stored in buffer 0, decoding into the
// placeholder buffer 1 (no uri) at `offset`.
size_t meshopt_view(GltfFile* f, const std::vector<uint8_t>& compressed, size_t count,
                    size_t stride, const char* mode, const char* filter, size_t offset) {
  size_t at = f->view(compressed.data(), compressed.size());
  json& v = f->doc["bufferViews"][at];
  json ext = {{"buffer", 0},
              {"byteOffset", v["byteOffset"]},
              {"byteLength", compressed.size()},
              {"byteStride", stride},
              {"count", count},
              {"mode", mode},
              {"filter", filter}};
  v = {{"buffer", 1},
       {"byteOffset", offset},
       {"byteLength", count * stride},
       {"extensions", {{"EXT_meshopt_compression", ext}}}};
  if (std::string(mode) == "ATTRIBUTES") v["byteStride"] = stride;
  return at;
}

std::vector<uint8_t> encode_vertices(const void* data, size_t count, size_t stride) {
  std::vector<uint8_t> out(meshopt_encodeVertexBufferBound(count, stride));
  out.resize(meshopt_encodeVertexBuffer(out.data(), out.size(), data, count, stride));
  return out;
}

const json kPlaceholder = {{"byteLength", 4096},
                           {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}};

TEST(GltfAccessors, MeshoptViewsWithEveryModeAndFilter) {
  // Positions through the EXPONENTIAL filter (exact for these values), normals OCTAHEDRAL,
  // a unit quaternion as a TANGENT through QUATERNION, a UV set unfiltered; indices as
  // TRIANGLES, and the same indices as an INDICES sequence in a second primitive.
  const float pos[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0.5f};
  const float nrm[16] = {0, 0, 1, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0.6f, 0.8f, 0, 0};
  const float quat[16] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const uint16_t uv[8] = {0, 0, 65535, 0, 0, 65535, 65535, 65535};
  const uint32_t tri[6] = {0, 1, 2, 2, 1, 3};
  std::vector<uint32_t> pos_exp(12), nrm_oct(4), quat_q(8);
  meshopt_encodeFilterExp(pos_exp.data(), 4, 12, 24, pos);
  meshopt_encodeFilterOct(nrm_oct.data(), 4, 4, 8, nrm);
  meshopt_encodeFilterQuat(quat_q.data(), 4, 8, 12, quat);
  std::vector<uint8_t> itri(meshopt_encodeIndexBufferBound(6, 4));
  itri.resize(meshopt_encodeIndexBuffer(itri.data(), itri.size(), tri, 6));
  std::vector<uint8_t> iseq(meshopt_encodeIndexSequenceBound(6, 4));
  iseq.resize(meshopt_encodeIndexSequence(iseq.data(), iseq.size(), tri, 6));

  GltfFile f;
  auto& attrs = f.primitive()["attributes"];
  attrs["POSITION"] = f.accessor(meshopt_view(&f, encode_vertices(pos_exp.data(), 4, 12), 4, 12,
                                              "ATTRIBUTES", "EXPONENTIAL", 0),
                                 5126, "VEC3", 4);
  attrs["NORMAL"] = f.accessor(
      meshopt_view(&f, encode_vertices(nrm_oct.data(), 4, 4), 4, 4, "ATTRIBUTES", "OCTAHEDRAL", 48),
      5120, "VEC3", 4, true);
  attrs["TANGENT"] = f.accessor(
      meshopt_view(&f, encode_vertices(quat_q.data(), 4, 8), 4, 8, "ATTRIBUTES", "QUATERNION", 64),
      5122, "VEC4", 4, true);
  attrs["TEXCOORD_0"] =
      f.accessor(meshopt_view(&f, encode_vertices(uv, 4, 4), 4, 4, "ATTRIBUTES", "NONE", 96), 5123,
                 "VEC2", 4, true);
  f.primitive()["indices"] =
      f.accessor(meshopt_view(&f, itri, 6, 4, "TRIANGLES", "NONE", 112), 5125, "SCALAR", 6);
  json second = f.primitive();
  second["indices"] =
      f.accessor(meshopt_view(&f, iseq, 6, 4, "INDICES", "NONE", 136), 5125, "SCALAR", 6);
  f.doc["meshes"][0]["primitives"].push_back(second);
  f.doc["extensionsUsed"] = {"EXT_meshopt_compression", "KHR_mesh_quantization"};
  auto s = f.load("meshopt", json::array({kPlaceholder}));
  ASSERT_TRUE(s.ok()) << s.status().message();
  const auto& p = only_primitive(*s);
  EXPECT_EQ(p.positions, (std::vector<scene::Vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0.5f}}));
  ASSERT_EQ(p.normals.size(), 4u);
  for (int v = 0; v < 4; ++v)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(p.normals[v][k], nrm[v * 4 + k], 0.02) << v << k;
  ASSERT_EQ(p.tangents.size(), 4u);
  EXPECT_NEAR(p.tangents[0][3], 1.0, 1e-3);
  EXPECT_EQ(p.uvs[0], (std::vector<scene::Vec2>{{0, 0}, {1, 0}, {0, 1}, {1, 1}}));
  EXPECT_EQ(p.indices, (std::vector<uint32_t>(tri, tri + 6)));
  EXPECT_EQ(s->meshes[0].primitives[1].indices, p.indices);
}

TEST(GltfAccessors, MeshoptErrorsNameTheView) {
  const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::vector<uint8_t> enc = encode_vertices(pos, 3, 12);
  std::vector<uint8_t> broken = enc;
  broken[0] = 0x55;  // not the vertex codec's header byte
  GltfFile f;
  f.primitive()["attributes"]["POSITION"] =
      f.accessor(meshopt_view(&f, broken, 3, 12, "ATTRIBUTES", "NONE", 0), 5126, "VEC3", 3);
  auto s = f.load("meshopt_bad", json::array({kPlaceholder}));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.status().message().find("bufferView 0: EXT_meshopt_compression: ATTRIBUTES data "
                                      "does not decode"),
            std::string::npos)
      << s.status().message();
  // A filter the spec forbids for the stride, and a count the compressed bytes cannot hold.
  f.doc["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["filter"] = "QUATERNION";
  auto t = f.load("meshopt_filter", json::array({kPlaceholder}));
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.status().message().find("filter 'QUATERNION' is not allowed"), std::string::npos)
      << t.status().message();
  GltfFile g;
  size_t huge = size_t{1} << 26;
  g.primitive()["attributes"]["POSITION"] =
      g.accessor(meshopt_view(&g, enc, huge, 12, "ATTRIBUTES", "NONE", 0), 5126, "VEC3", huge);
  std::string path = g.write("meshopt_huge", json::array({kPlaceholder}));
  std::optional<Expected<scene::Scene>> u;
  size_t largest = largest_allocation_during([&] { u.emplace(scene::load_scene(path)); });
  ASSERT_FALSE(u->ok());
  EXPECT_NE(u->status().message().find("count 67108864 x 12 bytes needs 768.0 MiB but its"),
            std::string::npos)
      << u->status().message();
  EXPECT_LT(largest, size_t{1} << 20);
}

// The hostile file of issue 20: 1.3 KB whose accessor claims 2^27 vertices. It is refused with
// the sizes named, before anything near its claim is allocated; counts above the ceilings are
// resource-limit errors, also for accessors of zeros that no bytes back.
TEST(GltfAccessors, HugeCountsAreRefusedBeforeAllocating) {
  std::vector<uint8_t> zeros(1300, 0);
  GltfFile f;
  f.primitive()["attributes"]["POSITION"] =
      f.accessor(f.view(zeros.data(), zeros.size()), 5126, "VEC3", size_t{1} << 27);
  std::string path = f.write("huge");
  std::optional<Expected<scene::Scene>> s;
  size_t largest = largest_allocation_during([&] { s.emplace(scene::load_scene(path)); });
  ASSERT_FALSE(s->ok());
  EXPECT_EQ(s->status().code(), ErrorCode::kCorrupt);
  EXPECT_EQ(
      s->status().message(),
      path +
          ": mesh 0 primitive 0: POSITION: accessor 0: count 134217728 x 12 bytes needs 1.5 GiB "
          "but bufferView 0 holds 1,300 bytes");
  EXPECT_LT(largest, size_t{64} << 10);

  struct Case {
    json accessor;
    bool indices;
    ErrorCode code;
    const char* message;
  } cases[] = {
      {{{"componentType", 5126}, {"type", "VEC3"}, {"count", size_t{1} << 29}},
       false,
       ErrorCode::kResourceLimit,
       "accessor 1: count 536870912 exceeds the ceiling of 268,435,456 vertices per primitive"},
      {{{"componentType", 5125}, {"type", "SCALAR"}, {"count", size_t{1} << 31}},
       true,
       ErrorCode::kResourceLimit,
       "accessor 1: count 2147483648 exceeds the ceiling of 1,073,741,824 indices per primitive"},
      {{{"componentType", 5125}, {"type", "SCALAR"}, {"count", -1}},
       true,
       ErrorCode::kCorrupt,
       "accessors[1].count: expected a non-negative integer"},
      {{{"componentType", 5125},
        {"type", "SCALAR"},
        {"count", 3},
        {"bufferView", 0},
        {"byteOffset", 1296}},
       true,
       ErrorCode::kCorrupt,
       "accessor 1: count 3 x 4 bytes needs 12 bytes but bufferView 0 holds 4 bytes after "
       "byteOffset 1296"},
  };
  for (const Case& c : cases) {
    GltfFile g = triangle_file();
    g.view(zeros.data(), zeros.size());
    std::swap(g.doc["bufferViews"][0], g.doc["bufferViews"][1]);  // zeros = view 0
    g.doc["accessors"][0]["bufferView"] = 1;
    size_t a = g.accessor(c.accessor);
    if (c.indices)
      g.primitive()["indices"] = a;
    else
      g.primitive()["attributes"]["NORMAL"] = a;
    std::string gp = g.write("limit");
    std::optional<Expected<scene::Scene>> t;
    size_t most = largest_allocation_during([&] { t.emplace(scene::load_scene(gp)); });
    ASSERT_FALSE(t->ok()) << c.message;
    EXPECT_EQ(t->status().code(), c.code) << t->status().message();
    EXPECT_NE(t->status().message().find(c.message), std::string::npos) << t->status().message();
    EXPECT_LT(most, size_t{64} << 10);
  }
}

}  // namespace
}  // namespace vt::test
