// Cube 2 engine model configs (Sauerbraten, Red Eclipse): the skins `iqm.cfg` / `obj.cfg` / ...
// name for every mesh become the materials' textures; a config that loads another model, and
// lines for named meshes, are not applied.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "scene/scene.h"
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
                     "skin 'skin.png', normal map 'norm.png' for every mesh (1 line for named "
                     "meshes not applied)"));
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

}  // namespace
}  // namespace vt::test
