// Hostile scenes: files a scene names outside its folder tree (images, glTF buffers, MTL
// libraries; absolute paths, "../../" escapes and symlinks) are refused unless
// SceneLoadOptions::allow_outside_paths; a FIFO as the scene is refused without blocking;
// non-finite UVs are an error naming the vertex; degenerate geometry is a warning with counts.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include "scene/scene.h"

namespace vt::test {
namespace {

namespace fs = std::filesystem;

// <tmp>/vt_hostile/ holding assets/car/ (the scene's folder), assets/shared/ (a sibling) and
// secret.png two levels above the scene: the tree a scene in assets/car/ may read is assets/.
struct Tree {
  std::string root, car, shared, secret;
  Tree() {
    // One tree per test: ctest runs the tests of this file in parallel processes.
    root = fs::weakly_canonical(::testing::TempDir()).string() + "/vt_hostile_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name() + "/";
    fs::remove_all(root);
    car = root + "assets/car/";
    shared = root + "assets/shared/";
    fs::create_directories(car);
    fs::create_directories(shared);
    secret = root + "secret.png";
    write(secret, "not an image");
    write(shared + "tex.png", "not an image");
    write(car + "tex.png", "not an image");
  }
  ~Tree() {
    std::error_code ec;
    fs::remove_all(root, ec);
  }
  static void write(const std::string& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
  }
};

// A glTF naming one image through material 'Body''s base colour texture.
std::string gltf_with_image(const std::string& uri) {
  return R"({"asset":{"version":"2.0"},"images":[{"name":"paint","uri":")" + uri +
         R"("}],"textures":[{"source":0}],"materials":[{"name":"Body","pbrMetallicRoughness":)"
         R"({"baseColorTexture":{"index":0}}}]})";
}

Expected<scene::Scene> load_gltf_naming(const Tree& t, const std::string& uri, bool allow = false) {
  Tree::write(t.car + "car.gltf", gltf_with_image(uri));
  scene::SceneLoadOptions options;
  options.allow_outside_paths = allow;
  return scene::load_scene(t.car + "car.gltf", options);
}

TEST(HostileScenes, ImagesInTheFolderBelowItAndInASiblingFolderLoad) {
  Tree t;
  for (const std::string uri : {"tex.png", "./tex.png", "../shared/tex.png", "../car/tex.png"}) {
    auto s = load_gltf_naming(t, uri);
    EXPECT_TRUE(s.ok()) << uri << ": " << s.status().message();
  }
  // Missing files are the missing-texture report's, not an escape.
  EXPECT_TRUE(load_gltf_naming(t, "../../../nowhere/none.png").ok());
}

TEST(HostileScenes, AnEscapeAboveTheTreeNamesTheSceneMaterialImageAndPath) {
  Tree t;
  auto s = load_gltf_naming(t, "../../secret.png");
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(s.status().message(),
            t.car + "car.gltf: material 'Body' baseColorTexture image 0 'paint': '" + t.car +
                "../../secret.png' is " + t.secret + ", outside the scene's folder tree " + t.root +
                "assets (a scene may name files in its folder, below it or in a " +
                "sibling folder; --allow-outside-paths reads it anyway)");
  EXPECT_TRUE(load_gltf_naming(t, "../../secret.png", true).ok());
}

TEST(HostileScenes, AbsolutePathsAndSymlinksOutsideAreRefused) {
  Tree t;
  // A glTF uri is always relative to the scene's folder ("/x" is "<folder>//x"); OBJ/MTL,
  // assimp and the resolver read absolute paths as they are.
  Tree::write(t.car + "abs.mtl", "newmtl paint\nmap_Kd " + t.secret + "\n");
  Tree::write(t.car + "abs.obj",
              "mtllib abs.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl paint\nf 1 2 3\n");
  auto abs = scene::load_scene(t.car + "abs.obj");
  ASSERT_FALSE(abs.ok());
  EXPECT_NE(abs.status().message().find("outside the scene's folder tree"), std::string::npos);
  // A percent-encoded escape is the same escape.
  EXPECT_FALSE(load_gltf_naming(t, "..%2F..%2Fsecret.png").ok());
  fs::create_symlink(t.secret, t.car + "link.png");
  auto link = load_gltf_naming(t, "link.png");
  ASSERT_FALSE(link.ok());
  EXPECT_NE(link.status().message().find("is " + t.secret + ", outside"), std::string::npos);
  EXPECT_TRUE(load_gltf_naming(t, "link.png", true).ok());
}

TEST(HostileScenes, GltfBufferOutsideIsRefusedBeforeItIsRead) {
  Tree t;
  Tree::write(t.root + "data.bin", std::string(12, '\0'));
  Tree::write(
      t.car + "car.gltf",
      R"({"asset":{"version":"2.0"},"buffers":[{"uri":"../../data.bin","byteLength":12}]})");
  auto s = scene::load_scene(t.car + "car.gltf");
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(s.status().message().find(t.car + "car.gltf: buffer 0: '"), std::string::npos);
  scene::SceneLoadOptions allow;
  allow.allow_outside_paths = true;
  EXPECT_TRUE(scene::load_scene(t.car + "car.gltf", allow).ok());
}

TEST(HostileScenes, ObjMapsAndMtlLibrariesOutsideAreRefused) {
  Tree t;
  Tree::write(t.car + "car.mtl", "newmtl paint\nmap_Kd ../../secret.png\n");
  Tree::write(t.car + "car.obj",
              "mtllib car.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl paint\nf 1 2 3\n");
  auto map = scene::load_scene(t.car + "car.obj");
  ASSERT_FALSE(map.ok());
  EXPECT_NE(map.status().message().find("material 'paint' baseColorTexture"), std::string::npos)
      << map.status().message();
  Tree::write(t.root + "evil.mtl", "newmtl paint\nKd 1 0 0\n");
  Tree::write(t.car + "car.obj", "mtllib ../../evil.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  auto lib = scene::load_scene(t.car + "car.obj");
  ASSERT_FALSE(lib.ok());
  EXPECT_NE(lib.status().message().find(t.car + "car.obj: line 1: mtllib: '"), std::string::npos)
      << lib.status().message();
}

TEST(HostileScenes, AFifoSceneIsRefusedWithoutBlocking) {
  Tree t;
  const std::string fifo = t.car + "pipe.gltf";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto s = scene::load_scene(fifo);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().message(), fifo + ": not a regular file to read");
}

// Found by vt_fuzz_gltf: a 26-byte binary glTF 1.0 whose header claims 2 GiB went to assimp,
// which allocated what the header said. Lengths that do not match the file keep it from assimp.
TEST(HostileScenes, BinaryGltf1WithLengthsPastTheFileIsRefused) {
  Tree t;
  const std::string glb = t.car + "v1.glb";
  const unsigned char bytes[26] = {'g', 'l', 'T',  'F', 1, 0, 0, 0, 0, 0x0e, 0, 0, 0,
                                   0,   0,   0x86, 0,   0, 0, 0, 0, 0, 0,    0, 0, 'a'};
  Tree::write(glb, std::string(reinterpret_cast<const char*>(bytes), sizeof bytes));
  auto s = scene::load_scene(glb);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().message().rfind(glb + ": ", 0), 0u) << s.status().message();
}

scene::Scene triangle_scene() {
  scene::Scene s;
  s.source_path = "tri.gltf";
  scene::Primitive p;
  p.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  p.uvs = {{{0, 0}, {1, 0}, {0, 1}}};
  p.indices = {0, 1, 2};
  s.meshes.push_back({"Body", {p}});
  return s;
}

TEST(HostileScenes, NonFiniteUvsAreAnErrorNamingMeshPrimitiveVertexAndSet) {
  scene::Scene s = triangle_scene();
  EXPECT_TRUE(scene::validate_geometry(s).ok());
  s.meshes[0].primitives[0].uvs[0][2][1] = std::numeric_limits<float>::quiet_NaN();
  Status st = scene::validate_geometry(s);
  EXPECT_EQ(st.code(), ErrorCode::kCorrupt);
  EXPECT_EQ(st.message(),
            "tri.gltf: mesh 'Body' primitive 0: vertex 2 has a non-finite TEXCOORD_0 (it would "
            "sample nothing: fix the UVs)");
  s.meshes[0].primitives[0].uvs[0][2][1] = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(scene::validate_geometry(s).ok());
}

TEST(HostileScenes, DegenerateGeometryIsAWarningWithCounts) {
  Tree t;
  // Primitive 0: one good triangle and two of zero area (a repeated index, collinear points);
  // primitive 1: only a zero-area triangle.
  Tree::write(t.car + "flat.obj",
              "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n"
              "f 1 2 3\nf 1 1 2\nf 1 2 4\n");
  auto s = scene::load_scene(t.car + "flat.obj");
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->warnings.size(), 1u);
  EXPECT_EQ(s->warnings[0], t.car + "flat.obj: 2 of 3 triangles have zero area and get no " +
                                "texels (first in mesh 'obj' primitive 0)");

  Tree::write(t.car + "line.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 3 2 1\n");
  auto line = scene::load_scene(t.car + "line.obj");
  ASSERT_TRUE(line.ok()) << line.status().message();
  ASSERT_EQ(line->warnings.size(), 2u);
  EXPECT_EQ(line->warnings[1], t.car + "line.obj: 1 primitive has no area at all and will not " +
                                   "appear in the bake: mesh 'obj' primitive 0");
}

}  // namespace
}  // namespace vt::test
