// Scenes read through assimp (COLLADA and STL written by the tests), glTF 1.0 routed to it, and
// the texture-path resolution every importer shares (Windows separators, letter case, absolute
// paths from the author's machine).
#include <assimp/texture.h>
#include <assimp/version.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "scene/image_load.h"
#include "scene/scene.h"
#include "scene/scene_io_util.h"
#include "tests/scene/iqm_file.h"
#include "tests/scene/le_bytes.h"
#include "tests/scene/scene_warnings.h"

namespace vt::test {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  fs::path d = fs::path(::testing::TempDir()) / ("vt_assimp_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// A COLLADA quad (two triangles) with UVs (`uvs`: four S T pairs), vertex colours and a diffuse
// texture `image`, a node translated by (5, 0, 0).
std::string collada_quad(const std::string& image, const std::string& uvs = "0 0 1 0 1 1 0 1") {
  return R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Y_UP</up_axis></asset>
  <library_images><image id="img"><init_from>)" +
         image + R"(</init_from></image></library_images>
  <library_effects><effect id="fx"><profile_COMMON>
    <newparam sid="surf"><surface type="2D"><init_from>img</init_from></surface></newparam>
    <newparam sid="samp"><sampler2D><source>surf</source></sampler2D></newparam>
    <technique sid="common"><lambert>
      <diffuse><texture texture="samp" texcoord="UV0"/></diffuse>
    </lambert></technique>
  </profile_COMMON></effect></library_effects>
  <library_materials><material id="mat" name="Painted"><instance_effect url="#fx"/></material></library_materials>
  <library_geometries><geometry id="quad"><mesh>
    <source id="pos"><float_array id="pos-a" count="12">0 0 0 1 0 0 1 1 0 0 1 0</float_array>
      <technique_common><accessor source="#pos-a" count="4" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
      </accessor></technique_common></source>
    <source id="uv"><float_array id="uv-a" count="8">)" +
         uvs + R"(</float_array>
      <technique_common><accessor source="#uv-a" count="4" stride="2">
        <param name="S" type="float"/><param name="T" type="float"/>
      </accessor></technique_common></source>
    <source id="col"><float_array id="col-a" count="12">1 0 0 0 1 0 0 0 1 1 1 1</float_array>
      <technique_common><accessor source="#col-a" count="4" stride="3">
        <param name="R" type="float"/><param name="G" type="float"/><param name="B" type="float"/>
      </accessor></technique_common></source>
    <vertices id="verts"><input semantic="POSITION" source="#pos"/></vertices>
    <triangles count="2" material="m">
      <input semantic="VERTEX" source="#verts" offset="0"/>
      <input semantic="TEXCOORD" source="#uv" offset="0" set="0"/>
      <input semantic="COLOR" source="#col" offset="0"/>
      <p>0 1 2 0 2 3</p>
    </triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="scene">
    <node id="n" name="Quad"><translate>5 0 0</translate>
      <instance_geometry url="#quad"><bind_material><technique_common>
        <instance_material symbol="m" target="#mat">
          <bind_vertex_input semantic="UV0" input_semantic="TEXCOORD" input_set="0"/>
        </instance_material>
      </technique_common></bind_material></instance_geometry>
    </node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
)";
}

TEST(AssimpImport, ColladaQuadWithTextureColoursAndTransform) {
  fs::path d = fresh_dir("dae");
  fs::create_directories(d / "maps");
  write_text(d / "maps" / "wall.png", "not read by the importer");
  write_text(d / "quad.dae", collada_quad("maps/wall.png"));
  auto s = scene::load_scene((d / "quad.dae").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->triangle_count(), 2u);
  auto instances = s->instances();
  ASSERT_EQ(instances.size(), 1u);
  auto p = scene::transform_point(instances[0].world, {0, 0, 0});
  EXPECT_NEAR(p[0], 5.0, 1e-9);
  const scene::Primitive& prim = s->meshes[instances[0].mesh].primitives[0];
  ASSERT_EQ(prim.uvs.size(), 1u);
  ASSERT_EQ(prim.colors.size(), prim.positions.size());
  ASSERT_EQ(prim.normals.size(), prim.positions.size());  // generated: the file has none
  // COLLADA's v is up; the scene model's is down (glTF). Find the corner at position (1, 1).
  bool seen = false;
  for (size_t v = 0; v < prim.positions.size(); ++v) {
    if (prim.positions[v][0] == 1 && prim.positions[v][1] == 1) {
      EXPECT_FLOAT_EQ(prim.uvs[0][v][0], 1.0f);
      EXPECT_FLOAT_EQ(prim.uvs[0][v][1], 0.0f);
      EXPECT_FLOAT_EQ(prim.colors[v][2], 1.0f);  // third vertex: blue
      seen = true;
    }
  }
  EXPECT_TRUE(seen);
  ASSERT_GE(prim.material, 0);
  const scene::Material& m = s->materials[prim.material];
  EXPECT_EQ(m.name, "Painted");
  ASSERT_TRUE(m.base_color_texture.valid());
  EXPECT_EQ(s->images[m.base_color_texture.image].path, (d / "maps" / "wall.png").string());
}

TEST(AssimpImport, TexturePathsFromOtherMachinesAreFoundWithAWarning) {
  fs::path d = fresh_dir("paths");
  fs::create_directories(d / "Tex");
  write_text(d / "Tex" / "Wall.PNG", "x");
  write_text(d / "floor.jpg", "x");
  std::string folder = d.string() + "/";
  std::string note;
  auto resolve = [&](const std::string& written) {
    return scene::detail::resolve_written_path(folder, written, &note);
  };
  // Windows separators alone: found directly, no warning.
  write_text(d / "Tex" / "ok.png", "x");
  EXPECT_EQ(resolve(".\\Tex\\ok.png"), folder + "Tex/ok.png");
  EXPECT_TRUE(note.empty());
  // Letter case differs on a case-sensitive file system.
  EXPECT_EQ(resolve("tex\\wall.png"), (d / "Tex" / "Wall.PNG").string());
  EXPECT_NE(note.find("letter case"), std::string::npos) << note;
  // An absolute path from the author's machine: the file name beside the scene.
  EXPECT_EQ(resolve("D:\\art\\floor.jpg"), (d / "floor.jpg").string());
  // A leading backslash means the scene's folder ("\\..\\maps\\x.jpg"), not a drive's root.
  fs::create_directories(d / "sub");
  EXPECT_EQ(scene::detail::resolve_written_path(folder + "sub/", "\\..\\floor.jpg", &note),
            folder + "sub/../floor.jpg");
  // Nothing anywhere: the plain resolution, so the error names what the file asked for.
  EXPECT_EQ(resolve("gone/none.png"), folder + "gone/none.png");
  // The same name with another image extension (Quake 3 shader names have none, and name .tga
  // files shipped as .jpg), in the folder as written (its letter case ignored), else beside.
  write_text(d / "Tex" / "bullet.jpg", "x");
  EXPECT_EQ(resolve("tex/bullet.tga"), (d / "Tex" / "bullet.jpg").string());
  EXPECT_NE(note.find("another extension"), std::string::npos) << note;
  write_text(d / "gauntlet.TGA", "x");
  EXPECT_EQ(resolve("models/weapons/Gauntlet"), (d / "gauntlet.TGA").string());
  // Several: the engine's order (.tga before .jpg before .png), not the folder's listing order.
  write_text(d / "both.png", "x");
  write_text(d / "both.jpg", "x");
  write_text(d / "both.tga", "x");
  EXPECT_EQ(resolve("both"), (d / "both.tga").string());
  // A textures folder beside the scene (FlightGear keeps Models/X/Textures/), with the name as
  // written, then with another extension.
  fs::create_directories(d / "Textures");
  write_text(d / "Textures" / "horloge.rgb", "x");
  EXPECT_EQ(resolve("horloge.rgb"), (d / "Textures" / "horloge.rgb").string());
  EXPECT_NE(note.find("textures folder"), std::string::npos) << note;
  write_text(d / "Textures" / "deck.png", "x");
  EXPECT_EQ(resolve("C:\\work\\deck.tga"), (d / "Textures" / "deck.png").string());
  // Only images stand in: a model of that name does not.
  write_text(d / "orb.md3", "x");
  EXPECT_EQ(resolve("orb.png"), folder + "orb.png");
  // A textures folder beside the scene's own (a game's models/ and textures/): after those
  // beside the scene.
  fs::create_directories(d / "models");
  fs::create_directories(d / "TEXTURES");
  write_text(d / "TEXTURES" / "cart.png", "x");
  EXPECT_EQ(scene::detail::resolve_written_path(folder + "models/", "cart.png", &note),
            folder + "models/../TEXTURES/cart.png");
  EXPECT_NE(note.find("textures folder"), std::string::npos) << note;
  fs::create_directories(d / "models" / "textures");
  write_text(d / "models" / "textures" / "cart.png", "x");
  EXPECT_EQ(scene::detail::resolve_written_path(folder + "models/", "cart.png", &note),
            folder + "models/textures/cart.png");
}

// A Blitz3D model whose animation has a key past the animation's end (Minetest's characters:
// key 221 of 220 frames). The bake takes the rest pose, so the animation is dropped, not the
// model (assimp's validation refused the whole file).
TEST(AssimpImport, AnimationKeysPastTheEndDoNotRefuseTheModel) {
  auto chunk = [](const char* tag, const std::string& body) {
    const int32_t n = int32_t(body.size());
    return std::string(tag, 4) + std::string(reinterpret_cast<const char*>(&n), 4) + body;
  };
  auto raw = [](std::initializer_list<float> f, std::initializer_list<int32_t> i = {}) {
    std::string out;
    for (int32_t v : i) out.append(reinterpret_cast<const char*>(&v), 4);
    for (float v : f) out.append(reinterpret_cast<const char*>(&v), 4);
    return out;
  };
  // One triangle with a UV set; an animation of 1 frame at 60 fps whose position keys are at
  // frames 1 and 3 (little-endian hosts, as B3D is).
  const std::string vrts = raw({0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, {0, 1, 2});
  const std::string mesh =
      chunk("MESH", raw({}, {-1}) + chunk("VRTS", vrts) + chunk("TRIS", raw({}, {-1, 0, 1, 2})));
  const std::string keys = chunk("KEYS", raw({}, {1}) + raw({0, 0, 0}, {1}) + raw({1, 0, 0}, {3}));
  const std::string anim = chunk("ANIM", raw({60}, {0, 1}));
  const std::string node = chunk(
      "NODE", std::string("tri", 4) + raw({0, 0, 0, 1, 1, 1, 1, 0, 0, 0}) + mesh + keys + anim);
  fs::path d = fresh_dir("b3d_anim");
  write_text(d / "anim.b3d", chunk("BB3D", raw({}, {1}) + node));
  auto s = scene::load_scene((d / "anim.b3d").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->meshes.size(), 1u);
  EXPECT_EQ(s->meshes[0].primitives.at(0).positions.size(), 3u);
  EXPECT_TRUE(warned(*s, "1 animations ignored"));
}

TEST(AssimpImport, UvSetWithOneCoordinateEverywhereIsKept) {
  // A Quake 3 flare samples a single texel: every UV equal. assimp's FindInvalidData would drop
  // the set, and the material's texture would then read a UV set the primitive lacks.
  fs::path d = fresh_dir("one_uv");
  write_text(d / "flare.dae", collada_quad("flare.png", "0.25 0.75 0.25 0.75 0.25 0.75 0.25 0.75"));
  auto s = scene::load_scene((d / "flare.dae").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->meshes.size(), 1u);
  const scene::Primitive& prim = s->meshes[0].primitives.at(0);
  ASSERT_EQ(prim.uvs.size(), 1u);
  ASSERT_EQ(prim.uvs[0].size(), prim.positions.size());
  for (const auto& uv : prim.uvs[0]) {
    EXPECT_FLOAT_EQ(uv[0], 0.25f);
    EXPECT_FLOAT_EQ(uv[1], 0.25f);  // v flipped to glTF's orientation
  }
}

TEST(AssimpImport, AsciiStlAndUnreadableFiles) {
  fs::path d = fresh_dir("stl");
  write_text(d / "tri.stl",
             "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
             "endloop\nendfacet\nendsolid t\n");
  auto s = scene::load_scene((d / "tri.stl").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->triangle_count(), 1u);
  write_text(d / "bad.fbx", "this is not an FBX file");
  auto bad = scene::load_scene((d / "bad.fbx").string());
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("bad.fbx: assimp"), std::string::npos)
      << bad.status().message();
  // Quake 3 maps: assimp's importer fails on real ones and is unsafe on crafted ones; refused
  // before it sees the file.
  write_text(d / "map.pk3", "PK not really");
  auto map = scene::load_scene((d / "map.pk3").string());
  ASSERT_FALSE(map.ok());
  EXPECT_EQ(map.status().code(), ErrorCode::kUnsupported);
  EXPECT_NE(map.status().message().find("Quake 3 BSP maps are not supported"), std::string::npos);
  // Irrlicht scenes: assimp before 5.3 reads no meshes from them (or fails on UTF-16 ones).
  write_text(d / "box.irr",
             "<?xml version=\"1.0\"?>\n<irr_scene><node type=\"cube\"></node></irr_scene>\n");
  auto irr = scene::load_scene((d / "box.irr").string());
  if (aiGetVersionMajor() * 100 + aiGetVersionMinor() < 503) {
    ASSERT_FALSE(irr.ok());
    EXPECT_EQ(irr.status().code(), ErrorCode::kUnsupported);
    EXPECT_NE(irr.status().message().find("Irrlicht scenes and meshes"), std::string::npos);
  }
  auto unknown = scene::load_scene((d / "x.notaformat").string());
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.status().message().find("unknown scene format"), std::string::npos);
}

TEST(AssimpImport, Gltf1IsReadThroughAssimp) {
  fs::path d = fresh_dir("gltf1");
  // A glTF 1.0 document: object-valued maps, asset.version "1.0". One triangle, embedded buffer.
  // Buffer: 3 float positions (36 bytes) + 3 u16 indices (6 bytes).
  const char* b64 = "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIA";
  write_text(d / "tri.gltf", std::string(R"({
  "asset": {"version": "1.0"},
  "buffers": {"b": {"uri": "data:application/octet-stream;base64,)") +
                                 b64 +
                                 R"(", "byteLength": 42}},
  "bufferViews": {
    "v": {"buffer": "b", "byteOffset": 0, "byteLength": 36, "target": 34962},
    "i": {"buffer": "b", "byteOffset": 36, "byteLength": 6, "target": 34963}},
  "accessors": {
    "pos": {"bufferView": "v", "byteOffset": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
    "idx": {"bufferView": "i", "byteOffset": 0, "componentType": 5123, "count": 3, "type": "SCALAR"}},
  "meshes": {"m": {"primitives": [{"attributes": {"POSITION": "pos"}, "indices": "idx", "mode": 4}]}},
  "nodes": {"n": {"meshes": ["m"]}},
  "scenes": {"s": {"nodes": ["n"]}},
  "scene": "s"
})");
  auto s = scene::load_scene((d / "tri.gltf").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->triangle_count(), 1u);
  EXPECT_TRUE(warned(*s, "glTF 1.0"));
}

// 3ds Max's COLLADA exporter writes <transparency> inverted: opacity 0 would hide the whole
// material, so it is read as opaque with a warning (Collada/earthCylindrical.DAE).
TEST(AssimpImport, ColladaOpacityZeroIsReadAsOpaque) {
  fs::path d = fresh_dir("dae_opacity");
  write_text(d / "wall.png", "not read by the importer");
  std::string dae = collada_quad("wall.png");
  const std::string diffuse = "<diffuse><texture texture=\"samp\" texcoord=\"UV0\"/></diffuse>";
  ASSERT_NE(dae.find(diffuse), std::string::npos);
  dae.replace(dae.find(diffuse), diffuse.size(),
              diffuse +
                  "<transparent opaque=\"A_ONE\"><color>1 1 1 1</color></transparent>"
                  "<transparency><float>0</float></transparency>");
  write_text(d / "quad.dae", dae);
  auto s = scene::load_scene((d / "quad.dae").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->materials.size(), 1u);
  const scene::Material& m = s->materials[0];
  EXPECT_EQ(m.alpha_mode, scene::AlphaMode::kOpaque);
  EXPECT_FLOAT_EQ(m.base_color_factor[3], 1.0f);
  EXPECT_TRUE(warned(*s, "opacity 0"));
}

// A Quake 1 model (IDPO): one triangle and an 8 x 8 palette skin, rows 0-3 colour 15 (the
// palette's light grey), rows 4-7 colour 0 (black). assimp expands the skin into an uncompressed
// embedded texture, which became an empty slot (Half-Life's yodan.mdl baked flat grey).
TEST(AssimpImport, UncompressedEmbeddedSkinsBecomeImages) {
  fs::path d = fresh_dir("mdl_skin");
  std::string skin(64, char(0));
  std::fill(skin.begin(), skin.begin() + 32, char(15));
  std::string mdl = "IDPO" + le32({6}) + lef({1, 1, 1, 0, 0, 0, 2, 0, 0, 0}) +
                    le32({1, 8, 8, 3, 1, 1, 0, 0}) + lef({1}) + le32({0}) + skin;
  // Texture coordinates (onseam, s, t): the triangle lies in the skin's top rows.
  mdl += le32({0, 1, 1, 0, 6, 1, 0, 1, 2});
  mdl += le32({1, 0, 1, 2});  // faces front, vertices 0 1 2
  // One simple frame: bounds, name, three vertices (x y z, normal index).
  mdl += le32({0}) + std::string("\0\0\0\0\10\10\0\0", 8) + std::string(16, '\0');
  mdl += std::string("\0\0\0\0\10\0\0\0\0\10\0\0", 12);
  write_text(d / "tri.mdl", mdl);
  auto s = scene::load_scene((d / "tri.mdl").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  const scene::Primitive& prim = s->meshes.at(s->instances().at(0).mesh).primitives.at(0);
  ASSERT_GE(prim.material, 0);
  const scene::TextureRef& ref = s->materials.at(prim.material).base_color_texture;
  ASSERT_TRUE(ref.valid());
  const scene::Image& image = s->images.at(ref.image);
  EXPECT_TRUE(image.embedded());
  EXPECT_EQ(image.mime_type, "image/png");
  auto texels = scene::load_float_image(image);
  ASSERT_TRUE(texels.ok()) << texels.status().message();
  ASSERT_EQ(texels->width, 8u);
  ASSERT_EQ(texels->height, 8u);
  EXPECT_EQ(texels->channels, 3u);  // opaque: no alpha channel
  // Skin row 0 is the image's top row; every texel of a half is the one palette colour.
  for (uint32_t y = 0; y < 8; ++y)
    for (uint32_t x = 0; x < 8; ++x)
      for (int c = 0; c < 3; ++c) {
        const float v = texels->at(x, y)[c];
        if (y < 4)
          EXPECT_GT(v, 0.8f) << x << " " << y;
        else
          EXPECT_EQ(v, 0.0f) << x << " " << y;
        EXPECT_EQ(v, texels->at(0, y < 4 ? 0 : 7)[0]);
      }
  // The UVs read the top rows in glTF's orientation: t + 0.5 texels from the top.
  ASSERT_EQ(prim.uvs.size(), 1u);
  for (const auto& uv : prim.uvs[0]) {
    EXPECT_GT(uv[1], 0.0f);
    EXPECT_LT(uv[1], 0.5f);
  }
}

// Half-Life's masked textures (palette entry 255 cut out): assimp gives opaque texels, the
// texture flag UseAlpha and the entry's colour as the material's transparent colour, in 0-255.
// Those texels get alpha 0 (the material then bakes as MASK); without a key the PNG stays RGB.
TEST(AssimpImport, ColourKeyedEmbeddedTexelsGetAlpha) {
  aiTexture t;
  t.mWidth = 2;
  t.mHeight = 1;
  t.pcData = new aiTexel[2];
  t.pcData[0] = {255, 0, 0, 255};  // b g r a: the key, pure blue
  t.pcData[1] = {0, 0, 255, 255};  // red
  for (const aiColor3D& key : {aiColor3D(0, 0, 255), aiColor3D(0, 0, 1)}) {
    auto keyed = scene::detail::embedded_texels_png(t, "masked", &key);
    ASSERT_TRUE(keyed.ok()) << keyed.status().message();
    auto texels = scene::load_float_image(*keyed);
    ASSERT_TRUE(texels.ok()) << texels.status().message();
    ASSERT_EQ(texels->channels, 4u);
    EXPECT_EQ(texels->at(0, 0)[3], 0.0f);
    EXPECT_EQ(texels->at(0, 0)[2], 1.0f);  // the colour under the cut stays as stored
    EXPECT_EQ(texels->at(1, 0)[3], 1.0f);
    EXPECT_EQ(texels->at(1, 0)[0], 1.0f);
  }
  auto plain = scene::detail::embedded_texels_png(t, "plain");
  ASSERT_TRUE(plain.ok()) << plain.status().message();
  auto texels = scene::load_float_image(*plain);
  ASSERT_TRUE(texels.ok()) << texels.status().message();
  EXPECT_EQ(texels->channels, 3u);
}

// A Quake 2 model (IDP2) of one triangle on an 8 x 8 skin, naming `skin` (none when empty), its
// frame followed by the GL commands' end marker or, as UFO: Alien Invasion's models are, ending
// the file; `st`: the three vertices' texel coordinates (signed 16-bit s, t pairs).
constexpr int16_t kQuake2St[6] = {1, 1, 6, 1, 1, 6};
std::string quake2_triangle(const std::string& skin, bool gl_commands,
                            const int16_t (&st_texels)[6] = kQuake2St) {
  const int32_t frame_size = 40 + 3 * 4, skins = skin.empty() ? 0 : 1;
  std::string md2 = "IDP2" + le32({8, 8, 8, frame_size, skins, 3, 3, 1, gl_commands ? 1 : 0, 1});
  const int32_t st = 68 + 64 * skins, tris = st + 3 * 4, frames = tris + 12,
                gl = frames + frame_size;
  md2 += le32({68, st, tris, frames, gl_commands ? gl : 0, gl_commands ? gl + 4 : gl});
  if (skins) md2 += skin + std::string(64 - skin.size(), '\0');
  md2.append(reinterpret_cast<const char*>(st_texels), sizeof st_texels);  // little-endian
  md2 += std::string("\0\0\1\0\2\0\0\0\1\0\2\0", 12);      // vertex and UV indices (short)
  md2 += lef({1, 1, 1, 0, 0, 0}) + std::string(16, '\0');  // scale, translate, name
  md2 += std::string("\0\0\0\0\10\0\0\0\0\10\0\0", 12);    // three vertices (x y z, normal)
  if (gl_commands) md2 += le32({0});
  return md2;
}

// A Quake 2 model that names no skin: the game assigns one. assimp names a placeholder
// ('$texture_dummy.bmp') that the bake refused as a missing file. Now the surfaces bake from the
// material's colour with a warning, or from an image of the model's name beside it.
TEST(AssimpImport, Md2WithoutSkinTakesTheImageOfItsName) {
  fs::path d = fresh_dir("md2_skin");
  write_text(d / "guy.md2", quake2_triangle("", true));
  auto bare = scene::load_scene((d / "guy.md2").string());
  ASSERT_TRUE(bare.ok()) << bare.status().message();
  ASSERT_EQ(bare->materials.size(), 1u);
  EXPECT_FALSE(bare->materials[0].base_color_texture.valid());
  EXPECT_TRUE(warned(*bare, "names no skin (assimp's placeholder")) << bare->warnings.size();
  write_text(d / "Guy.BMP", "not read by the importer");
  auto skinned = scene::load_scene((d / "guy.md2").string());
  ASSERT_TRUE(skinned.ok()) << skinned.status().message();
  const scene::TextureRef& ref = skinned->materials.at(0).base_color_texture;
  ASSERT_TRUE(ref.valid());
  EXPECT_EQ(fs::path(skinned->images.at(ref.image).path).filename(), "Guy.BMP");
  EXPECT_TRUE(warned(*skinned, "'Guy.BMP' beside it, of the model's name, is used"));
}

// UFO: Alien Invasion's models: no GL commands, so the frames end the file (assimp 5.2 refused
// that as "offsets outside the file"), and skins named ".name": the image `name` beside the
// model, of any extension.
TEST(AssimpImport, Md2EndingAtItsFramesWithADottedSkinIsRead) {
  fs::path d = fresh_dir("md2_ufoai");
  write_text(d / "crate.md2", quake2_triangle(".crate_1", false));
  write_text(d / "crate_1.png", "not read by the importer");
  auto crate = scene::load_scene((d / "crate.md2").string());
  ASSERT_TRUE(crate.ok()) << crate.status().message();
  EXPECT_EQ(crate->triangle_count(), 1u);
  const scene::TextureRef& ref = crate->materials.at(0).base_color_texture;
  ASSERT_TRUE(ref.valid());
  EXPECT_EQ(fs::path(crate->images.at(ref.image).path).filename(), "crate_1.png");
  EXPECT_TRUE(warned(*crate, "(a leading dot: the name beside the model, any extension)"));
  // A frame cut short is still refused by assimp: only a file that holds every section is padded.
  std::string cut = quake2_triangle(".crate_1", false);
  cut.resize(cut.size() - 2);
  write_text(d / "cut.md2", cut);
  auto refused = scene::load_scene((d / "cut.md2").string());
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("Invalid MD2 file"), std::string::npos)
      << refused.status().message();
}

// Quake 2's texture coordinates are signed (a vertex left of the skin: the texture repeats);
// assimp reads them unsigned, -2 texels as 65534 / 8 = 8191.75 (UFO:AI's hull1.md2: triangles
// spanning the skin 256 times, an atlas 13x too large). Read back as -2 / 8.
TEST(AssimpImport, Md2TextureCoordinatesAreSigned) {
  fs::path d = fresh_dir("md2_signed");
  const int16_t st[6] = {-2, 1, 6, -3, 1, 6};
  write_text(d / "hull.md2", quake2_triangle("", true, st));
  auto hull = scene::load_scene((d / "hull.md2").string());
  ASSERT_TRUE(hull.ok()) << hull.status().message();
  const scene::Primitive& p = hull->meshes.at(0).primitives.at(0);
  ASSERT_EQ(p.uvs.at(0).size(), 3u);
  std::vector<std::array<float, 2>> uvs;
  for (const auto& uv : p.uvs[0]) uvs.push_back({uv[0], uv[1]});
  std::sort(uvs.begin(), uvs.end());
  // s / 8 and t / 8 in glTF's convention (v down from the top, as the skin's t).
  const std::vector<std::array<float, 2>> want = {
      {-0.25f, 0.125f}, {0.125f, 0.75f}, {0.75f, -0.375f}};
  EXPECT_EQ(uvs, want);
}

// A Doom 3 mesh (MD5) without its `MD5Version 10` line, as the Cube 2 engine reads them (Red
// Eclipse's zapper): assimp refused it; it is handed the line. With the line, as before.
TEST(AssimpImport, Md5MeshWithoutItsVersionLineIsRead) {
  fs::path d = fresh_dir("md5");
  const std::string body =
      "commandline \"\"\n\nnumJoints 1\nnumMeshes 1\n\n"
      "joints {\n\t\"origin\" -1 ( 0.0 0.0 0.0 ) ( -0.5 -0.5 -0.5 )\n}\n\n"
      "mesh {\n\tshader \"skin\"\n\n\tnumverts 3\n"
      "\tvert 0 ( 0.0 0.0 ) 0 1\n\tvert 1 ( 1.0 0.0 ) 1 1\n\tvert 2 ( 0.0 1.0 ) 2 1\n\n"
      "\tnumtris 1\n\ttri 0 0 1 2\n\n\tnumweights 3\n"
      "\tweight 0 0 1.0 ( 0.0 0.0 0.0 )\n\tweight 1 0 1.0 ( 1.0 0.0 0.0 )\n"
      "\tweight 2 0 1.0 ( 0.0 1.0 0.0 )\n}\n";
  for (const std::string& text : {body, "MD5Version 10\n" + body}) {
    write_text(d / "item.md5mesh", text);
    auto item = scene::load_scene((d / "item.md5mesh").string());
    ASSERT_TRUE(item.ok()) << item.status().message();
    EXPECT_EQ(item->triangle_count(), 1u);
  }
}

// `bytes` written to `file` are refused as corrupt before assimp reads them, in words that name
// the file and then say `says`.
void expect_corrupt(const fs::path& file, const std::string& bytes, const std::string& says) {
  write_text(file, bytes);
  auto bad = scene::load_scene(file.string());
  ASSERT_FALSE(bad.ok()) << says;
  EXPECT_EQ(bad.status().code(), ErrorCode::kCorrupt) << bad.status().message();
  EXPECT_NE(bad.status().message().find(file.string() + says), std::string::npos)
      << bad.status().message();
}

// assimp's MD5 reader takes a mesh's indices as given: a face the file does not list was read
// through a null pointer, an index past its count grew an array to it, a face's later corners,
// a vertex's weights and a weight's joint were followed unchecked. Each is refused first.
TEST(AssimpImport, Md5IndicesPastTheirCountsAreRefusedBeforeAssimpReadsThem) {
  fs::path d = fresh_dir("md5_bad");
  const std::string head =
      "MD5Version 10\ncommandline \"\"\n\nnumJoints 1\nnumMeshes 1\n\n"
      "joints {\n\t\"origin\" -1 ( 0.0 0.0 0.0 ) ( -0.5 -0.5 -0.5 )\n}\n\n"
      "mesh {\n\tshader \"skin\"\n\n\tnumverts 3\n";
  const std::string verts =
      "\tvert 0 ( 0.0 0.0 ) 0 1\n\tvert 1 ( 1.0 0.0 ) 1 1\n\tvert 2 ( 0.0 1.0 ) 2 1\n\n";
  const std::string weights =
      "\tnumweights 3\n\tweight 0 0 1.0 ( 0.0 0.0 0.0 )\n\tweight 1 0 1.0 ( 1.0 0.0 0.0 )\n"
      "\tweight 2 0 1.0 ( 0.0 1.0 0.0 )\n}\n";
  write_text(d / "ok.md5mesh", head + verts + "\tnumtris 1\n\ttri 0 0 1 2\n\n" + weights);
  auto ok = scene::load_scene((d / "ok.md5mesh").string());
  ASSERT_TRUE(ok.ok()) << ok.status().message();
  EXPECT_EQ(ok->triangle_count(), 1u);
  struct Broken {
    std::string text, says;
  };
  const Broken broken[] = {
      {head + verts + "\tnumtris 2\n\ttri 0 0 1 2\n\n" + weights,
       ": MD5 line 26: tri 1 of 2 is not given"},
      {head + verts + "\tnumtris 1\n\ttri 4000000000 0 1 2\n\n" + weights,
       ": MD5 line 20: tri 4000000000 past numtris 1"},
      {head + verts + "\tnumtris 1\n\ttri 0 0 1 7\n\n" + weights,
       ": MD5 line 20: tri 0 names a vertex past numverts 3"},
      {head + "\tvert 0 ( 0.0 0.0 ) 0 1\n\tvert 1 ( 1.0 0.0 ) 1 1\n\tvert 2 ( 0.0 1.0 ) 2 9\n\n" +
           "\tnumtris 1\n\ttri 0 0 1 2\n\n" + weights,
       ": MD5 line 17: a vertex names weights past numweights 3"},
      {head + verts + "\tnumtris 1\n\ttri 0 0 1 2\n\n" +
           "\tnumweights 3\n\tweight 0 0 1.0 ( 0.0 0.0 0.0 )\n\tweight 1 5 1.0 ( 1.0 0.0 0.0 )\n"
           "\tweight 2 0 1.0 ( 0.0 1.0 0.0 )\n}\n",
       ": MD5 line 24: weight 1 names a joint past the file's 1"},
      {"MD5Version 10\nmesh {\n\tnumverts 99999999999\n}\n",
       ": MD5 line 3: numverts 99999999999 is more than the file holds"},
  };
  for (const Broken& b : broken) expect_corrupt(d / "bad.md5mesh", b.text, b.says);
}

// assimp's IQM reader follows the file's offsets and counts unchecked: a crafted file had it read
// and allocate far past its buffer. Every section it reads is checked against the file first.
TEST(AssimpImport, IqmSectionsOutsideTheFileAreRefusedBeforeAssimpReadsThem) {
  fs::path d = fresh_dir("iqm");
  write_text(d / "ok.iqm", IqmFile().bytes);
  auto ok = scene::load_scene((d / "ok.iqm").string());
  ASSERT_TRUE(ok.ok()) << ok.status().message();
  EXPECT_EQ(ok->triangle_count(), 2u);
  struct Broken {
    uint32_t at, value;
    std::string says;
  };
  const Broken broken[] = {
      {16 + 4 * 6, 0x7fffffff, ": IQM meshes start past the end of the file"},
      {16 + 4 * 5, 0x10000000, ": IQM meshes: count 268435456 x 24 bytes needs"},
      {IqmFile::kMeshes + 24 + 16, 0x0fffffff, ": IQM mesh 1's triangles start past the end"},
      {IqmFile::kMeshes + 24 + 20, 1000, ": IQM mesh 1's triangles: count 1000 x 12 bytes"},
      {IqmFile::kMeshes + 12, 0xffffffff, ": IQM mesh 0's vertices in array 0: count 4294967295"},
      {IqmFile::kArrays + 20 + 16, 0xfffffff0, ": IQM mesh 0's vertices in array 1 start past"},
      {IqmFile::kArrays, 1, ": IQM vertex array 1 repeats an earlier array's attribute"},
      {IqmFile::kMeshes + 4, 18, ": IQM mesh 0's material name is not in the text"},
  };
  for (const Broken& b : broken) {
    IqmFile file;
    file.set(b.at, b.value);
    expect_corrupt(d / "bad.iqm", file.bytes, b.says);
  }
}

// An OFF file's counts are checked against its size before assimp allocates for them: assimp's
// own invalid/OutOfMemory.off (309 bytes, 353,535,235,358 vertices declared) took 16 GB and 90 s.
TEST(AssimpImport, OffCountsBeyondTheFileAreRefusedBeforeAssimpReadsThem) {
  fs::path d = fresh_dir("off");
  write_text(d / "tri.off", "OFF\n# a comment\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  auto tri = scene::load_scene((d / "tri.off").string());
  ASSERT_TRUE(tri.ok()) << tri.status().message();
  EXPECT_EQ(tri->triangle_count(), 1u);
  write_text(d / "huge.off", "OFF\n353535235358 6 0\n-0.5 -0.5 0.5\n0.5 -0.5 0.5\n");
  auto huge = scene::load_scene((d / "huge.off").string());
  ASSERT_FALSE(huge.ok());
  EXPECT_EQ(huge.status().code(), ErrorCode::kCorrupt);
  EXPECT_NE(huge.status().message().find("OFF vertices: count 353535235358"), std::string::npos)
      << huge.status().message();
  // Counts on the keyword's line, faces beyond the file.
  write_text(d / "faces.off", "OFF 3 99999 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  auto faces = scene::load_scene((d / "faces.off").string());
  ASSERT_FALSE(faces.ok());
  EXPECT_NE(faces.status().message().find("OFF faces"), std::string::npos)
      << faces.status().message();
}

// Lights and cameras are dropped before assimp's validation, as animations are: the bake ignores
// them, and assimp 5.2's OpenGEX reader makes a light twice, once without a node, which the
// validation refused (assimp's own OpenGEX/camera.ogex and collada.ogex).
TEST(AssimpImport, LightsAreDroppedBeforeAssimpValidatesTheScene) {
  fs::path d = fresh_dir("ogex");
  write_text(d / "lamp.ogex", R"(Metric (key = "distance") {float {1.0}}
GeometryNode $node1 {Name {string {"Tri"}} ObjectRef {ref {$geometry1}}}
LightNode $node2 {Name {string {"Lamp"}} ObjectRef {ref {$light1}}}
GeometryObject $geometry1
{
  Mesh (primitive = "triangles")
  {
    VertexArray (attrib = "position") {float[3] {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}}}
    IndexArray {unsigned_int32[3] {{0, 1, 2}}}
  }
}
LightObject $light1 (type = "point") {Color (attrib = "light") {float[3] {{1.0, 1.0, 1.0}}}}
)");
  auto s = scene::load_scene((d / "lamp.ogex").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->triangle_count(), 1u);
  EXPECT_TRUE(s->lights.empty());
  EXPECT_TRUE(warned(*s, "lights ignored"));
}

// A mesh without vertices or faces (an STL's empty solid beside a real one, as assimp's own
// STL/triangle_with_empty_solid.stl has) is skipped with a warning: assimp's validation refused
// the whole file. A file of empty meshes only has nothing to bake.
TEST(AssimpImport, EmptyMeshesAreSkipped) {
  fs::path d = fresh_dir("empty_mesh");
  const std::string triangle =
      "solid tri\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
      "endloop\nendfacet\nendsolid tri\n";
  write_text(d / "two.stl", triangle + "solid empty\nendsolid empty\n");
  auto s = scene::load_scene((d / "two.stl").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->triangle_count(), 1u);
  EXPECT_TRUE(warned(*s, "1 meshes without vertices or faces skipped"));
  write_text(d / "none.stl", "solid empty\nendsolid empty\n");
  auto none = scene::load_scene((d / "none.stl").string());
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.status().message().find("nothing to bake"), std::string::npos)
      << none.status().message();
}

// Text scenes in UTF-16 with a byte-order mark (Irrlicht writes its .irr scenes so; assimp's
// own test models have COLLADA and ASE files so): assimp's XML and ASE readers took the bytes as
// UTF-8 and refused them ("malformed XML"); they are handed to it as UTF-8.
TEST(AssimpImport, Utf16TextScenesAreRead) {
  fs::path d = fresh_dir("utf16");
  write_text(d / "wall.png", "not read by the importer");
  const std::string text = collada_quad("wall.png");
  for (const bool big_endian : {false, true}) {
    std::string utf16 = big_endian ? "\xfe\xff" : "\xff\xfe";
    for (const char c : text) utf16 += big_endian ? std::string{'\0', c} : std::string{c, '\0'};
    const fs::path path = d / (big_endian ? "quad_be.dae" : "quad_le.dae");
    write_text(path, utf16);
    auto s = scene::load_scene(path.string());
    ASSERT_TRUE(s.ok()) << s.status().message();
    EXPECT_EQ(s->triangle_count(), 2u);
    ASSERT_EQ(s->materials.size(), 1u);
    EXPECT_EQ(s->materials[0].name, "Painted");
    ASSERT_TRUE(s->materials[0].base_color_texture.valid());
    EXPECT_EQ(fs::path(s->images.at(s->materials[0].base_color_texture.image).path).filename(),
              "wall.png");
  }
}

TEST(AssimpImport, MeshWithoutUvsUnderATexturedMaterialBakesFromItsFactors) {
  // gl-117's 3DS trucks: a Maya cube without UVs under a textured material. It cannot sample
  // the texture: it gets a copy of the material without it (the bake used to refuse the model).
  fs::path d = fresh_dir("no_uvs");
  write_text(d / "wall.png", "not read by the importer");
  std::string dae = collada_quad("wall.png");
  const size_t texcoord = dae.find("      <input semantic=\"TEXCOORD\"");
  ASSERT_NE(texcoord, std::string::npos);
  dae.erase(texcoord, dae.find('\n', texcoord) + 1 - texcoord);
  write_text(d / "bare.dae", dae);
  auto s = scene::load_scene((d / "bare.dae").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  const scene::Primitive& prim = s->meshes[s->instances()[0].mesh].primitives[0];
  EXPECT_TRUE(prim.uvs.empty());
  ASSERT_GE(prim.material, 0);
  const scene::Material& m = s->materials[prim.material];
  EXPECT_EQ(m.name, "Painted");
  EXPECT_FALSE(m.base_color_texture.valid());
  EXPECT_TRUE(warned(*s, "has no UV set for the textures of material 'Painted'"));
  // With its UVs the same quad keeps the texture (the copy is made only where UVs are missing).
  write_text(d / "quad.dae", collada_quad("wall.png"));
  auto with_uvs = scene::load_scene((d / "quad.dae").string());
  ASSERT_TRUE(with_uvs.ok()) << with_uvs.status().message();
  EXPECT_EQ(with_uvs->materials.size(), 1u);
  EXPECT_TRUE(with_uvs->materials[0].base_color_texture.valid());
}

}  // namespace
}  // namespace vt::test
