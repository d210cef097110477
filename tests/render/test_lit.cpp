// The lit check (render/lit_pass.h): lights from the camera, the lit reference's materials, the
// layers it reads; and on a small bake of the procedural sample scene (all four layers), the
// correct bake passes while a normal layer with green flipped fails the lit comparison and an
// emissive layer at half strength the emissive-only one.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "bake/scene_bake.h"
#include "common/srgb.h"
#include "render/emissive_check.h"
#include "render/lit_pass.h"
#include "render/validate.h"
#include "render/vulkan_context.h"
#include "samples/sample_scene.h"
#include "tests/render/page_file_rewrite.h"

namespace vt::render {
namespace {

LayerSpec layer(LayerSemantic s, const std::string& name) {
  LayerSpec l;
  l.semantic = s;
  l.name = name;
  return l;
}

TEST(LitLayers, EveryRenderableLitLayerOrTheNamedOne) {
  const std::vector<LayerSpec> specs = {
      layer(LayerSemantic::kAlbedo, "albedo"), layer(LayerSemantic::kNormal, "normal"),
      layer(LayerSemantic::kOrm, "orm"), layer(LayerSemantic::kEmissive, "emissive")};
  const std::vector<RuntimeFormat> formats = {RuntimeFormat::kBc1, RuntimeFormat::kBc5,
                                              RuntimeFormat::kBc1, RuntimeFormat::kRgba16f};
  auto all = find_lit_layers(specs, formats);
  ASSERT_TRUE(all.ok()) << all.status().message();
  EXPECT_EQ(all->layer[0], 0u);
  EXPECT_EQ(all->layer[1], 1u);
  EXPECT_EQ(all->layer[2], 2u);
  EXPECT_FALSE(all->layer[3]);  // a float layer cannot be rendered: skipped, said why
  ASSERT_EQ(all->skipped.size(), 1u);
  EXPECT_NE(all->skipped[0].find("emissive"), std::string::npos);
  EXPECT_EQ(all->inputs(), (1u << 1) | (1u << 2));
  EXPECT_TRUE(all->any());

  auto orm = find_lit_layers(specs, formats, "orm");
  ASSERT_TRUE(orm.ok());
  EXPECT_EQ(orm->inputs(), 1u << 2);

  auto bad = find_lit_layers(specs, formats, "albedo");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("'albedo'"), std::string::npos);

  // Albedo alone: nothing to light.
  auto none = find_lit_layers(std::span(specs).first(1), formats);
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(none->any());
}

TEST(LitFrame, LightsComeFromBehindTheCameraAtItsEye) {
  const Vec3f eye{3, 4, 5};
  Camera c;
  c.view_proj = perspective(0.9f, 16.0f / 9.0f, 0.1f, 100.0f) * look_at(eye, {0, 0, 0}, {0, 1, 0});
  const LitFrameOptions o = lit_frame_for(c, 6);
  EXPECT_NEAR(o.eye[0], 3, 1e-3);
  EXPECT_NEAR(o.eye[1], 4, 1e-3);
  EXPECT_NEAR(o.eye[2], 5, 1e-3);
  EXPECT_EQ(o.inputs, 6u);
  // Towards the camera (positive along the eye direction) and above it: a view is never dark.
  const float len = std::sqrt(50.0f);
  for (const float* d : {o.key_dir, o.fill_dir}) {
    EXPECT_GT((d[0] * 3 + d[1] * 4 + d[2] * 5) / len, 0.5f);
  }
  EXPECT_GT(o.key_dir[1], 0.3f);
}

TEST(LitMaterials, FactorsAndDefaultsAsTheBakeAppliesThem) {
  scene::Scene s;
  scene::Material m;
  m.roughness_factor = 0.4f;
  m.metallic_factor = 0.8f;
  m.emissive_factor = {0.5f, 0.25f, 1.0f};
  m.emissive_strength = 2.0f;
  s.materials = {m};
  auto lit = lit_materials(s);
  ASSERT_TRUE(lit.ok()) << lit.status().message();
  ASSERT_EQ(lit->size(), 2u);  // the material and the default material
  const LitMaterial& a = (*lit)[0];
  EXPECT_FALSE(a.has_normal_map);
  ASSERT_EQ(a.orm.width, 1u);
  EXPECT_EQ(a.orm.levels[0], (std::vector<uint8_t>{255, 102, 204, 255}));
  EXPECT_EQ(a.emissive_scale[0], 1.0f);
  EXPECT_EQ(a.emissive_scale[1], 0.5f);
  EXPECT_EQ(a.emissive_scale[2], 2.0f);
  EXPECT_EQ(a.normal.levels[0], (std::vector<uint8_t>{128, 128, 255, 255}));
  EXPECT_EQ(a.occlusion.levels[0], (std::vector<uint8_t>{255, 255, 255, 255}));
  // glTF's default material: fully rough, fully metallic, no emission.
  EXPECT_EQ((*lit)[1].orm.levels[0], (std::vector<uint8_t>{255, 255, 255, 255}));
  EXPECT_EQ((*lit)[1].emissive_scale[0], 0.0f);

  scene::Scene missing = s;
  missing.images.push_back({"gone", "gone.png", "/nonexistent/gone.png", "", {}});
  missing.materials[0].normal_texture.image = 0;
  missing.source_path = "scene.gltf";
  auto err = lit_materials(missing);
  ASSERT_FALSE(err.ok());
  EXPECT_NE(err.status().message().find("gone.png"), std::string::npos);
  // As a bake with --missing-textures warn: the slot's factor alone (a flat normal), listed.
  std::vector<std::string> listed;
  auto factor = lit_materials(missing, {.missing_as_factor = true}, &listed);
  ASSERT_TRUE(factor.ok()) << factor.status().message();
  EXPECT_FALSE((*factor)[0].has_normal_map);
  EXPECT_EQ((*factor)[0].normal.levels[0], (std::vector<uint8_t>{128, 128, 255, 255}));
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_NE(listed[0].find("gone.png"), std::string::npos) << listed[0];
}

TEST(LitShadingFrames, NormalsTangentsAndUvsInWorldSpace) {
  scene::Scene s;
  scene::Primitive p;
  p.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  p.uvs = {{{0, 1}, {1, 1}, {0, 0}}};
  p.indices = {0, 1, 2};
  p.material = 0;
  scene::Material m;
  m.normal_texture.image = 0;  // read through its own slot (tex_uv), the draw's UV left alone
  s.materials = {m};
  scene::Mesh mesh;
  mesh.primitives = {p};
  s.meshes = {mesh};
  scene::Node node;
  node.mesh = 0;
  node.local = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 0, 0, 1};  // moved, not rotated
  s.nodes = {node};
  s.roots = {0};
  SceneDraws draws;
  MeshData md;
  md.vertices.resize(3);
  md.indices = p.indices;
  draws.meshes = {md};
  ASSERT_TRUE(add_shading_frames(s, draws, true).ok());
  const Vertex& v = draws.meshes[0].vertices[1];
  EXPECT_FLOAT_EQ(v.nz, 1.0f);  // counter-clockwise in xy: +z
  EXPECT_FLOAT_EQ(v.tx, 1.0f);  // u grows along +x
  EXPECT_FLOAT_EQ(v.tw, 1.0f);
  EXPECT_FLOAT_EQ(v.tex_uv[kLitNormalUv][0], 1.0f);
  EXPECT_FLOAT_EQ(v.tex_uv[kLitNormalUv][1], 1.0f);
  EXPECT_FLOAT_EQ(v.u, 0.0f);
  draws.meshes.push_back(md);  // a draw the scene does not have
  EXPECT_FALSE(add_shading_frames(s, draws, true).ok());
}

class LitCheck : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = (std::filesystem::temp_directory_path() / ("vt_lit_" + std::to_string(::getpid())))
               .string();
    std::filesystem::remove_all(dir_);
    SampleSceneOptions so;
    so.ground_cells = 4;
    so.sphere_segments = 12;
    so.texture_size = 256;  // the emissive lines fall between texel centres below that
    Status s = write_sample_scene(dir_ + "/scene", so);
    if (s.ok()) {
      SceneBakeOptions o;
      o.build.output = dir_ + "/bake.vtpf";
      o.unwrap.size_pages = 4;
      auto baked = bake_scene(dir_ + "/scene/scene.gltf", o);
      if (!baked.ok()) s = baked.status();
    }
    if (!s.ok()) setup_error_ = s.message();
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(dir_); }
  void SetUp() override {
    ASSERT_TRUE(setup_error_.empty()) << setup_error_;
    if (auto ctx = VulkanContext::create(); !ctx.ok()) {
      GTEST_SKIP() << "no Vulkan device: " << ctx.status().message();
    }
  }

  static Expected<ValidationReport> validate(const std::string& page_file,
                                             const std::string& layer = "",
                                             const std::string& cameras = "") {
    BakeValidationOptions o;
    o.scene = dir_ + "/scene/scene.gltf";
    o.page_file = page_file;
    o.unwrapped = dir_ + "/bake.glb";
    o.out_dir = page_file + ".validate";
    o.layer = layer;
    o.cameras_file = cameras;
    o.views = 2;
    o.width = 320;
    o.height = 180;
    o.atlas.enabled = false;  // the atlas check has its own tests
    // The 4-page bake is coarser than its 256-texel sources on purpose (fast); density has its
    // own tests (test_view_planner.cpp).
    o.thresholds.min_density = 0;
    return validate_bake(o);
  }

  // The sabotaged copy of the bake: `edit` applied to every page of the layer `semantic`.
  static std::string sabotage(const std::string& name, LayerSemantic semantic,
                              const std::function<void(std::vector<uint8_t>&)>& edit) {
    auto reader = PageFileReader::open(dir_ + "/bake.vtpf");
    EXPECT_TRUE(reader.ok());
    uint32_t li = 0;
    for (uint32_t i = 0; reader.ok() && i < (*reader)->layers().size(); ++i)
      if ((*reader)->layers()[i].semantic == semantic) li = i;
    const std::string out = dir_ + "/" + name + ".vtpf";
    Status s = rewrite_page_file(
        dir_ + "/bake.vtpf", out, [](const PageId& id, uint32_t) { return id; },
        [&](const PageId&, uint32_t layer, std::vector<uint8_t>& t) {
          if (layer != li) return false;
          edit(t);
          return true;
        });
    EXPECT_TRUE(s.ok()) << s.message();
    return out;
  }

  static bool lit_failed(const ValidationReport& r) {
    for (const ViewReport& v : r.views)
      if (v.lit)
        std::printf("lit view %u: %.2f dB, worst tile %.2f dB; normals mean %.2f deg, r %.3f\n",
                    v.view, v.lit->metrics.psnr_rgb, v.lit->metrics.worst_tile_psnr,
                    v.lit->normals ? v.lit->normals->mean_deg : -1.0,
                    v.lit->normals ? v.lit->normals->detail_correlation : -1.0);
    for (const ViewReport& v : r.views)
      for (const std::string& f : v.failures)
        if (f.rfind("lit", 0) == 0) return true;  // "lit: ", "lit emissive: ", "lit normals: "
    return false;
  }

  static std::string dir_, setup_error_;
};
std::string LitCheck::dir_, LitCheck::setup_error_;

TEST_F(LitCheck, CorrectBakePassesWithLitImages) {
  auto r = validate(dir_ + "/bake.vtpf");
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->lit_layers, (std::vector<std::string>{"albedo", "normal", "orm", "emissive"}));
  for (const ViewReport& v : r->views) {
    ASSERT_TRUE(v.lit.has_value());
    EXPECT_TRUE(v.failures.empty()) << v.failures[0];
    EXPECT_GT(v.lit->metrics.pixels, 1000u);
    EXPECT_GE(v.lit->metrics.psnr_rgb, r->lit_thresholds.min_psnr);
    ASSERT_TRUE(v.lit->normals.has_value());  // the bake has a normal layer
    EXPECT_TRUE(v.lit->normals->detail_judged());
    EXPECT_GE(v.lit->normals->detail_correlation, r->normal_bounds.min_detail_correlation);
    EXPECT_LE(v.lit->normals->mean_deg, r->normal_bounds.max_mean_deg);
    int lit_images = 0;
    for (const std::string& image : v.images) {
      lit_images +=
          std::filesystem::path(image).filename().string().find("_lit_") != std::string::npos;
      EXPECT_TRUE(std::filesystem::exists(image)) << image;
    }
    EXPECT_EQ(lit_images, 2);
  }
  EXPECT_FALSE(lit_failed(*r));
}

TEST_F(LitCheck, NamedLayerLightsThatLayerAlone) {
  auto r = validate(dir_ + "/bake.vtpf", "normal");
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->lit_layers, (std::vector<std::string>{"albedo", "normal"}));
  ASSERT_FALSE(r->views.empty());
  EXPECT_TRUE(r->views[0].lit.has_value());
  auto albedo = validate(dir_ + "/bake.vtpf", "albedo");
  ASSERT_TRUE(albedo.ok()) << albedo.status().message();
  EXPECT_TRUE(albedo->lit_layers.empty());
  EXPECT_FALSE(albedo->views[0].lit.has_value());
}

TEST_F(LitCheck, NormalLayerWithGreenFlippedFails) {
  const std::string file = sabotage("green", LayerSemantic::kNormal, [](std::vector<uint8_t>& t) {
    for (size_t i = 1; i < t.size(); i += 2) t[i] = uint8_t(255 - t[i]);
  });
  auto r = validate(file, "normal");
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(lit_failed(*r));
  EXPECT_FALSE(r->passed());
  // The normals frame is what sees it: every view's detail no longer correlates.
  for (const ViewReport& v : r->views) {
    ASSERT_TRUE(v.lit && v.lit->normals);
    EXPECT_TRUE(v.lit->normals->detail_judged());
    EXPECT_LT(v.lit->normals->detail_correlation, r->normal_bounds.min_detail_correlation);
    bool named = false;
    for (const std::string& f : v.failures) named |= f.rfind("lit normals: ", 0) == 0;
    EXPECT_TRUE(named) << "view " << v.view;
  }
}

TEST_F(LitCheck, EmissiveAtHalfStrengthFails) {
  const std::string file =
      sabotage("emissive", LayerSemantic::kEmissive, [](std::vector<uint8_t>& t) {
        for (uint8_t& v : t)
          v = uint8_t(std::lround(linear_to_srgb(0.5f * srgb_to_linear(v / 255.0f)) * 255.0f));
      });
  // The torus is a small part of the automatic views: look at it from close by.
  const std::string cameras = dir_ + "/torus.json";
  std::FILE* f = std::fopen(cameras.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fputs(R"({"cameras": [{"eye": [-1, 2.2, 4.2], "target": [-1, 0.3, 2]}]})", f);
  std::fclose(f);
  auto correct = validate(dir_ + "/bake.vtpf", "emissive", cameras);
  ASSERT_TRUE(correct.ok()) << correct.status().message();
  auto r = validate(file, "emissive", cameras);
  ASSERT_TRUE(r.ok()) << r.status().message();
  // Close on the 1-texel emissive lines the whole lit view of the correct bake scores only
  // 24.5 / 17.5 dB (the atlas is coarser than the 256-texel source) and the halved layer 23.1 /
  // 15.3 dB: the emissive contribution alone (emissive_check.h) tells them apart.
  lit_failed(*correct), lit_failed(*r);  // prints the figures
  ASSERT_TRUE(correct->views[0].lit && r->views[0].lit);
  ASSERT_TRUE(correct->views[0].lit->emissive && r->views[0].lit->emissive);
  const EmissiveMetrics& good = *correct->views[0].lit->emissive;
  const EmissiveMetrics& bad = *r->views[0].lit->emissive;
  std::printf("emissive alone: correct %.2f dB, energy %.3f; halved %.2f dB, energy %.3f\n",
              good.psnr_rgb, good.energy_ratio, bad.psnr_rgb, bad.energy_ratio);
  auto emissive_failed = [](const ValidationReport& v) {
    for (const std::string& f : v.views[0].failures)
      if (f.rfind("lit emissive: ", 0) == 0) return true;
    return false;
  };
  EXPECT_FALSE(emissive_failed(*correct)) << ::testing::PrintToString(correct->views[0].failures);
  EXPECT_TRUE(emissive_failed(*r));
  EXPECT_FALSE(r->passed());
  EXPECT_LT(bad.energy_ratio, 0.5);
  EXPECT_LT(r->views[0].lit->metrics.worst_tile_psnr,
            correct->views[0].lit->metrics.worst_tile_psnr - 1.0);
}

// Synthetic frames, no GPU: a view whose surfaces emit nothing. Faint stray glow in the
// virtual render (codec bleed from a glowing chart nearby: ClearCoatTest's label) is judged by
// PSNR, not as an infinite energy ratio; a bright false glow still fails.
TEST(EmissiveCheck, ViewWithoutGlowIsJudgedByPsnrNotTheEnergyRatio) {
  constexpr uint32_t w = 64, h = 64;
  ReferenceFrame ref;
  ref.color.width = w;
  ref.color.height = h;
  ref.color.texels.assign(size_t(w) * h * 4, 0);
  ref.covered.assign(size_t(w) * h, 1u);
  VirtualFrame test;
  test.color = ref.color;
  test.status.assign(size_t(w) * h, 0x80000000u);
  auto paint = [&](Rgba8Image& img, uint32_t pixels, uint8_t v) {
    for (uint32_t i = 0; i < pixels; ++i)
      for (int c = 0; c < 3; ++c) img.texels[size_t(i) * 97 % (w * h) * 4 + c] = v;
  };
  const EmissiveBounds b = default_emissive_bounds();
  paint(test.color, 40, 20);  // speckles at 20/255
  auto faint = compare_emissive(ref, test);
  ASSERT_TRUE(faint.ok());
  EXPECT_EQ(faint->reference_glow_pixels, 0u);
  EXPECT_FALSE(faint->energy_judged());
  EXPECT_GT(faint->energy_ratio, 10.0);  // reported, not judged
  EXPECT_TRUE(check_emissive(*faint, b).empty()) << check_emissive(*faint, b)[0];
  paint(test.color, 2000, 200);  // a glow that is not there
  auto bright = compare_emissive(ref, test);
  ASSERT_TRUE(bright.ok());
  EXPECT_FALSE(check_emissive(*bright, b).empty());
  // Where the reference glows, the ratio is judged: the virtual at a quarter of its light fails.
  paint(ref.color, 2000, 200);
  paint(test.color, 2000, 110);  // sRGB 110 is about a quarter of 200's linear light
  auto dim = compare_emissive(ref, test);
  ASSERT_TRUE(dim.ok());
  EXPECT_TRUE(dim->energy_judged());
  EXPECT_LT(dim->energy_ratio, 0.3);
  const auto why = check_emissive(*dim, b);
  EXPECT_TRUE(std::any_of(why.begin(), why.end(), [](const std::string& l) {
    return l.find("emits") != std::string::npos;
  }));
}

}  // namespace
}  // namespace vt::render
