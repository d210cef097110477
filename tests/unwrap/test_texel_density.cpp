// Texel density from the sources (bake/unwrap/texel_density.h): the estimate on quads with
// known texture and world sizes, the percentile, the bounds, per-material and per-object
// densities from a density file, and the coarseness warning. Images are written by the tests.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "bake/unwrap/texel_density.h"
#include "mesh_gen.h"

namespace vt::test {
namespace {

namespace fs = std::filesystem;

// A sx x sy quad (two triangles) at x offset `x0`, UV set 0 covering [0, uv]^2, material `m`.
Primitive quad(double sx, double sy, int m, float uv = 1.0f, float x0 = 0.0f) {
  Primitive p = flat_grid(1, 1, sx, sy);
  for (auto& v : p.positions) v[0] += x0;
  p.uvs.resize(1);
  for (const auto& v : p.positions)
    p.uvs[0].push_back({float((v[0] - x0) / sx) * uv, float(v[1] / sy) * uv});
  p.material = m;
  return p;
}

class TexelDensity : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("vt_density_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A grey PNG of w x h texels; returns its path.
  std::string png(int w, int h) {
    std::string path =
        (dir_ / ("t" + std::to_string(w) + "x" + std::to_string(h) + ".png")).string();
    auto out = OIIO::ImageOutput::create(path);
    OIIO::ImageSpec spec(w, h, 1, OIIO::TypeDesc::UINT8);
    std::vector<uint8_t> pixels(size_t(w) * h, 128);
    EXPECT_TRUE(out && out->open(path, spec) &&
                out->write_image(OIIO::TypeDesc::UINT8, pixels.data()) && out->close());
    return path;
  }

  // Adds a material named `name` whose base colour is a w x h image; returns its index.
  static int textured(Scene& s, const std::string& name, const std::string& image_path) {
    scene::Image im;
    im.path = image_path;
    s.images.push_back(im);
    scene::Material m;
    m.name = name;
    m.base_color_texture.image = int(s.images.size()) - 1;
    s.materials.push_back(m);
    return int(s.materials.size()) - 1;
  }

  // A 1 x 1 quad whose material `name` has a side x side base colour.
  Scene textured_quad(const std::string& name, int side) {
    Scene s = scene_of(quad(1, 1, 0));
    textured(s, name, png(side, side));
    return s;
  }

  // Two 1 x 1 quads under node "Wall", materials "plaster" and "sign", both 128 x 128 texels.
  Scene plaster_and_sign() {
    Scene s = scene_of(std::vector<Primitive>{quad(1, 1, 0), quad(1, 1, 1, 1.0f, 2.0f)});
    s.nodes[0].name = "Wall";
    const std::string image = png(128, 128);
    textured(s, "plaster", image);
    textured(s, "sign", image);
    return s;
  }

  void write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
  }

  fs::path dir_;
};

unwrap::UnwrapOptions options() {
  unwrap::UnwrapOptions o;
  o.threads = 2;
  o.density_file = "-";
  return o;
}

TEST(TexelDensityMath, TriangleDensityIsExact) {
  // 256 x 128 texels over a 2 x 1 world quad: sqrt(256 * 128 / 2) = 128 texels per unit.
  EXPECT_EQ(unwrap::triangle_source_density(256, 128, 0.5, 1.0), 128.0);
  EXPECT_EQ(unwrap::triangle_source_density(256, 128, 0.0, 1.0), 0.0);
  EXPECT_EQ(unwrap::triangle_source_density(256, 128, 0.5, 0.0), 0.0);
}

TEST(TexelDensityMath, PercentileIsAreaWeighted) {
  const std::vector<unwrap::DensitySample> s = {{10, 8}, {1, 1}, {2, 1}};
  EXPECT_EQ(unwrap::area_percentile(s, 0.1), 1.0);  // 1 of 10 units of area
  EXPECT_EQ(unwrap::area_percentile(s, 0.2), 2.0);
  EXPECT_EQ(unwrap::area_percentile(s, 0.5), 10.0);
  EXPECT_EQ(unwrap::area_percentile(s, 0.9), 10.0);
  EXPECT_EQ(unwrap::area_percentile({}, 0.9), 0.0);
  // A small, densely mapped decal does not size the scene: 5% of the area.
  EXPECT_EQ(unwrap::area_percentile({{100, 95}, {5000, 5}}, unwrap::kSourcePercentile), 100.0);
}

TEST_F(TexelDensity, QuadWithKnownTextureAndWorldSize) {
  Scene s = scene_of(quad(2, 1, 0));
  textured(s, "wall", png(256, 128));
  auto d = unwrap::measure_source_density(s, false);
  ASSERT_EQ(d.material.size(), 1u);
  EXPECT_DOUBLE_EQ(d.material[0], 128.0);
  EXPECT_DOUBLE_EQ(d.material_area[0], 2.0);
  EXPECT_DOUBLE_EQ(d.scene, 128.0);
  EXPECT_TRUE(d.unreadable.empty());
}

TEST_F(TexelDensity, RepeatTransformAndInstanceScaleCount) {
  // UVs repeating 4 times: 4x the density; a node scaled by 2: half of it.
  Scene s = scene_of(quad(1, 1, 0, 4.0f));
  textured(s, "tiles", png(64, 64));
  EXPECT_DOUBLE_EQ(unwrap::measure_source_density(s, false).scene, 256.0);
  s.materials[0].base_color_texture.transform.scale = {0.5f, 0.5f};  // KHR_texture_transform
  EXPECT_DOUBLE_EQ(unwrap::measure_source_density(s, false).scene, 128.0);
  s.nodes[0].local = {2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1};
  EXPECT_DOUBLE_EQ(unwrap::measure_source_density(s, false).scene, 64.0);
}

TEST_F(TexelDensity, EmbeddedImagesAndMissingOnes) {
  std::string path = png(32, 16);
  std::ifstream f(path, std::ios::binary);
  scene::Image im;
  im.bytes.assign(std::istreambuf_iterator<char>(f), {});
  im.mime_type = "image/png";
  auto size = unwrap::image_size(im);
  ASSERT_TRUE(size.ok()) << size.status().message();
  EXPECT_EQ(*size, (std::array<int, 2>{32, 16}));
  // A missing image gives no density (transfer reports it by its own policy), and a warning.
  Scene s = scene_of(quad(1, 1, 0));
  textured(s, "lost", (dir_ / "nope.png").string());
  auto d = unwrap::measure_source_density(s, false);
  EXPECT_EQ(d.scene, 0.0);
  ASSERT_EQ(d.unreadable.size(), 1u);
  EXPECT_NE(d.unreadable[0].find("nope.png"), std::string::npos) << d.unreadable[0];
}

TEST_F(TexelDensity, DefaultIsTwiceTheSourcesDensity) {
  Scene s = textured_quad("wall", 128);
  auto o = options();
  o.min_size_pages = 1;
  auto r = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  expect_valid(s, *r);
  EXPECT_EQ(r->stats.density_rule, "sources");
  EXPECT_EQ(r->stats.texels_per_unit, 256.0);  // unwrap::kSourceOversample x 128
  EXPECT_EQ(r->stats.source_texels_per_unit, 128.0);
  ASSERT_EQ(r->stats.materials.size(), 1u);
  EXPECT_EQ(r->stats.materials[0].name, "wall");
  EXPECT_DOUBLE_EQ(r->stats.materials[0].achieved, 256.0);
  EXPECT_TRUE(r->stats.warnings.empty());
  EXPECT_EQ(r->stats.pages_x, 3);  // 256 texels + margins and gutter: 3 pages of 120
}

TEST_F(TexelDensity, CapAndFloor) {
  Scene dense = textured_quad("dense", 2048);  // would be 18 pages wide
  auto o = options();
  o.max_size_pages = 8;
  auto r = unwrap::unwrap_scene(dense, o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->stats.density_rule, "sources, capped");
  EXPECT_EQ(r->stats.pages_x, 8);
  EXPECT_EQ(r->stats.pages_y, 8);
  EXPECT_LT(r->stats.texels_per_unit, 960.0);
  EXPECT_GT(r->stats.texels_per_unit, 900.0);  // the square fills nearly the whole atlas
  ASSERT_EQ(r->stats.warnings.size(), 1u);     // 2048 vs < 960: more than 2x coarser
  EXPECT_NE(r->stats.warnings[0].find("'dense'"), std::string::npos) << r->stats.warnings[0];

  Scene coarse = textured_quad("coarse", 16);
  auto f = unwrap::unwrap_scene(coarse, options());
  ASSERT_TRUE(f.ok()) << f.status().message();
  EXPECT_EQ(f->stats.density_rule, "sources, floored");
  EXPECT_EQ(f->stats.pages_x, 4);  // UnwrapOptions::min_size_pages
  EXPECT_GT(f->stats.texels_per_unit, 16.0);
  EXPECT_TRUE(f->stats.warnings.empty());
}

TEST_F(TexelDensity, UntexturedScenesFitTheDefaultSize) {
  Scene s = scene_of(quad(1, 1, -1));
  auto r = unwrap::unwrap_scene(s, options());
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->stats.density_rule, "default size");
  EXPECT_EQ(r->stats.pages_x, unwrap::kDefaultSizePages);
  EXPECT_EQ(r->stats.source_texels_per_unit, 0.0);
}

// Atlas texel area of the triangles of output primitive `prim` (one mesh, one instance).
double atlas_area(const unwrap::UnwrapResult& r, size_t first, size_t count) {
  double a = 0;
  for (size_t i = first; i < first + count; ++i) {
    const auto& t = r.triangles[i].uv;
    a += std::abs((t[2] - t[0]) * (t[5] - t[1]) - (t[3] - t[1]) * (t[4] - t[0])) / 2;
  }
  return a;
}

TEST_F(TexelDensity, MaterialAndObjectDensitiesScaleTheirCharts) {
  Scene s = plaster_and_sign();
  write("d.json", R"({"texels_per_unit": 32, "materials": {"sign": 128}})");
  auto o = options();
  o.density_file = (dir_ / "d.json").string();
  auto r = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  expect_valid(s, *r);
  EXPECT_EQ(r->stats.density_rule, "texels_per_unit");
  EXPECT_EQ(r->stats.density_file, o.density_file);
  EXPECT_EQ(r->stats.texels_per_unit, 32.0);
  ASSERT_EQ(r->stats.materials.size(), 2u);
  EXPECT_DOUBLE_EQ(r->stats.materials[0].achieved, 32.0);
  EXPECT_DOUBLE_EQ(r->stats.materials[1].achieved, 128.0);
  EXPECT_EQ(r->stats.materials[1].requested, 128.0);
  // The sign's quad takes (128 / 32)^2 = 16 times the plaster's texels.
  EXPECT_NEAR(atlas_area(*r, 2, 2) / atlas_area(*r, 0, 2), 16.0, 1e-3);
  // The plaster is baked 4x coarser than its 128 texels per unit: named in the warning.
  ASSERT_EQ(r->stats.warnings.size(), 1u);
  EXPECT_NE(r->stats.warnings[0].find("4x coarser"), std::string::npos) << r->stats.warnings[0];
  EXPECT_NE(r->stats.warnings[0].find("'plaster' 32 vs 128"), std::string::npos);

  // An object's density wins over its material's and covers the node's whole mesh.
  write("o.json", R"({"objects": {"Wall": 64}, "materials": {"sign": 128}})");
  o.density_file = (dir_ / "o.json").string();
  o.texels_per_unit = 32;  // the command line's density wins over the file's (none here)
  auto q = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(q.ok()) << q.status().message();
  EXPECT_DOUBLE_EQ(q->stats.materials[0].achieved, 64.0);
  EXPECT_DOUBLE_EQ(q->stats.materials[1].achieved, 64.0);

  // With a fitted size every density scales alike, relative to the sources' 128: the ratio
  // stays.
  write("f.json", R"({"texels_per_unit": 32, "materials": {"sign": 512}})");
  o.texels_per_unit = 0;
  o.size_pages = 4;  // the command line's size wins over the file's density
  o.density_file = (dir_ / "f.json").string();
  auto f = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(f.ok()) << f.status().message();
  EXPECT_EQ(f->stats.density_rule, "size");
  EXPECT_EQ(f->stats.pages_x, 4);
  EXPECT_NEAR(f->stats.materials[1].achieved / f->stats.materials[0].achieved, 4.0, 1e-9);
}

TEST(TexelDensityMath, ObjectScalesAreCappedAndBudgeted) {
  unwrap::SourceDensity d;
  d.scene = 32;
  d.node = {32, 128, 1000, 0, 64};
  d.node_area = {16, 1, 0.1, 5, 1};
  // Only objects more than kSourceOversample times denser get a scale: their density over the
  // scene's, at most kMaxObjectScale. At 2x (64) the scene's density still gives one baked
  // texel per source texel.
  auto k = unwrap::object_scales(d, {0, 0, 0, 0, 0});
  EXPECT_EQ(k, (std::vector<double>{0, 4, unwrap::kMaxObjectScale, 0, 0}));
  EXPECT_EQ(unwrap::object_scales(d, {0, 1, 0, 0, 0})[1], 0.0);  // its own density was given
  // A dense object of a quarter of the scene's area would add 4 * (4^2 - 1) = 60 units of area
  // at the scene's density, over the budget of the scene's own 20 (kObjectScaleBudget 1): its
  // scale drops to the one that adds 20, sqrt(1 + 20 / 4).
  d.node = {32, 128};
  d.node_area = {16, 4};
  k = unwrap::object_scales(d, {});
  EXPECT_EQ(k[0], 0.0);
  EXPECT_NEAR(k[1], std::sqrt(1 + 20.0 / 4), 1e-6);
}

TEST_F(TexelDensity, AnObjectDenserThanTheSceneGetsItsOwnDensity) {
  // A 4 x 4 "Earth" and a 1 x 1 "Moon" sharing one 128^2 texture: 32 and 128 texels per unit.
  Scene s = scene_of(quad(4, 4, 0));
  s.nodes[0].name = "Earth";
  scene::Mesh moon;
  moon.primitives.push_back(quad(1, 1, 0, 1.0f, 6.0f));
  s.meshes.push_back(moon);
  scene::Node n;
  n.name = "Moon";
  n.mesh = 1;
  s.nodes.push_back(n);
  s.roots.push_back(1);
  textured(s, "globe", png(128, 128));
  auto r = unwrap::unwrap_scene(s, options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  expect_valid(s, *r);
  EXPECT_EQ(r->stats.density_rule, "sources");
  EXPECT_EQ(r->stats.texels_per_unit, 64.0);  // twice the scene's 32
  ASSERT_EQ(r->stats.objects.size(), 1u);
  EXPECT_EQ(r->stats.objects[0].name, "Moon");
  EXPECT_EQ(r->stats.objects[0].source, 128.0);
  EXPECT_EQ(r->stats.objects[0].scale, 4.0);
  // The Moon's two triangles (the second mesh's, last) take 4^2 times the Earth's texels per
  // unit of area: 256 texels per unit, twice its sources' density like the Earth.
  EXPECT_NEAR(atlas_area(*r, 2, 2) / 1.0 / (atlas_area(*r, 0, 2) / 16.0), 16.0, 1e-3);
  EXPECT_TRUE(r->stats.warnings.empty());

  // A density given for the object, or for the whole scene, is not second-guessed.
  write("m.json", R"({"objects": {"Moon": {"scale": 1}}})");
  auto o = options();
  o.density_file = (dir_ / "m.json").string();
  auto m = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_TRUE(m->stats.objects.empty());
  EXPECT_NEAR(atlas_area(*m, 2, 2) / (atlas_area(*m, 0, 2) / 16.0), 1.0, 1e-3);
  o.density_file = "-";
  o.texels_per_unit = 64;
  auto t = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(t.ok()) << t.status().message();
  EXPECT_TRUE(t->stats.objects.empty());
  EXPECT_NEAR(atlas_area(*t, 2, 2) / (atlas_area(*t, 0, 2) / 16.0), 1.0, 1e-3);
}

TEST_F(TexelDensity, ScalesAndNodesAndGltfExtrasSetOwnDensities) {
  Scene s = plaster_and_sign();
  auto o = options();
  o.texels_per_unit = 32;
  // A scale multiplies the scene's density; {"texels_per_unit": D} is the same as D.
  write("s.json", R"({"materials": {"plaster": {"scale": 0.5}, "sign": {"texels_per_unit": 96}}})");
  o.density_file = (dir_ / "s.json").string();
  auto r = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  expect_valid(s, *r);
  ASSERT_EQ(r->stats.materials.size(), 2u);
  EXPECT_DOUBLE_EQ(r->stats.materials[0].achieved, 16.0);
  EXPECT_EQ(r->stats.materials[0].requested_scale, 0.5);
  EXPECT_DOUBLE_EQ(r->stats.materials[1].achieved, 96.0);
  EXPECT_EQ(r->stats.materials[1].requested, 96.0);
  // "nodes" is "objects" by another name.
  write("n.json", R"({"nodes": {"Wall": {"scale": 2}}})");
  o.density_file = (dir_ / "n.json").string();
  auto n = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(n.ok()) << n.status().message();
  EXPECT_DOUBLE_EQ(n->stats.materials[0].achieved, 64.0);
  EXPECT_DOUBLE_EQ(n->stats.materials[1].achieved, 64.0);

  // glTF extras (read by the importer into the scene model) act like the file, which wins.
  s.materials[1].texels_per_unit = 128;
  o.density_file = "-";
  auto e = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(e.ok()) << e.status().message();
  EXPECT_DOUBLE_EQ(e->stats.materials[0].achieved, 32.0);
  EXPECT_DOUBLE_EQ(e->stats.materials[1].achieved, 128.0);
  EXPECT_EQ(e->stats.materials[1].requested, 128.0);
  o.density_file = (dir_ / "s.json").string();
  EXPECT_DOUBLE_EQ(unwrap::unwrap_scene(s, o)->stats.materials[1].achieved, 96.0);
  s.materials[1].texels_per_unit = 0;
  s.nodes[0].texels_per_unit = 48;  // a node's extras cover its mesh
  o.density_file = "-";
  auto ne = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(ne.ok());
  EXPECT_DOUBLE_EQ(ne->stats.materials[0].achieved, 48.0);
  EXPECT_DOUBLE_EQ(ne->stats.materials[1].achieved, 48.0);
}

TEST_F(TexelDensity, GltfExtrasAreReadFromMaterialsAndNodes) {
  write("x.gltf", R"({"asset": {"version": "2.0"},
    "materials": [{"name": "a", "extras": {"vtbake_texels_per_unit": 250}},
                  {"name": "b", "extras": "someone else's"}, {"name": "c"}],
    "nodes": [{"name": "n", "extras": {"vtbake_texels_per_unit": 12.5}}, {"name": "m"}],
    "scenes": [{"nodes": [0, 1]}], "scene": 0})");
  auto s = scene::load_scene((dir_ / "x.gltf").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->materials[0].texels_per_unit, 250.0);
  EXPECT_EQ(s->materials[1].texels_per_unit, 0.0);
  EXPECT_EQ(s->materials[2].texels_per_unit, 0.0);
  EXPECT_EQ(s->nodes[0].texels_per_unit, 12.5);
  EXPECT_EQ(s->nodes[1].texels_per_unit, 0.0);
  write("bad.gltf", R"({"asset": {"version": "2.0"},
    "materials": [{"name": "a", "extras": {"vtbake_texels_per_unit": -3}}]})");
  auto bad = scene::load_scene((dir_ / "bad.gltf").string());
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find(
                "materials[0] 'a'.extras.vtbake_texels_per_unit: expected a positive number"),
            std::string::npos)
      << bad.status().message();
}

TEST_F(TexelDensity, ExplicitDensityCoarserThanSourcesWarns) {
  Scene s = textured_quad("wall", 256);
  auto o = options();
  o.texels_per_unit = 32;
  auto r = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r->stats.warnings.size(), 1u);
  EXPECT_NE(r->stats.warnings[0].find("8x coarser"), std::string::npos) << r->stats.warnings[0];
  EXPECT_NE(r->stats.warnings[0].find("'wall' 32 vs 256"), std::string::npos);
  o.texels_per_unit = 200;  // 1.28x coarser: no warning
  auto q = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(q.ok());
  EXPECT_TRUE(q->stats.warnings.empty());
}

TEST_F(TexelDensity, DensityFileBesideTheSceneIsFound) {
  Scene s = textured_quad("wall", 64);
  s.source_path = (dir_ / "level.gltf").string();
  EXPECT_EQ(unwrap::default_density_file(s.source_path), (dir_ / "level.density.json").string());
  write("level.density.json", R"({"size_pages": 2})");
  auto o = options();
  o.density_file = "";
  auto r = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->stats.density_rule, "size");
  EXPECT_EQ(r->stats.pages_x, 2);
  EXPECT_EQ(r->stats.density_file, (dir_ / "level.density.json").string());
  o.size_pages = 3;  // the command line wins
  EXPECT_EQ(unwrap::unwrap_scene(s, o)->stats.pages_x, 3);
  o.size_pages = 0;
  o.density_file = "-";  // none
  EXPECT_EQ(unwrap::unwrap_scene(s, o)->stats.density_rule, "sources, floored");
}

TEST_F(TexelDensity, BadDensityFilesNameTheFileAndTheProblem) {
  Scene s = textured_quad("wall", 8);
  s.nodes[0].name = "House";
  const std::pair<const char*, const char*> cases[] = {
      {R"({"materials": {"Wal": 10}})", "no material named 'Wal' (it has 'wall')"},
      {R"({"objects": {"Hose": 10}})", "no object named 'Hose' (it has 'House')"},
      {R"({"materials": {"wall": -1}})", "material 'wall' must be a positive number, not -1"},
      {R"({"texels_per_unit": 4, "size_pages": 2})", "not both"},
      {R"({"size_pages": 0.5})", "\"size_pages\" must be a whole number"},
      {R"({"density": 4})", "unknown key \"density\""},
      {R"({"materials": {"wall": {"scale": 0}}})", "material 'wall' scale must be a positive"},
      {R"({"materials": {"wall": {"size": 2}}})", "{\"scale\": K}, not {\"size\":2}"},
      {R"({"objects": {"House": 2}, "nodes": {"House": 2}})", "not both"},
      {R"({"nodes": {"Hose": 10}})", "no object named 'Hose'"},
      {R"([1, 2])", "a density file is a JSON object"},
      {R"({"materials": )", "malformed density JSON"},
  };
  for (const auto& [text, message] : cases) {
    write("bad.json", text);
    const std::string path = (dir_ / "bad.json").string();
    auto f = unwrap::load_density_file(path, s);
    ASSERT_FALSE(f.ok()) << text;
    EXPECT_NE(f.status().message().find(path + ": "), std::string::npos) << f.status().message();
    EXPECT_NE(f.status().message().find(message), std::string::npos) << f.status().message();
    auto o = options();
    o.density_file = path;
    EXPECT_FALSE(unwrap::unwrap_scene(s, o).ok());  // and the unwrap stops before any work
  }
  EXPECT_EQ(unwrap::load_density_file((dir_ / "none.json").string(), s).status().code(),
            ErrorCode::kNotFound);
}

}  // namespace
}  // namespace vt::test
