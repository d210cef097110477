// Importer and exporter round trips on small files written by the tests: OBJ+MTL, PLY ascii
// and binary, glTF with an external .bin, .glb (through save_glb), Draco .drc and glTF with
// KHR_draco_mesh_compression. Also the errors: missing and malformed files name the file.
#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "scene/image_load.h"
#include "tests/scene/pcx_files.h"
#include "tests/scene/scene_warnings.h"
#include "tests/unwrap/mesh_gen.h"

namespace vt::test {
namespace {

std::string temp(const std::string& name) {
  return ::testing::TempDir() + "vt_unwrap_io_" + name;
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// Writes `text` to the temporary file `name` and loads it.
Expected<scene::Scene> write_and_load(const std::string& name, const std::string& text) {
  write_text(temp(name), text);
  return scene::load_scene(temp(name));
}

void write_bytes(const std::string& path, const void* data, size_t size) {
  std::ofstream(path, std::ios::binary)
      .write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
}

// A PLY header: `vertices` float x, y, z vertices, then one list element ("face 2",
// "tristrips 1") of vertex_indices lists with `list_types` ("uchar int": count, index).
std::string ply_header(const std::string& format, int vertices, const std::string& list_element,
                       const std::string& list_types) {
  return "ply\nformat " + format + " 1.0\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement " + list_element +
         "\nproperty list " + list_types + " vertex_indices\nend_header\n";
}

TEST(SceneIo, ObjWithMtlQuadsNegativeIndicesAndMaterials) {
  write_text(
      temp("a.mtl"),
      "newmtl red\nKd 1 0 0\nmap_Kd -bm 1 tex/red.png\nnewmtl glass\nKd 0.5 0.5 0.5\nd 0.25\n");
  auto s = write_and_load(
      "a.obj",
      "# quad and triangle\nmtllib vt_unwrap_io_a.mtl\n"
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
      "usemtl red\nf 1/1/1 2/2/1 3/3/1 4/4/1\n"
      "usemtl glass\nf -4/-4/-1 -2/-2/-1 -1/-1/-1\n");
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->materials.size(), 2u);
  EXPECT_EQ(s->materials[0].name, "red");
  EXPECT_FLOAT_EQ(s->materials[0].base_color_factor[0], 1.0f);
  ASSERT_TRUE(s->materials[0].base_color_texture.valid());
  EXPECT_EQ(s->images[s->materials[0].base_color_texture.image].uri, "tex/red.png");
  EXPECT_EQ(s->images[0].path, ::testing::TempDir() + "tex/red.png");
  EXPECT_EQ(s->materials[1].alpha_mode, scene::AlphaMode::kBlend);
  EXPECT_FLOAT_EQ(s->materials[1].base_color_factor[3], 0.25f);
  ASSERT_EQ(s->meshes.size(), 1u);
  const auto& prims = s->meshes[0].primitives;
  ASSERT_EQ(prims.size(), 2u);
  EXPECT_EQ(prims[0].material, 0);
  EXPECT_EQ(prims[0].triangle_count(), 2u);  // the quad, fanned
  EXPECT_EQ(prims[0].positions.size(), 4u);
  EXPECT_EQ(prims[1].triangle_count(), 1u);
  ASSERT_EQ(prims[0].uvs.size(), 1u);
  // OBJ's v-up becomes glTF's v-down: vertex 1 (vt 0 0) has v = 1.
  EXPECT_FLOAT_EQ(prims[0].uvs[0][0][1], 1.0f);
  EXPECT_FLOAT_EQ(prims[0].normals[0][2], 1.0f);
  EXPECT_TRUE(scene::validate_geometry(*s).ok());
}

TEST(SceneIo, ObjErrorsNameFileAndLine) {
  auto s = write_and_load("bad.obj", "v 0 0 0\nv 1 0 0\nf 1 2 7\n");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.status().message().find("bad.obj:3"), std::string::npos) << s.status().message();
  auto missing = scene::load_scene(temp("does_not_exist.obj"));
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), ErrorCode::kNotFound);
  EXPECT_NE(missing.status().message().find("does_not_exist.obj"), std::string::npos);
  EXPECT_EQ(scene::load_scene(temp("x.fbx")).status().code(), ErrorCode::kNotFound);
  EXPECT_EQ(scene::load_scene(temp("x.notascene")).status().code(), ErrorCode::kUnsupported);
}

TEST(SceneIo, PlyAsciiAndBinary) {
  auto a = write_and_load("a.ply", ply_header("ascii", 4, "face 2", "uchar int") +
                                       "0 0 0\n1 0 0\n1 1 0\n0 1 0.5\n3 0 1 2\n3 0 2 3\n");
  ASSERT_TRUE(a.ok()) << a.status().message();
  const auto& pa = a->meshes[0].primitives[0];
  ASSERT_EQ(pa.triangle_count(), 2u);
  ASSERT_EQ(pa.positions.size(), 4u);
  EXPECT_FLOAT_EQ(pa.positions[pa.indices[5]][2], 0.5f);

  std::string body = ply_header("binary_little_endian", 3, "face 1", "uchar int");
  float v[9] = {0, 0, 0, 2, 0, 0, 0, 3, 0};
  body.append(reinterpret_cast<const char*>(v), sizeof(v));
  unsigned char count = 3;
  int idx[3] = {0, 1, 2};
  body.push_back(static_cast<char>(count));
  body.append(reinterpret_cast<const char*>(idx), sizeof(idx));
  auto b = write_and_load("b.ply", body);
  ASSERT_TRUE(b.ok()) << b.status().message();
  const auto& pb = b->meshes[0].primitives[0];
  ASSERT_EQ(pb.triangle_count(), 1u);
  float ys = 0;
  for (const auto& p : pb.positions) ys = std::max(ys, p[1]);
  EXPECT_FLOAT_EQ(ys, 3.0f);

  auto c = write_and_load(
      "c.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n");
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("c.ply"), std::string::npos);
}

TEST(SceneIo, PlyTristripsWithRestart) {
  // Draco's reader has no tristrips element; the fallback reader turns strips into triangles
  // with alternating winding, restarting at -1.
  auto s =
      write_and_load("s.ply", ply_header("ascii", 6, "tristrips 1", "int int") +
                                  "0 0 0\n1 0 0\n0 1 0\n1 1 0\n5 0 0\n6 0 0\n8 0 1 2 3 -1 4 5 2\n");
  ASSERT_TRUE(s.ok()) << s.status().message();
  const auto& p = s->meshes[0].primitives[0];
  EXPECT_EQ(p.indices, (std::vector<uint32_t>{0, 1, 2, 2, 1, 3, 4, 5, 2}));
  // All three triangles face +z (counter-clockwise seen from above).
  for (size_t t = 0; t < 3; ++t) {
    const auto& a = p.positions[p.indices[3 * t]];
    const auto& b = p.positions[p.indices[3 * t + 1]];
    const auto& c = p.positions[p.indices[3 * t + 2]];
    EXPECT_GT((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]), 0) << t;
  }
  // A truncated strip list is an error naming the file.
  auto bad = write_and_load(
      "s2.ply", ply_header("binary_little_endian", 1, "tristrips 1", "int int") + "\x01\x02");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("s2.ply"), std::string::npos);
}

// Every PLY scalar type under both its names, big endian: tristrips send the file to the
// fallback reader, which must read (or skip) each property at its own size.
TEST(SceneIo, PlyFallbackReadsEveryScalarTypeBigEndian) {
  std::string body =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\n"
      "property int16 y\nproperty float32 z\nproperty uchar a\nproperty int8 b\n"
      "property ushort c\nproperty uint32 d\nproperty float64 e\n"
      "element tristrips 1\nproperty list uint8 int vertex_indices\nend_header\n";
  auto put = [&](const void* v, size_t n) {  // big endian
    const char* b = static_cast<const char*>(v);
    for (size_t i = n; i-- > 0;) body.push_back(b[i]);
  };
  const double xs[3] = {0.5, 2.25, -1.0};
  const int16_t ys[3] = {-3, 7, 300};
  const float zs[3] = {1.5f, -2.0f, 4.0f};
  for (int k = 0; k < 3; ++k) {
    const uint8_t a = 200;
    const int8_t b = -5;
    const uint16_t c = 60000;
    const uint32_t d = 4000000000u;
    const double e = 1e300;
    put(&xs[k], 8), put(&ys[k], 2), put(&zs[k], 4), put(&a, 1), put(&b, 1), put(&c, 2), put(&d, 4),
        put(&e, 8);
  }
  const uint8_t count = 3;
  const int32_t strip[3] = {0, 1, 2};
  put(&count, 1);
  for (int32_t i : strip) put(&i, 4);
  auto s = write_and_load("types.ply", body);
  ASSERT_TRUE(s.ok()) << s.status().message();
  const auto& p = s->meshes[0].primitives[0];
  ASSERT_EQ(p.positions.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(p.positions[k][0], float(xs[k])) << k;
    EXPECT_EQ(p.positions[k][1], float(ys[k])) << k;
    EXPECT_EQ(p.positions[k][2], zs[k]) << k;
  }
  EXPECT_EQ(p.indices, (std::vector<uint32_t>{0, 1, 2}));
  // An unknown type is no size at all: the data cannot be read.
  auto bad = write_and_load(
      "types2.ply",
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty quad x\n"
      "element tristrips 0\nproperty list uchar int vertex_indices\nend_header\n0123456789abcdef");
  EXPECT_FALSE(bad.ok());
}

// A glTF with an external .bin: two nodes (TRS parent, child with a matrix) instancing one
// mesh, a textured material with a sampler, uint16 indices and a normalised uint8 colour.
TEST(SceneIo, GltfWithExternalBufferNodesAndMaterials) {
  std::vector<uint8_t> bin;
  float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  float uv[6] = {0, 0, 1, 0, 0, 1};
  uint16_t idx[3] = {0, 1, 2};
  uint8_t col[12] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 128};
  auto put = [&](const void* d, size_t n) {
    const auto* p = static_cast<const uint8_t*>(d);
    bin.insert(bin.end(), p, p + n);
    while (bin.size() % 4) bin.push_back(0);
  };
  put(pos, sizeof(pos));
  put(uv, sizeof(uv));
  put(idx, sizeof(idx));
  put(col, sizeof(col));
  write_bytes(temp("g.bin"), bin.data(), bin.size());
  nlohmann::json doc = R"({
    "asset": {"version": "2.0"},
    "buffers": [{"uri": "vt_unwrap_io_g.bin", "byteLength": 80}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                    {"buffer": 0, "byteOffset": 36, "byteLength": 24},
                    {"buffer": 0, "byteOffset": 60, "byteLength": 6},
                    {"buffer": 0, "byteOffset": 68, "byteLength": 12}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                  {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
                  {"bufferView": 2, "componentType": 5123, "count": 3, "type": "SCALAR"},
                  {"bufferView": 3, "componentType": 5121, "normalized": true, "count": 3, "type": "VEC4"}],
    "images": [{"uri": "albedo%20map.png"}],
    "samplers": [{"wrapS": 33071, "wrapT": 33648}],
    "textures": [{"source": 0, "sampler": 0}],
    "materials": [{"name": "m", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1],
                   "baseColorTexture": {"index": 0, "texCoord": 0}, "metallicFactor": 0.25},
                   "normalTexture": {"index": 0, "scale": 0.5}, "alphaMode": "MASK", "alphaCutoff": 0.3,
                   "emissiveFactor": [1, 0.5, 0]}],
    "meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "COLOR_0": 3},
                "indices": 2, "material": 0}]}],
    "nodes": [{"name": "parent", "translation": [10, 0, 0], "scale": [2, 2, 2], "children": [1], "mesh": 0},
              {"name": "child", "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1], "mesh": 0}],
    "scenes": [{"nodes": [0]}], "scene": 0
  })"_json;
  auto s = write_and_load("g.gltf", doc.dump());
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->meshes.size(), 1u);
  const auto& p = s->meshes[0].primitives[0];
  EXPECT_EQ(p.indices, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_FLOAT_EQ(p.uvs[0][2][1], 1.0f);
  EXPECT_NEAR(p.colors[2][3], 128.0 / 255.0, 1e-6);
  const auto& m = s->materials[0];
  EXPECT_FLOAT_EQ(m.metallic_factor, 0.25f);
  EXPECT_EQ(m.alpha_mode, scene::AlphaMode::kMask);
  EXPECT_FLOAT_EQ(m.alpha_cutoff, 0.3f);
  EXPECT_FLOAT_EQ(m.normal_scale, 0.5f);
  EXPECT_EQ(m.base_color_texture.wrap_s, scene::WrapMode::kClampToEdge);
  EXPECT_EQ(m.base_color_texture.wrap_t, scene::WrapMode::kMirroredRepeat);
  EXPECT_EQ(s->images[0].path, ::testing::TempDir() + "albedo map.png");
  auto inst = s->instances();
  ASSERT_EQ(inst.size(), 2u);
  auto w = scene::transform_point(inst[1].world, {1, 0, 0});
  EXPECT_DOUBLE_EQ(w[0], 12.0);  // child: parent scale 2 and translation 10
  EXPECT_DOUBLE_EQ(w[2], 10.0);  // child's own z = 5, scaled by 2

  // Out-of-bounds accessor: a clear error naming the file.
  doc["accessors"][0]["count"] = 1000;
  auto bad = write_and_load("h.gltf", doc.dump());
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("h.gltf"), std::string::npos);
  EXPECT_NE(bad.status().message().find("accessor 0"), std::string::npos) << bad.status().message();
}

TEST(SceneIo, GlbRoundTripThroughExporter) {
  Scene s = scene_of(sphere(8, 4), "ball");
  auto& p = s.meshes[0].primitives[0];
  p.normals = p.positions;
  p.uvs.resize(1);
  for (const auto& v : p.positions) p.uvs[0].push_back({v[0], v[1]});
  p.colors.assign(p.positions.size(), {0.25f, 0.5f, 0.75f, 1});
  p.material = 0;
  scene::Material mat;
  mat.name = "mat";
  mat.base_color_texture.image = 0;
  mat.base_color_texture.wrap_s = scene::WrapMode::kClampToEdge;
  mat.emissive_factor = {1, 2, 3};
  mat.double_sided = true;
  s.materials.push_back(mat);
  scene::Image embedded;
  embedded.mime_type = "image/png";
  embedded.bytes = {0x89, 'P', 'N', 'G', 1, 2, 3};
  s.images.push_back(embedded);
  s.nodes[0].local[13] = 3.5;
  std::string path = temp("r.glb");
  ASSERT_TRUE(scene::save_glb(s, path).ok());
  auto back = scene::load_scene(path);
  ASSERT_TRUE(back.ok()) << back.status().message();
  const auto& q = back->meshes[0].primitives[0];
  EXPECT_EQ(q.positions, p.positions);
  EXPECT_EQ(q.normals, p.normals);
  EXPECT_EQ(q.uvs, p.uvs);
  EXPECT_EQ(q.colors, p.colors);
  EXPECT_EQ(q.indices, p.indices);
  EXPECT_EQ(q.material, 0);
  EXPECT_EQ(back->meshes[0].name, "ball");
  EXPECT_EQ(back->materials[0].base_color_texture.wrap_s, scene::WrapMode::kClampToEdge);
  EXPECT_EQ(back->materials[0].emissive_factor, mat.emissive_factor);
  EXPECT_TRUE(back->materials[0].double_sided);
  ASSERT_EQ(back->images.size(), 1u);
  EXPECT_EQ(back->images[0].bytes, embedded.bytes);
  EXPECT_EQ(back->images[0].mime_type, "image/png");
  EXPECT_DOUBLE_EQ(back->nodes[0].local[13], 3.5);

  // A truncated .glb is an error naming the file, never a crash.
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (size_t cut : {size_t{10}, size_t{30}, bytes.size() / 2, bytes.size() - 4}) {
    auto t = write_and_load("t.glb", bytes.substr(0, cut));
    ASSERT_FALSE(t.ok()) << cut;
    EXPECT_NE(t.status().message().find("t.glb"), std::string::npos) << t.status().message();
  }
}

// Encodes a two-triangle mesh with Draco (positions and one UV set).
std::vector<char> draco_bytes(int* pos_id, int* uv_id) {
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(2);
  *pos_id = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  *uv_id = builder.AddAttribute(draco::GeometryAttribute::TEX_COORD, 2, draco::DT_FLOAT32);
  float p[2][9] = {{0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 0, 1, 1, 0, 0, 1, 0}};
  float t[2][6] = {{0, 0, 1, 0, 1, 1}, {0, 0, 1, 1, 0, 1}};
  for (int f = 0; f < 2; ++f) {
    builder.SetAttributeValuesForFace(*pos_id, draco::FaceIndex(f), p[f], p[f] + 3, p[f] + 6);
    builder.SetAttributeValuesForFace(*uv_id, draco::FaceIndex(f), t[f], t[f] + 2, t[f] + 4);
  }
  auto mesh = builder.Finalize();
  *pos_id = mesh->attribute(*pos_id)->unique_id();
  *uv_id = mesh->attribute(*uv_id)->unique_id();
  draco::Encoder encoder;
  draco::EncoderBuffer buffer;
  EXPECT_TRUE(encoder.EncodeMeshToBuffer(*mesh, &buffer).ok());
  return std::vector<char>(buffer.data(), buffer.data() + buffer.size());
}

TEST(SceneIo, DracoFileAndKhrDracoPrimitive) {
  int pos_id = 0, uv_id = 0;
  auto bytes = draco_bytes(&pos_id, &uv_id);
  write_bytes(temp("m.drc"), bytes.data(), bytes.size());
  auto d = scene::load_scene(temp("m.drc"));
  ASSERT_TRUE(d.ok()) << d.status().message();
  const auto& p = d->meshes[0].primitives[0];
  EXPECT_EQ(p.triangle_count(), 2u);
  ASSERT_EQ(p.uvs.size(), 1u);
  double area = 0;
  for (size_t t = 0; t < 2; ++t) {
    const auto& a = p.positions[p.indices[3 * t]];
    const auto& b = p.positions[p.indices[3 * t + 1]];
    const auto& c = p.positions[p.indices[3 * t + 2]];
    area += 0.5 * std::abs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
  }
  EXPECT_NEAR(area, 1.0, 1e-6);  // unquantised Draco is lossless

  // The same bytes as a KHR_draco_mesh_compression primitive in a .gltf (data: URI buffer).
  std::string b64;
  {
    static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (size_t i = 0; i < bytes.size(); i += 3) {
      uint32_t v = static_cast<uint8_t>(bytes[i]) << 16;
      if (i + 1 < bytes.size()) v |= static_cast<uint8_t>(bytes[i + 1]) << 8;
      if (i + 2 < bytes.size()) v |= static_cast<uint8_t>(bytes[i + 2]);
      b64 += k[(v >> 18) & 63];
      b64 += k[(v >> 12) & 63];
      b64 += i + 1 < bytes.size() ? k[(v >> 6) & 63] : '=';
      b64 += i + 2 < bytes.size() ? k[v & 63] : '=';
    }
  }
  nlohmann::json doc = {
      {"asset", {{"version", "2.0"}}},
      {"extensionsUsed", {"KHR_draco_mesh_compression"}},
      {"extensionsRequired", {"KHR_draco_mesh_compression"}},
      {"buffers",
       {{{"uri", "data:application/octet-stream;base64," + b64}, {"byteLength", bytes.size()}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", bytes.size()}}}},
      {"accessors",
       {{{"componentType", 5126}, {"count", 4}, {"type", "VEC3"}},
        {{"componentType", 5126}, {"count", 4}, {"type", "VEC2"}},
        {{"componentType", 5125}, {"count", 6}, {"type", "SCALAR"}}}},
      {"meshes",
       {{{"primitives",
          {{{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}}},
            {"indices", 2},
            {"extensions",
             {{"KHR_draco_mesh_compression",
               {{"bufferView", 0},
                {"attributes", {{"POSITION", pos_id}, {"TEXCOORD_0", uv_id}}}}}}}}}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"scenes", {{{"nodes", {0}}}}}};
  auto k = write_and_load("k.gltf", doc.dump());
  ASSERT_TRUE(k.ok()) << k.status().message();
  const auto& q = k->meshes[0].primitives[0];
  EXPECT_EQ(q.triangle_count(), 2u);
  ASSERT_EQ(q.uvs.size(), 1u);
  EXPECT_EQ(q.positions.size(), p.positions.size());

  // Corrupt Draco bytes: an error naming the file.
  bytes.resize(bytes.size() / 2);
  write_bytes(temp("bad.drc"), bytes.data(), bytes.size());
  auto bad = scene::load_scene(temp("bad.drc"));
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("bad.drc"), std::string::npos);
}

TEST(SceneIo, UnwrappedSceneSurvivesGlbRoundTrip) {
  Scene s = scene_of(sphere(12, 6));
  unwrap::UnwrapOptions o;
  o.size_pages = 2;
  auto r = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(scene::save_glb(r->scene, temp("u.glb")).ok());
  auto back = scene::load_scene(temp("u.glb"));
  ASSERT_TRUE(back.ok());
  const auto& a = r->scene.meshes[0].primitives[0];
  const auto& b = back->meshes[0].primitives[0];
  ASSERT_EQ(b.uvs.size(), 1u);  // TEXCOORD_0: the sphere had no UV set
  EXPECT_EQ(a.uvs[0], b.uvs[0]);
  EXPECT_EQ(a.indices, b.indices);
}

// Embedded images are read by a name whose extension picks the decoder: MIME type first, then
// the bytes' magic (a .glb image with a missing or wrong mimeType), PNG last.
// PCX images (Quake 2's skins; OpenImageIO has no reader for them) are decoded at load and
// carried as embedded PNGs: a 256-colour image (run-length runs, the palette at the end) and a
// 24-bit one (three planes, a byte of 0xC0 or more escaped as a run of one).
TEST(SceneIo, PcxTexturesAreReadAsEmbeddedImages) {
  write_text(temp("pal.pcx"), pcx_paletted_3x2());
  write_text(temp("rgb.pcx"), pcx_rgb_3x1());
  write_text(temp("pcx.mtl"), "newmtl pal\nmap_Kd " + temp("pal.pcx") + "\nnewmtl rgb\nmap_Kd " +
                                  temp("rgb.pcx") + "\n");
  auto s = write_and_load("pcx.obj", "mtllib " + temp("pcx.mtl") +
                                         "\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                                         "usemtl pal\nf 1/1 2/2 3/3\nusemtl rgb\nf 1/1 3/3 2/2\n");
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->images.size(), 2u);
  auto texels = [&](int i) {
    EXPECT_TRUE(s->images[i].embedded());
    EXPECT_EQ(s->images[i].mime_type, "image/png");
    auto t = scene::load_float_image(s->images[i]);
    EXPECT_TRUE(t.ok()) << t.status().message();
    return t.ok() ? *t : scene::FloatImage{};
  };
  const scene::FloatImage p = texels(0);
  ASSERT_EQ(p.width, 3u);
  ASSERT_EQ(p.height, 2u);
  const int want[2][3] = {{1, 2, 1}, {2, 2, 1}};  // 1 red, 2 blue
  for (uint32_t y = 0; y < 2; ++y)
    for (uint32_t x = 0; x < 3; ++x) {
      EXPECT_EQ(p.at(x, y)[0], want[y][x] == 1 ? 1.0f : 0.0f) << x << " " << y;
      EXPECT_EQ(p.at(x, y)[2], want[y][x] == 2 ? 1.0f : 0.0f) << x << " " << y;
    }
  const scene::FloatImage c = texels(1);
  ASSERT_EQ(c.width, 3u);
  ASSERT_EQ(c.height, 1u);
  const int rgb[3][3] = {{200, 40, 70}, {20, 50, 80}, {30, 60, 90}};
  for (uint32_t x = 0; x < 3; ++x)
    for (int ch = 0; ch < 3; ++ch)
      EXPECT_NEAR(c.at(x, 0)[ch] * 255.0f, rgb[x][ch], 1e-3) << x << " " << ch;
  // A header asking for 65,535 x 65,536 texels of four planes from a few bytes.
  std::string huge = pcx_header(1, 1, 4, 255);
  huge[8] = char(254), huge[9] = huge[10] = huge[11] = char(255);  // 65,535 x 65,536
  huge[66] = huge[67] = char(255);
  write_text(temp("rgb.pcx"), huge + std::string(64, '\xff'));
  auto big = scene::load_scene(temp("pcx.obj"));
  ASSERT_TRUE(big.ok()) << big.status().message();
  EXPECT_FALSE(big->images[1].embedded());
  EXPECT_TRUE(warned(*big, "65535 x 65536 texels need more data than the file holds"));
  // A PCX kind it does not read: a warning naming the file; the image stays a file.
  std::string ega = pcx_header(3, 1, 4, 4);
  ega[3] = 1;
  write_text(temp("pal.pcx"), ega + std::string(16, '\0'));
  auto ega_scene = scene::load_scene(temp("pcx.obj"));
  ASSERT_TRUE(ega_scene.ok()) << ega_scene.status().message();
  EXPECT_FALSE(ega_scene->images[0].embedded());
  EXPECT_TRUE(warned(*ega_scene, "pal.pcx: not a readable PCX image (1 bits x 4 planes"));
}

TEST(EmbeddedImage, ExtensionFromMimeTypeThenMagic) {
  scene::Image img;
  img.mime_type = "image/jpeg";
  EXPECT_STREQ(img.embedded_extension(), ".jpg");
  img.mime_type = "image/webp";
  EXPECT_STREQ(img.embedded_extension(), ".webp");
  img.mime_type = "image/x-exr";
  EXPECT_STREQ(img.embedded_extension(), ".exr");
  img.mime_type.clear();
  img.bytes = {0xFF, 0xD8, 0xFF, 0xE0};
  EXPECT_STREQ(img.embedded_extension(), ".jpg");
  img.bytes = {0x76, 0x2F, 0x31, 0x01, 2, 0, 0, 0};
  EXPECT_STREQ(img.embedded_extension(), ".exr");
  img.bytes = {'R', 'I', 'F', 'F', 0, 0, 0, 0, 'W', 'E', 'B', 'P'};
  EXPECT_STREQ(img.embedded_extension(), ".webp");
  img.bytes = {'R', 'I', 'F', 'F', 0, 0, 0, 0, 'W', 'A', 'V', 'E'};  // RIFF, but not WebP
  EXPECT_STREQ(img.embedded_extension(), ".png");
  img.bytes = {0xFF};  // too short for any magic
  EXPECT_STREQ(img.embedded_extension(), ".png");
}

// A normal moved by a mirror stays on the side of the surface it was on, where the moved
// triangle's edge cross product turns over with the reversed winding.
TEST(SceneMath, NormalsKeepTheirSideUnderAMirror) {
  scene::Mat4 m = scene::kIdentity;
  m[0] = -2, m[5] = 3, m[10] = 0.5;  // mirrored in x, scaled
  m[12] = 7;
  EXPECT_TRUE(scene::mirrors(m));
  EXPECT_FALSE(scene::mirrors(scene::kIdentity));
  const auto up = scene::transform_direction(m, {0, 1, 0});
  EXPECT_NEAR(up[1], 1, 1e-12);
  const auto side = scene::transform_direction(m, {1, 0, 0});
  EXPECT_NEAR(side[0], -1, 1e-12);
  // The inverse-transpose: a tilted normal leans as the scaled surface does.
  const auto tilted = scene::transform_direction(m, {0, 1, 1});
  EXPECT_NEAR(tilted[1] / tilted[2], (1.0 / 3) / (1.0 / 0.5), 1e-12);
  // The edge cross product of a moved triangle faces down; its normal says up.
  const auto a = scene::transform_point(m, {0, 0, 0}), b = scene::transform_point(m, {1, 0, 0}),
             c = scene::transform_point(m, {0, 0, -1});
  const double cross_y = (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2]);
  EXPECT_LT(cross_y, 0);
  // Two mirrors make a rotation.
  m[5] = -3;
  EXPECT_FALSE(scene::mirrors(m));
  EXPECT_NEAR(scene::transform_direction(m, {0, 1, 0})[1], -1, 1e-12);
}

}  // namespace
}  // namespace vt::test
