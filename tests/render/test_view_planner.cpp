// The view planner and the density figure: the up axis from the data, views that face the
// surfaces they frame, determinism, the density of a view exactly, and a bake at a quarter of
// its sources' density failing the density bound where the default bake passes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "bake/scene_bake.h"
#include "format/page_file.h"
#include "render/report.h"
#include "render/validate.h"
#include "render/view_density.h"
#include "render/view_planner.h"
#include "render/view_surfaces.h"
#include "render/vulkan_context.h"
#include "scene/gltf_export.h"

namespace vt::render {
namespace {

constexpr uint32_t kW = 160, kH = 90;

std::string temp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("vt_view_planner_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

// A quad p0 p1 p2 p3 (counter-clockwise seen from its front) as a mesh of its own: source UVs
// 0..1 over it, atlas UVs (the last set, as the unwrapper writes them) over `atlas`
// {u0, v0, u1, v1}.
void add_quad(scene::Scene& s, std::array<scene::Vec3, 4> p, std::array<float, 4> atlas,
              int material = -1) {
  scene::Primitive prim;
  prim.positions = {p[0], p[1], p[2], p[3]};
  prim.uvs = {
      {{0, 1}, {1, 1}, {1, 0}, {0, 0}},
      {{atlas[0], atlas[3]}, {atlas[2], atlas[3]}, {atlas[2], atlas[1]}, {atlas[0], atlas[1]}}};
  prim.indices = {0, 1, 2, 0, 2, 3};
  prim.material = material;
  scene::Mesh mesh;
  mesh.name = "quad" + std::to_string(s.meshes.size());
  mesh.primitives.push_back(std::move(prim));
  scene::Node node;
  node.name = mesh.name;
  node.mesh = int(s.meshes.size());
  s.meshes.push_back(std::move(mesh));
  s.roots.push_back(int(s.nodes.size()));
  s.nodes.push_back(node);
}

// A 4 x 2 board lying in the XY plane of a Z-up world, facing +Z, offset from the origin.
scene::Scene z_up_board() {
  scene::Scene s;
  s.source_path = "board.glb";
  add_quad(s, {{{1, 3, 0.5f}, {5, 3, 0.5f}, {5, 5, 0.5f}, {1, 5, 0.5f}}}, {0, 0, 0.5f, 0.25f});
  return s;
}

double degrees_between(Vec3f a, Vec3f b) {
  const double c = dot(a, b) / (length(a) * length(b));
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / 3.14159265358979;
}

ViewSurfaces surfaces_of(const scene::Scene& s, uint32_t side = 512) {
  auto r = gather_view_surfaces(s, side, side);
  EXPECT_TRUE(r.ok()) << r.status().message();
  return r.ok() ? *r : ViewSurfaces{};
}

ViewPlan plan_of(const ViewSurfaces& s, UpAxis up = UpAxis::kAuto, uint32_t views = 6) {
  ViewPlanOptions o;
  o.views = views, o.up = up, o.width = kW, o.height = kH;
  auto r = plan_views(s, o);
  EXPECT_TRUE(r.ok()) << r.status().message();
  return r.ok() ? *r : ViewPlan{};
}

TEST(UpAxis, ParsesEveryAxisAndNamesTheAcceptedWords) {
  EXPECT_EQ(*parse_up_axis("auto"), UpAxis::kAuto);
  EXPECT_EQ(*parse_up_axis("Z"), UpAxis::kPosZ);
  EXPECT_EQ(*parse_up_axis("+y"), UpAxis::kPosY);
  EXPECT_EQ(*parse_up_axis("-z"), UpAxis::kNegZ);
  EXPECT_EQ(*parse_up_axis("-x"), UpAxis::kNegX);
  auto bad = parse_up_axis("w");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("'w'"), std::string::npos);
  EXPECT_NE(bad.status().message().find("x, y, z"), std::string::npos);
}

TEST(ViewPlanner, SeesAZUpFlatBoardFaceOn) {
  const ViewSurfaces s = surfaces_of(z_up_board());
  const ViewPlan plan = plan_of(s);
  EXPECT_EQ(plan.up.z, 1.0f);
  EXPECT_EQ(plan.up_rule.rfind("flat", 0), 0u) << plan.up_rule;
  ASSERT_EQ(plan.views.size(), 6u);
  EXPECT_EQ(plan.views[0].kind, ViewKind::kOverview);
  EXPECT_EQ(plan.views[1].kind, ViewKind::kSurface);
  EXPECT_EQ(plan.views[2].kind, ViewKind::kTexel);
  for (const PlannedView& v : plan.views) {
    const Vec3f to_eye = v.spec.eye - v.spec.target;
    // In front of the board and far from edge-on (the old +Y orbit looked along its plane).
    EXPECT_LE(degrees_between(to_eye, {0, 0, 1}), 60.0) << v.description;
    const ViewDensity d = measure_view_density(s, v.camera, kW, kH);
    EXPECT_GT(d.covered_pixels, 0.05 * kW * kH) << v.description;
  }
  // The surface view frames the board's bounding sphere; the texel view is filled by the board.
  for (int i : {1, 2}) {
    EXPECT_GT(measure_view_density(s, plan.views[i].camera, kW, kH).covered_pixels,
              (i == 1 ? 0.12 : 0.75) * kW * kH)
        << plan.views[i].description;
  }
  // One baked texel per pixel at the texel view's centre.
  EXPECT_NEAR(plan.views[2].pixels_per_texel, 1.0, 1e-3);
  EXPECT_LE(plan.views[2].angle_deg, 15.0);
}

TEST(ViewPlanner, FindsZUpFromTheGroundAndTakesAGivenAxis) {
  // A 10 x 10 ground at z = 0 with a 1 x 1 x 3 tower: not flat, but the ground faces +Z.
  scene::Scene site;
  add_quad(site, {{{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}}}, {0, 0, 0.5f, 0.5f});
  add_quad(site, {{{4, 4, 3}, {5, 4, 3}, {5, 5, 3}, {4, 5, 3}}}, {0.5f, 0, 0.6f, 0.1f});
  add_quad(site, {{{4, 4, 0}, {5, 4, 0}, {5, 4, 3}, {4, 4, 3}}}, {0.6f, 0, 0.7f, 0.3f});
  add_quad(site, {{{5, 5, 0}, {4, 5, 0}, {4, 5, 3}, {5, 5, 3}}}, {0.7f, 0, 0.8f, 0.3f});
  const ViewSurfaces s = surfaces_of(site);
  std::string rule;
  const Vec3f up = find_up_axis(s, UpAxis::kAuto, &rule);
  EXPECT_EQ(up.z, 1.0f) << rule;
  EXPECT_EQ(rule.rfind("normals", 0), 0u) << rule;
  const Vec3f given = find_up_axis(s, UpAxis::kNegY, &rule);
  EXPECT_EQ(given.y, -1.0f);
  EXPECT_EQ(rule, "given");
  // The overview looks down on the ground from above the horizon, not along it.
  const ViewPlan plan = plan_of(s);
  const Vec3f to_eye = plan.views[0].spec.eye - plan.views[0].spec.target;
  EXPECT_NEAR(degrees_between(to_eye, {0, 0, 1}), 55.0, 0.5);
  // The ground holds most texels: the first framed view is on it, near face-on.
  ASSERT_GE(plan.views.size(), 2u);
  EXPECT_EQ(plan.views[1].cluster, 0);
  EXPECT_LE(degrees_between(plan.views[1].spec.eye - plan.views[1].spec.target, {0, 0, 1}), 30.0);
}

TEST(ViewPlanner, IsDeterministic) {
  scene::Scene s = z_up_board();
  add_quad(s, {{{0, 0, 0}, {0, 2, 0}, {0, 2, 2}, {0, 0, 2}}}, {0.5f, 0.5f, 0.9f, 0.9f});
  const ViewSurfaces surfaces = surfaces_of(s);
  ViewPlan a = plan_of(surfaces), b = plan_of(surfaces);
  a.seconds = b.seconds = 0;
  EXPECT_EQ(to_json(a).dump(), to_json(b).dump());
  for (size_t i = 0; i < a.views.size(); ++i)
    EXPECT_EQ(a.views[i].camera.view_proj.m, b.views[i].camera.view_proj.m) << i;
  EXPECT_EQ(plan_of(surfaces, UpAxis::kAuto, 1).views.size(), 1u);
  EXPECT_FALSE(plan_views(surfaces, ViewPlanOptions{.views = 0}).ok());
}

// A 1 x 1 board with a 64 x 64 base-colour texture over it and a quarter of a 128 x 128 atlas
// per side: 1024 baked texels for 4096 source texels, density 0.5 exactly.
TEST(ViewDensity, IsBakedTexelsPerSourceTexelInView) {
  const std::string dir = temp_dir("density");
  Rgba8Image image{64, 64, std::vector<uint8_t>(64 * 64 * 4, 200)};
  ASSERT_TRUE(write_png(dir + "/t.png", image).ok());
  scene::Scene s;
  s.images.push_back({"t", "t.png", dir + "/t.png", "image/png", {}});
  s.materials.push_back({});
  s.materials[0].base_color_texture.image = 0;
  add_quad(s, {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}}, {0, 0, 0.25f, 0.25f}, 0);
  auto surfaces = gather_view_surfaces(s, 128, 128);
  ASSERT_TRUE(surfaces.ok()) << surfaces.status().message();
  const float aspect = float(kW) / kH;
  auto cam = [&](Vec3f eye, Vec3f target) {
    auto c = camera_from_spec({eye, target, {0, 1, 0}}, aspect);
    EXPECT_TRUE(c.ok());
    return *c;
  };
  ViewDensity d = measure_view_density(*surfaces, cam({0.5f, 0.5f, 2}, {0.5f, 0.5f, 0}), kW, kH);
  EXPECT_DOUBLE_EQ(d.density, 0.5);
  EXPECT_DOUBLE_EQ(d.low, 0.5);
  EXPECT_DOUBLE_EQ(d.textured_share, 1.0);
  EXPECT_EQ(check_view_density(d, 0.5), "");
  const std::string why = check_view_density(d, 0.6);
  EXPECT_NE(why.find("density 0.50"), std::string::npos) << why;
  EXPECT_NE(why.find("2.0x coarser"), std::string::npos) << why;
  // Close up the board overfills the view: clipped to exactly the frame.
  d = measure_view_density(*surfaces, cam({0.5f, 0.5f, 0.3f}, {0.5f, 0.5f, 0}), kW, kH);
  EXPECT_NEAR(d.covered_pixels, double(kW) * kH, 1e-6 * kW * kH);
  // Looking away: nothing in view, nothing judged.
  d = measure_view_density(*surfaces, cam({0.5f, 0.5f, 2}, {0.5f, 0.5f, 4}), kW, kH);
  EXPECT_FALSE(d.judged());
  EXPECT_EQ(check_view_density(d, 0.5), "");
  std::filesystem::remove_all(dir);
}

// A 2 x 2 board with a 256 x 256 texture (128 texels per unit) in a Z-up glTF, baked by the
// library at the default (source) density and at a quarter of it.
class DensityBake : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = temp_dir("bake");
    Rgba8Image image{256, 256, std::vector<uint8_t>(256 * 256 * 4)};
    for (uint32_t i = 0; i < 256 * 256; ++i)
      for (int c = 0; c < 4; ++c)
        image.texels[i * 4 + c] =
            c == 3 ? 255 : uint8_t(((i % 256) / 8 + (i / 256) / 8) % 2 * 180 + c * 20);
    scene::Scene s;
    s.images.push_back({"board", "board.png", dir_ + "/board.png", "image/png", {}});
    s.materials.push_back({});
    s.materials[0].name = "board";
    s.materials[0].base_color_texture.image = 0;
    s.materials[0].metallic_factor = 0;
    add_quad(s, {{{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}}}, {0, 0, 1, 1}, 0);
    s.meshes[0].primitives[0].uvs.pop_back();  // the source has no atlas UVs
    Status st = write_png(dir_ + "/board.png", image);
    if (st.ok()) st = scene::save_gltf(s, dir_ + "/board.gltf");
    for (const char* name : {"default", "quarter"}) {
      if (!st.ok()) break;
      SceneBakeOptions o;
      o.build.output = dir_ + "/" + name + ".vtpf";
      if (std::string(name) == "quarter") o.unwrap.texels_per_unit = 32;
      auto baked = bake_scene(dir_ + "/board.gltf", o);
      if (!baked.ok()) st = baked.status();
    }
    if (!st.ok()) setup_error_ = st.message();
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(dir_); }
  void SetUp() override { ASSERT_TRUE(setup_error_.empty()) << setup_error_; }

  // The planned views' densities of a bake, through the library as validate_bake computes them.
  static std::vector<ViewDensity> densities(const std::string& name) {
    auto reader = PageFileReader::open(dir_ + "/" + name + ".vtpf");
    EXPECT_TRUE(reader.ok()) << reader.status().message();
    auto baked = scene::load_scene(dir_ + "/" + name + ".glb");
    EXPECT_TRUE(baked.ok()) << baked.status().message();
    if (!reader.ok() || !baked.ok()) return {};
    const PageGeometry& g = (*reader)->geometry();
    auto surfaces = gather_view_surfaces(*baked, g.width, g.height);
    EXPECT_TRUE(surfaces.ok()) << surfaces.status().message();
    if (!surfaces.ok()) return {};
    const ViewPlan plan = plan_of(*surfaces);
    EXPECT_EQ(plan.up.z, 1.0f);
    std::vector<ViewDensity> out;
    for (const PlannedView& v : plan.views)
      out.push_back(measure_view_density(*surfaces, v.camera, kW, kH));
    return out;
  }

  static BakeValidationOptions validation(const std::string& name) {
    BakeValidationOptions o;
    o.scene = dir_ + "/board.gltf";
    o.page_file = dir_ + "/" + name + ".vtpf";
    o.views = 3;
    o.width = kW, o.height = kH;
    return o;
  }

  static std::string dir_, setup_error_;
};
std::string DensityBake::dir_, DensityBake::setup_error_;

TEST_F(DensityBake, AQuarterDensityBakeFailsTheDensityViews) {
  const std::vector<ViewDensity> good = densities("default");
  const std::vector<ViewDensity> coarse = densities("quarter");
  ASSERT_EQ(good.size(), 6u);
  ASSERT_EQ(coarse.size(), 6u);
  for (size_t i = 0; i < good.size(); ++i) {
    ASSERT_TRUE(good[i].judged()) << i;
    ASSERT_TRUE(coarse[i].judged()) << i;
    EXPECT_GE(good[i].density, 0.9) << i;
    EXPECT_EQ(check_view_density(good[i], 0.5), "") << i;
    EXPECT_NEAR(coarse[i].density, 0.25, 0.01) << i;
    EXPECT_NE(check_view_density(coarse[i], 0.5).find("density 0.25"), std::string::npos) << i;
  }
}

TEST_F(DensityBake, ValidateNamesTheDensityOfTheFailingViews) {
  if (auto ctx = VulkanContext::create(); !ctx.ok()) {
    GTEST_SKIP() << "no Vulkan device: " << ctx.status().message();
  }
  auto good = validate_bake(validation("default"));
  ASSERT_TRUE(good.ok()) << good.status().message();
  auto coarse = validate_bake(validation("quarter"));
  ASSERT_TRUE(coarse.ok()) << coarse.status().message();
  ASSERT_EQ(good->views.size(), 3u);
  ASSERT_EQ(coarse->views.size(), 3u);
  EXPECT_FALSE(coarse->passed());
  for (size_t i = 0; i < 3; ++i) {
    const auto mentions_density = [](const ViewReport& v) {
      for (const std::string& f : v.failures)
        if (f.find("baked texels per source texel") != std::string::npos) return true;
      return false;
    };
    EXPECT_FALSE(mentions_density(good->views[i])) << i;
    EXPECT_TRUE(mentions_density(coarse->views[i])) << i;
    EXPECT_FALSE(good->views[i].framing.empty());
  }
  const auto json = nlohmann::json::parse(report_json(*coarse));
  EXPECT_NEAR(json["views"][1]["density"]["median"].get<double>(), 0.25, 0.01);
  EXPECT_EQ(json["view_plan"]["views"].size(), 3u);
  EXPECT_EQ(json["thresholds"]["min_density"].get<double>(), 0.5);
}

}  // namespace
}  // namespace vt::render
