// AC3D and TORCS's ACC read by the own reader: triangle strips, texture layers, concave
// polygons, object transforms, texrep/texoff, and what a damaged or miscounted file gives.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "scene/scene.h"
#include "tests/scene/bmp_tga_files.h"
#include "tests/scene/scene_warnings.h"

namespace vt::test {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  fs::path d = fs::path(::testing::TempDir()) / ("vt_ac3d_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

Expected<scene::Scene> load_text(const fs::path& dir, const std::string& name,
                                 const std::string& text,
                                 const scene::SceneLoadOptions& options = {}) {
  write_text(dir / name, text);
  return scene::load_scene((dir / name).string(), options);
}

const std::string kMaterials =
    "MATERIAL \"grey\" rgb 0.4 0.5 0.6  amb 0.8 0.8 0.8  emis 0 0 0  spec 0 0 0  shi 50  "
    "trans 0\n"
    "MATERIAL \"glow\" rgb 1 1 1  amb 0.8 0.8 0.8  emis 0.4 0.4 0.4  spec 0 0 0  shi 50  "
    "trans 0\n";

double triangle_area(const scene::Primitive& p, size_t t) {
  const auto& a = p.positions[p.indices[3 * t]];
  const auto& b = p.positions[p.indices[3 * t + 1]];
  const auto& c = p.positions[p.indices[3 * t + 2]];
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  // Signed by +Z, the polygons' normal here.
  return 0.5 * (u[0] * v[1] - u[1] * v[0]);
}

// An AC3D quad under one material: `name` (quoted as AC3D writes it), its `trans` field, and
// the object's lines before its vertices (name, texture).
std::string ac3d_quad(const std::string& name, const std::string& trans,
                      const std::string& object_lines) {
  return "AC3Db\nMATERIAL " + name +
         " rgb 1 1 1  amb 0.2 0.2 0.2  emis 0 0 0  spec 0.5 0.5 0.5  shi 10  " + trans +
         "\nOBJECT world\nkids 1\nOBJECT poly\n" + object_lines +
         "numvert 4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\nnumsurf 1\nSURF 0x10\nmat 0\nrefs 4\n"
         "0 0 0\n1 1 0\n2 1 1\n3 0 1\nkids 0\n";
}

TEST(Ac3dImport, AccTriangleStripsTakeTheBaseTextureAndItsUvs) {
  // A TORCS track piece: a strip of six vertices (four triangles, alternating winding), four
  // texture lines (base, tiled, and two placeholders) and refs with a UV pair for each layer.
  // assimp 5.2 read the strip as one polygon and the last texture line ("ERROR").
  fs::path d = fresh_dir("strip");
  std::vector<uint8_t> texels(4 * 4 * 4, 200);
  for (size_t i = 3; i < texels.size(); i += 4) texels[i] = 0;  // no alpha: the TGA is RGB
  ASSERT_TRUE(write_tga32((d / "road.tga").string(), 4, 4, texels, 0));
  ASSERT_TRUE(write_tga32((d / "shadow.tga").string(), 4, 4, texels, 0));
  std::string acc = "AC3Db\n" + kMaterials +
                    "OBJECT world\nkids 2\nOBJECT poly\nname \"road\"\n"
                    "texture \"road.tga\" base\ntexture \"shadow.tga\" tiled\n"
                    "texture empty_texture_no_mapping skids\n"
                    "texture empty_texture_no_mapping shad\n"
                    "numvert 6\n"
                    "0 0 0 0 0 1\n0 1 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n2 0 0 0 0 1\n"
                    "2 1 0 0 0 1\n"
                    "numsurf 1\nSURF 0x14\nmat 0\nrefs 7\n";
  for (int i = 0; i < 6; ++i) {
    // u = x / 2, v = y: the base pair; the tiled layer's pair after it is ignored.
    acc += std::to_string(i) + " " + std::to_string((i / 2) * 0.5) + " " + std::to_string(i % 2) +
           " 7 7\n";
  }
  acc += "5 1 1 7 7\nkids 0\n";  // a repeated vertex, as strips join runs: no triangle
  // A second object whose exporter printed a missing name: untextured, with a warning.
  acc +=
      "OBJECT poly\ntexture \"(null)\" base\nnumvert 3\n0 0 0\n1 0 0\n0 1 0\nnumsurf 1\n"
      "SURF 0\nmat 0\nrefs 3\n0 0 0\n1 1 0\n2 0 1\nkids 0\n";
  auto s = load_text(d, "track.acc", acc);
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->meshes.size(), 2u);
  ASSERT_EQ(s->meshes[0].primitives.size(), 1u);
  const scene::Primitive& p = s->meshes[0].primitives[0];
  ASSERT_EQ(p.triangle_count(), 4u);
  const scene::Primitive& unnamed = s->meshes[1].primitives[0];
  EXPECT_FALSE(s->materials[size_t(unnamed.material)].base_color_texture.valid());
  EXPECT_TRUE(warned(*s, "1 objects name their texture \"(null)\""));
  // Every strip triangle faces as the first does (-Z here): odd ones are taken in the other
  // order, as OpenGL draws a strip.
  for (size_t t = 0; t < 4; ++t) EXPECT_NEAR(triangle_area(p, t), -0.5, 1e-6) << t;
  ASSERT_EQ(p.uvs.size(), 1u);
  ASSERT_EQ(p.normals.size(), p.positions.size());
  for (size_t v = 0; v < p.positions.size(); ++v) {
    EXPECT_FLOAT_EQ(p.uvs[0][v][0], p.positions[v][0] * 0.5f);
    EXPECT_FLOAT_EQ(p.uvs[0][v][1], 1.0f - p.positions[v][1]);  // v up in AC3D, down here
    EXPECT_FLOAT_EQ(p.normals[v][2], 1.0f);
  }
  const scene::Material& m = s->materials[size_t(p.material)];
  EXPECT_EQ(m.name, "grey");
  EXPECT_FLOAT_EQ(m.base_color_factor[1], 0.5f);
  ASSERT_TRUE(m.base_color_texture.valid());
  EXPECT_EQ(fs::path(s->images[size_t(m.base_color_texture.image)].path).filename(), "road.tga");
  EXPECT_EQ(m.alpha_mode, scene::AlphaMode::kOpaque);
  EXPECT_FALSE(m.emissive_texture.valid());
  EXPECT_TRUE(warned(*s, "1 ACC texture layers after the base texture ignored"));
}

TEST(Ac3dImport, ConcavePolygonsKeepTheirOutline) {
  // An L of six corners (area 3), listed from (2, 1): a fan from there would cover the notch.
  fs::path d = fresh_dir("concave");
  auto s = load_text(d, "l.ac",
                     "AC3Db\n" + kMaterials +
                         "OBJECT world\nkids 1\nOBJECT poly\nname \"L\"\nnumvert 6\n"
                         "0 0 0\n2 0 0\n2 1 0\n1 1 0\n1 2 0\n0 2 0\n"
                         "numsurf 1\nSURF 0x20\nmat 0\nrefs 6\n"
                         "2 0 0\n3 0 0\n4 0 0\n5 0 0\n0 0 0\n1 0 0\nkids 0\n");
  ASSERT_TRUE(s.ok()) << s.status().message();
  const scene::Primitive& p = s->meshes[0].primitives[0];
  ASSERT_EQ(p.triangle_count(), 4u);
  double area = 0;
  for (size_t t = 0; t < 4; ++t) {
    const double a = triangle_area(p, t);
    EXPECT_GT(a, 0) << "triangle " << t << " turned over";
    area += a;
    // No triangle covers the notch (1..2, 1..2): its centroid would lie there.
    double cx = 0, cy = 0;
    for (int k = 0; k < 3; ++k) {
      cx += p.positions[p.indices[3 * t + k]][0] / 3;
      cy += p.positions[p.indices[3 * t + k]][1] / 3;
    }
    EXPECT_FALSE(cx > 1 && cy > 1) << "triangle " << t << " covers the notch";
  }
  EXPECT_NEAR(area, 3.0, 1e-6);
  EXPECT_TRUE(s->materials[size_t(p.material)].double_sided);  // SURF flag 0x20
}

TEST(Ac3dImport, ObjectTransformsTexrepAndMaterials) {
  // A group moved by loc and turned a quarter about Z by rot, holding a textured quad with
  // texrep 2 2 and texoff 0.5 0, under the emissive material: its texture is also the
  // emission's (fixed-function GL modulates emission by the texture). The texture has alpha:
  // AC3D's renderers blend it.
  fs::path d = fresh_dir("transform");
  std::vector<uint8_t> texels(2 * 2 * 4, 255);
  texels[3] = 64;
  ASSERT_TRUE(write_tga32((d / "leaf.tga").string(), 2, 2, texels, 8));
  auto s = load_text(d, "t.ac",
                     "AC3Db\n" + kMaterials +
                         "OBJECT world\nkids 1\nOBJECT group\nname \"arm\"\nloc 10 0 0\n"
                         "rot 0 -1 0 1 0 0 0 0 1\nkids 1\nOBJECT poly\nname \"leaf\"\n"
                         "texture \"leaf.tga\"\ntexrep 2 2\ntexoff 0.5 0\n"
                         "numvert 4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\nnumsurf 1\nSURF 0x10\nmat 1\n"
                         "refs 4\n0 0 0\n1 1 0\n2 1 1\n3 0 1\nkids 0\n");
  ASSERT_TRUE(s.ok()) << s.status().message();
  std::vector<scene::Instance> inst = s->instances();
  ASSERT_EQ(inst.size(), 1u);
  // (1, 0, 0) of the leaf: turned to (0, 1, 0), then moved to (10, 1, 0).
  const auto moved = scene::transform_point(inst[0].world, {1, 0, 0});
  EXPECT_NEAR(moved[0], 10, 1e-9);
  EXPECT_NEAR(moved[1], 1, 1e-9);
  const scene::Primitive& p = s->meshes[size_t(inst[0].mesh)].primitives[0];
  for (size_t v = 0; v < p.positions.size(); ++v) {
    EXPECT_FLOAT_EQ(p.uvs[0][v][0], p.positions[v][0] * 2 + 0.5f);
    EXPECT_FLOAT_EQ(p.uvs[0][v][1], 1.0f - p.positions[v][1] * 2);
  }
  const scene::Material& m = s->materials[size_t(p.material)];
  EXPECT_EQ(m.name, "glow");
  EXPECT_EQ(m.alpha_mode, scene::AlphaMode::kBlend);
  ASSERT_TRUE(m.emissive_texture.valid());
  EXPECT_EQ(m.emissive_texture.image, m.base_color_texture.image);
  EXPECT_FLOAT_EQ(m.emissive_factor[0], 0.4f);
  EXPECT_EQ(s->nodes[size_t(inst[0].node)].name, "leaf");
}

TEST(Ac3dImport, OvercountedKidsKeepWhatIsThereWithAWarning) {
  // TORCS's track maker writes `kids 3` where two objects follow and the file ends.
  fs::path d = fresh_dir("kids");
  const std::string quad =
      "OBJECT poly\nnumvert 3\n0 0 0\n1 0 0\n0 1 0\nnumsurf 1\nSURF 0\nmat 0\nrefs 3\n"
      "0 0 0\n1 1 0\n2 0 1\nkids 0\n";
  auto s = load_text(d, "k.ac", "AC3Db\n" + kMaterials + "OBJECT world\nkids 3\n" + quad + quad);
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->instances().size(), 2u);
  EXPECT_TRUE(warned(*s, "1 child objects short of what its 'kids' lines announce"));
}

TEST(Ac3dImport, FilesWithoutMaterialsAndHugePolygonsLoad) {
  // No MATERIAL line and no `mat` line: AC3D's white default. A polygon of 5,000 corners (a
  // circle) is fanned, not ear-clipped in n^3 steps, with a warning.
  fs::path d = fresh_dir("huge");
  const int n = 5000;
  std::string ac = "AC3Db\nOBJECT world\nkids 1\nOBJECT poly\nnumvert " + std::to_string(n) + "\n";
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    ac += std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
  }
  ac += "numsurf 1\nSURF 0\nrefs " + std::to_string(n) + "\n";
  for (int i = 0; i < n; ++i) ac += std::to_string(i) + " 0 0\n";
  auto s = load_text(d, "circle.ac", ac + "kids 0\n");
  ASSERT_TRUE(s.ok()) << s.status().message();
  const scene::Primitive& p = s->meshes[0].primitives[0];
  EXPECT_EQ(p.triangle_count(), size_t(n - 2));
  double area = 0;
  for (size_t t = 0; t < p.triangle_count(); ++t) area += triangle_area(p, t);
  EXPECT_NEAR(area, M_PI, 1e-3);
  EXPECT_FLOAT_EQ(s->materials[size_t(p.material)].base_color_factor[0], 1.0f);
  EXPECT_TRUE(warned(*s, "1 polygons of over 1024 corners fanned"));
}

TEST(Ac3dImport, ASecondVertexListKeepsEveryAttributeWhole) {
  // An object with two `numvert` lists, normals in the first only (a fuzzer's find): one
  // primitive, whose normals would have covered some vertices only. Every array stays whole.
  fs::path d = fresh_dir("two_lists");
  const std::string surface = "numsurf 1\nSURF 0\nmat 0\nrefs 3\n0 0 0\n1 1 0\n2 0 1\n";
  auto s = load_text(d, "two.acc",
                     "AC3Db\n" + kMaterials +
                         "OBJECT world\nkids 1\nOBJECT poly\nnumvert 3\n0 0 0 0 0 1\n"
                         "1 0 0 0 0 1\n0 1 0 0 0 1\n" +
                         surface + "numvert 3\n5 0 0\n6 0 0\n5 1 0\n" + surface + "kids 0\n");
  ASSERT_TRUE(s.ok()) << s.status().message();
  const scene::Primitive& p = s->meshes[0].primitives[0];
  EXPECT_EQ(p.triangle_count(), 2u);
  EXPECT_EQ(p.positions.size(), 6u);
  ASSERT_EQ(p.normals.size(), 6u);  // the file's for the first list, made for the second
  for (const scene::Vec3& n : p.normals) EXPECT_FLOAT_EQ(n[2], 1.0f);
  EXPECT_EQ(p.uvs[0].size(), 6u);
}

TEST(Ac3dImport, NormalsAreMadeWithinTheCreaseAngle) {
  // A quad folded 90 degrees along x = 1 (two shaded surfaces sharing vertices 1 and 2): with
  // crease 45 each face keeps its own normal; with crease 100 the shared corners take the
  // average; a flat surface (SURF 0x0) never does.
  fs::path d = fresh_dir("crease");
  auto folded = [&](const std::string& crease, const std::string& surf) {
    return "AC3Db\n" + kMaterials + "OBJECT world\nkids 1\nOBJECT poly\n" + crease +
           "numvert 4\n0 0 0\n1 0 0\n1 1 0\n1 0 -1\nnumsurf 2\nSURF " + surf +
           "\nmat 0\nrefs 3\n0 0 0\n1 1 0\n2 1 1\nSURF " + surf +
           "\nmat 0\nrefs 3\n1 0 0\n3 1 0\n2 1 1\nkids 0\n";
  };
  auto normal_at_shared_corner = [](const scene::Scene& s) {
    const scene::Primitive& p = s.meshes[0].primitives[0];
    std::vector<scene::Vec3> out;
    for (size_t v = 0; v < p.positions.size(); ++v)
      if (p.positions[v] == scene::Vec3{1, 1, 0}) out.push_back(p.normals[v]);
    return out;
  };
  auto sharp = load_text(d, "sharp.ac", folded("crease 45\n", "0x10"));
  ASSERT_TRUE(sharp.ok()) << sharp.status().message();
  EXPECT_EQ(normal_at_shared_corner(*sharp).size(), 2u);  // one a face: split
  auto smooth = load_text(d, "smooth.ac", folded("crease 100\n", "0x10"));
  ASSERT_TRUE(smooth.ok()) << smooth.status().message();
  const std::vector<scene::Vec3> shared = normal_at_shared_corner(*smooth);
  ASSERT_EQ(shared.size(), 1u);
  // Faces +Z (area 0.5) and +X (area 0.5): the average is (1, 0, 1) / sqrt 2.
  EXPECT_NEAR(shared[0][0], std::sqrt(0.5), 1e-6);
  EXPECT_NEAR(shared[0][1], 0.0, 1e-6);
  EXPECT_NEAR(shared[0][2], std::sqrt(0.5), 1e-6);
  auto flat = load_text(d, "flat.ac", folded("crease 100\n", "0x0"));
  ASSERT_TRUE(flat.ok()) << flat.status().message();
  EXPECT_EQ(normal_at_shared_corner(*flat).size(), 2u);
}

TEST(Ac3dImport, DamagedFilesAndFilesWithoutSurfacesAreClearErrors) {
  fs::path d = fresh_dir("damaged");
  const std::string head = "AC3Db\n" + kMaterials + "OBJECT world\nkids 1\nOBJECT poly\n";
  struct Case {
    std::string text, message;
    ErrorCode code;
  } cases[] = {
      {"OBJ\n", "not an AC3D file", ErrorCode::kCorrupt},
      // `data` on the last line, with no line break after it (a fuzzer's find: read past the end).
      {head + "data 10 4", "the file ends inside an OBJECT", ErrorCode::kCorrupt},
      {head + "numvert 3\n0 0 0\n1 0 0\n", "k.ac:9: the file ends after 2 of 3 vertices",
       ErrorCode::kCorrupt},
      {head + "numvert 3\n0 0 0\n1 0 0\n0 1 0\nnumsurf 1\nSURF 0\nmat 0\nrefs 3\n0 0 0\n1 0 0\n"
              "7 0 0\nkids 0\n",
       "k.ac:17: surface refers to vertex '7' of 3", ErrorCode::kCorrupt},
      // NaN as a vertex reference (a fuzzer's find: it passed the range check) and as a UV.
      {head + "numvert 3\n0 0 0\n1 0 0\n0 1 0\nnumsurf 1\nSURF 0\nmat 0\nrefs 3\nnan 0 0\n",
       "surface refers to vertex 'nan' of 3", ErrorCode::kCorrupt},
      {head + "numvert 3\n0 0 0\n1 0 0\n0 1 0\nnumsurf 1\nSURF 0\nmat 0\nrefs 3\n0 nan 0\n",
       "k.ac:15: bad texture coordinates 'nan'", ErrorCode::kCorrupt},
      {head + "loc 0 inf 0\n", "k.ac:7: bad 'loc' line", ErrorCode::kCorrupt},
      {head + "numvert 3\n0 0 0\n1 0 0\n0 1 0\nnumsurf 1\nSURF 0\nmat 9\n",
       "surface material '9' is not one of the file's 2 materials", ErrorCode::kCorrupt},
      {head + "numvert 2\n0 0 0\n1 0 0\nnumsurf 1\nSURF 0x2\nmat 0\nrefs 2\n0 0 0\n1 0 0\n"
              "kids 0\n",
       "no surfaces: nothing to bake (the file holds 1 lines only)", ErrorCode::kInvalidArgument},
  };
  for (const Case& c : cases) {
    auto s = load_text(d, "k.ac", c.text);
    ASSERT_FALSE(s.ok()) << c.message;
    EXPECT_EQ(s.status().code(), c.code) << s.status().message();
    EXPECT_NE(s.status().message().find(c.message), std::string::npos) << s.status().message();
  }
}

TEST(Ac3dImport, TexturePathFindsAGamesSharedTextures) {
  // A TORCS track names "tr-dirt.rgb", which the game keeps in data/textures, two folders up
  // and across: not found beside the scene, found in the folder --texture-path names (any
  // letter case), even outside the scene's folder tree.
  fs::path d = fresh_dir("texture_path");
  fs::create_directories(d / "data" / "textures");
  fs::create_directories(d / "tracks" / "dirt" / "dirt-1");
  std::vector<uint8_t> texels(4 * 4, 90);
  ASSERT_TRUE(write_tga32((d / "data" / "textures" / "TR-Dirt.tga").string(), 2, 2, texels, 0));
  const std::string ac = "AC3Db\n" + kMaterials +
                         "OBJECT world\nkids 1\nOBJECT poly\ntexture \"tr-dirt.tga\"\n"
                         "numvert 3\n0 0 0\n1 0 0\n0 1 0\nnumsurf 1\nSURF 0\nmat 0\nrefs 3\n"
                         "0 0 0\n1 1 0\n2 0 1\nkids 0\n";
  const fs::path track = d / "tracks" / "dirt" / "dirt-1";
  auto plain = load_text(track, "dirt-1.ac", ac);
  ASSERT_TRUE(plain.ok()) << plain.status().message();  // the bake reports the missing file
  EXPECT_FALSE(fs::exists(plain->images[0].path));
  scene::SceneLoadOptions options;
  options.texture_folders = {(d / "nothing").string(), (d / "data" / "textures").string()};
  auto s = load_text(track, "dirt-1.ac", ac, options);
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->images[0].path, (d / "data" / "textures" / "TR-Dirt.tga").string());
  EXPECT_TRUE(warned(*s, "read from '" + (d / "data" / "textures" / "TR-Dirt.tga").string() +
                             "' (--texture-path)"));
  // A path that climbs out of the named folder is looked up by its base name only.
  fs::create_directories(d / "outside");
  ASSERT_TRUE(write_tga32((d / "outside" / "secret.tga").string(), 2, 2, texels, 0));
  std::string climbing = ac;
  climbing.replace(climbing.find("tr-dirt.tga"), 11, "../../outside/secret.tga");
  auto c = load_text(track, "climb.ac", climbing, options);
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_FALSE(fs::exists(c->images[0].path)) << c->images[0].path;
}

TEST(Ac3dImport, TransOneIsFullyTransparent) {
  // AC3D's "trans 1" (FlightGear's light halos): the author's word, not an exporter's inversion
  // (COLLADA's opacity 0 is read as opaque: AssimpImport.ColladaOpacityZeroIsReadAsOpaque).
  fs::path d = fresh_dir("opacity");
  write_text(d / "halo.ac", ac3d_quad("\"halo\"", "trans 1", "name \"quad\"\n"));
  auto s = scene::load_scene((d / "halo.ac").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_GE(s->materials.size(), 1u);
  const scene::Material& m = s->materials[0];
  EXPECT_EQ(m.name, "halo");
  EXPECT_EQ(m.alpha_mode, scene::AlphaMode::kBlend);
  EXPECT_FLOAT_EQ(m.base_color_factor[3], 0.0f);
  bool warned = false;
  for (const std::string& w : s->warnings)
    warned |= w.find("bake fully transparent") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(Ac3dImport, ByteOrderMarksAndUtf16ReadAsText) {
  // As assimp's test models SphereWithLight_UTF8BOM.ac and SphereWithLight_UTF16LE.ac have it.
  fs::path d = fresh_dir("bom");
  const std::string text = ac3d_quad("\"m\"", "trans 0", "name \"caf\xc3\xa9\"\n");
  std::string utf16le = "\xff\xfe", utf16be = "\xfe\xff";
  for (size_t i = 0; i < text.size(); ++i) {
    // The one non-ASCII character, U+00E9, is two UTF-8 bytes and one UTF-16 unit.
    const char c = text[i] == '\xc3' ? '\xe9' : text[i];
    if (text[i] == '\xa9') continue;
    utf16le += std::string{c, '\0'};
    utf16be += std::string{'\0', c};
  }
  for (const auto& [name, bytes] :
       {std::pair<std::string, std::string>{"bom8.ac", "\xef\xbb\xbf" + text},
        {"le.ac", utf16le},
        {"be.ac", utf16be}}) {
    auto s = load_text(d, name, bytes);
    ASSERT_TRUE(s.ok()) << name << ": " << s.status().message();
    ASSERT_EQ(s->meshes.size(), 1u) << name;
    EXPECT_EQ(s->meshes[0].primitives[0].triangle_count(), 2u) << name;
    bool named = false;
    for (const scene::Node& n : s->nodes) named |= n.name == "caf\xc3\xa9";
    EXPECT_TRUE(named) << name;
  }
}

TEST(Ac3dImport, NamesInAnEightBitCodePageReadAsLatin1) {
  // Older formats do not say their encoding; a European author's 3ds Max writes "Par d\xe9faut"
  // in Windows-1252 (Sauerbraten's rocket.iqm). Names become UTF-8 (reports, JSON and the glTF
  // need it); a texture's file name stays as the disk spells it.
  fs::path d = fresh_dir("latin1");
  write_text(d / "d\xe9"
                 "cor.png",
             "not read by the importer");
  write_text(d / "m.ac", ac3d_quad("\"Par d\xe9"
                                   "faut\"",
                                   "trans 0",
                                   "name \"caf\xe9\"\ntexture \"d\xe9"
                                   "cor.png\"\n"));
  auto s = scene::load_scene((d / "m.ac").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  bool material_named = false, node_named = false;
  for (const scene::Material& m : s->materials) {
    material_named |= m.name ==
                      "Par d\xc3\xa9"
                      "faut";
    if (m.base_color_texture.valid()) {
      EXPECT_EQ(s->images[m.base_color_texture.image].path, (d / "d\xe9"
                                                                 "cor.png")
                                                                .string());
    }
  }
  for (const scene::Node& n : s->nodes) node_named |= n.name == "caf\xc3\xa9";
  EXPECT_TRUE(material_named);
  EXPECT_TRUE(node_named);
}

}  // namespace
}  // namespace vt::test
