// Cube 2 engine model configs (Sauerbraten, Red Eclipse): the skins `iqm.cfg` / `obj.cfg` / ...
// name for every mesh, or for a mesh by the engine's name for it, become the materials'
// textures; a config that loads another model, and lines naming meshes the model does not name,
// are not applied.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include "scene/scene.h"
#include "tests/scene/iqm_file.h"
#include "tests/scene/le_bytes.h"
#include "tests/scene/scene_warnings.h"

namespace vt::test {
namespace {

namespace fs = std::filesystem;

void write_text(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

// A textured triangle whose material names a texture by a name that is no file (as the Cube 2
// games' models do).
constexpr char kObj[] =
    "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl skin\n"
    "f 1/1 2/2 3/3\n";
constexpr char kMtl[] = "newmtl skin\nmap_Kd door\n";

fs::path model_folder(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("vt_cube2_" + name);
  fs::remove_all(d);
  write_text(d / "door.obj", kObj);
  write_text(d / "m.mtl", kMtl);
  write_text(d / "skin.png", "not read by the importer");
  write_text(d / "norm.png", "not read by the importer");
  return d;
}

std::string texture_file(const scene::Scene& s, const scene::TextureRef& t) {
  return t.valid() ? fs::path(s.images.at(t.image).path).filename().string() : "";
}

TEST(Cube2Config, SkinsForEveryMeshBecomeTheMaterialsTextures) {
  const fs::path d = model_folder("beside");
  write_text(d / "obj.cfg",
             "objload door.obj\n// a comment\nobjskin * \"<dds>skin.png\" mask.png 0.3\n"
             "objbumpmap * <dds>norm.png\nobjskin handle other.png\n");
  auto s = scene::load_scene((d / "door.obj").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->materials.size(), 1u);
  EXPECT_EQ(texture_file(*s, s->materials[0].base_color_texture), "skin.png");
  EXPECT_EQ(texture_file(*s, s->materials[0].normal_texture), "norm.png");
  EXPECT_TRUE(warned(*s,
                     "skin 'skin.png', normal map 'norm.png' for every mesh (1 line for meshes "
                     "the model does not name not applied)"));
}

TEST(Cube2Config, AConfigBelowThatLoadsTheModelApplies) {
  const fs::path d = model_folder("below");
  write_text(d / "item" / "obj.cfg", "objload ../door.obj\nobjskin * ../skin.png\n");
  auto s = scene::load_scene((d / "door.obj").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(texture_file(*s, s->materials.at(0).base_color_texture), "skin.png");
  EXPECT_FALSE(s->materials[0].normal_texture.valid());
}

TEST(Cube2Config, AConfigOfAnotherModelIsNotApplied) {
  const fs::path d = model_folder("other");
  write_text(d / "obj.cfg", "objload crate.obj\nobjskin * skin.png\n");
  write_text(d / "hud" / "obj.cfg", "objload ../crate.obj\nobjskin * ../skin.png\n");
  auto s = scene::load_scene((d / "door.obj").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(texture_file(*s, s->materials.at(0).base_color_texture), "door");
}

// A Doom 3 mesh (MD5) of three mesh blocks: the engine names them by their `// meshes:`
// comment; assimp makes a material for each block with vertices and triangles, in order (its
// parser wants the blank lines between sections).
std::string md5_block(const std::string& name, int tris) {
  std::string block = "mesh {\n";
  if (!name.empty()) block += "\t// meshes: " + name + "\n";
  block +=
      "\tshader \"\"\n\tnumverts 3\n\tvert 0 ( 0.0 0.0 ) 0 1\n\tvert 1 ( 1.0 0.0 ) 1 1\n"
      "\tvert 2 ( 0.0 1.0 ) 2 1\n\tnumtris " +
      std::to_string(tris) + "\n";
  if (tris > 0) block += "\ttri 0 0 1 2\n";
  return block +
         "\tnumweights 3\n\tweight 0 0 1.0 ( 0.0 0.0 0.0 )\n"
         "\tweight 1 0 1.0 ( 1.0 0.0 0.0 )\n\tweight 2 0 1.0 ( 0.0 1.0 0.0 )\n}\n\n";
}

TEST(Cube2Config, SkinsForNamedMeshesGoToTheirMeshes) {
  const fs::path d = model_folder("named");
  write_text(d / "gun.md5mesh",
             "MD5Version 10\ncommandline \"\"\nnumJoints 1\nnumMeshes 4\n\n"
             "joints {\n\t\"origin\" -1 ( 0.0 0.0 0.0 ) ( -0.5 -0.5 -0.5 )\n}\n\n" +
                 md5_block("top", 1) + md5_block("empty", 0) + md5_block("", 1) +
                 md5_block("bottom", 1));
  write_text(d / "item" / "md5.cfg",
             "md5load ../gun.md5mesh\nmd5skin * ../skin.png\nmd5skin bottom ../bottom.png\n"
             "md5bumpmap bottom ../norm.png\nmd5skin barrel ../barrel.png\n");
  auto s = scene::load_scene((d / "gun.md5mesh").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->materials.size(), 3u);  // the empty block has none
  EXPECT_EQ(texture_file(*s, s->materials[0].base_color_texture), "skin.png");
  EXPECT_FALSE(s->materials[0].normal_texture.valid());
  EXPECT_EQ(texture_file(*s, s->materials[1].base_color_texture), "skin.png");
  EXPECT_EQ(texture_file(*s, s->materials[2].base_color_texture), "bottom.png");
  EXPECT_EQ(texture_file(*s, s->materials[2].normal_texture), "norm.png");
  EXPECT_EQ(s->materials[0].base_color_texture.image, s->materials[1].base_color_texture.image);
  EXPECT_TRUE(warned(*s,
                     "skin '../skin.png' for every mesh; skin '../bottom.png', normal map "
                     "'../norm.png' for mesh 'bottom' (1 line for meshes the model does not name "
                     "not applied)"));
}

// An Inter-Quake Model names its meshes in its text table.
TEST(Cube2Config, SkinsForNamedIqmMeshesGoToTheirMeshes) {
  const fs::path d = model_folder("iqm");
  write_text(d / "turret.iqm", IqmFile().bytes);
  write_text(d / "iqm.cfg", "iqmskin cannon skin.png\niqmbumpmap stand norm.png\n");
  auto s = scene::load_scene((d / "turret.iqm").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->materials.size(), 2u);
  EXPECT_EQ(texture_file(*s, s->materials[0].normal_texture), "norm.png");
  EXPECT_EQ(texture_file(*s, s->materials[1].base_color_texture), "skin.png");
  EXPECT_FALSE(s->materials[1].normal_texture.valid());
}

// A Quake 3 model (MD3) names its surfaces in their headers; assimp names a surface's material
// `MD3_[SKIN][SURFACE]`.
std::string md3_of_surfaces(const std::vector<std::string>& surfaces) {
  auto name = [](const std::string& n) { return n + std::string(64 - n.size(), '\0'); };
  constexpr uint32_t kHeader = 108, kFrame = 56, kSurface = 236;
  const uint32_t n = uint32_t(surfaces.size()), size = kHeader + kFrame + n * kSurface;
  // version, name, flags, frames, tags, surfaces, skins; offsets of frames, tags, surfaces, end
  std::string out = "IDP3" + le32({15}) + name("model") + le32({0, 1, 0, n, 0}) +
                    le32({kHeader, kHeader + kFrame, kHeader + kFrame, size});
  out += std::string(kFrame, '\0');  // one frame: bounds, origin, radius, name
  for (const std::string& s : surfaces) {
    out += "IDP3" + name(s) + le32({0, 1, 1, 3, 1});  // flags, frames, shaders, vertices, tris
    out += le32({176, 108, 188, 212, kSurface});      // triangles, shaders, st, xyz, end
    out += name(s + ".tga") + le32({0});              // the shader
    out += le32({0, 1, 2});                           // the triangle
    out += lef({0, 0, 1, 0, 0, 1});                   // texture coordinates
    for (int16_t v : {0, 0, 0, 0, 64, 0, 0, 0, 0, 64, 0, 0})
      out += char(v & 0xff), out += char(v >> 8);
  }
  return out;
}

TEST(Cube2Config, SkinsForNamedMd3SurfacesGoToTheirSurfaces) {
  const fs::path d = model_folder("md3");
  write_text(d / "tris.md3", md3_of_surfaces({"bark", "leaves"}));
  write_text(d / "md3.cfg",
             "md3load tris.md3\nmd3skin leaves skin.png\nmd3bumpmap bark norm.png\n");
  auto s = scene::load_scene((d / "tris.md3").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->materials.size(), 2u);
  EXPECT_EQ(texture_file(*s, s->materials[0].normal_texture), "norm.png");
  EXPECT_EQ(texture_file(*s, s->materials[0].base_color_texture), "bark.tga");  // its own
  EXPECT_EQ(texture_file(*s, s->materials[1].base_color_texture), "skin.png");
  EXPECT_FALSE(s->materials[1].normal_texture.valid());
}

}  // namespace
}  // namespace vt::test
