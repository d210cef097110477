// render::check_atlas_pages on small bakes of the procedural sample scene: a correct bake
// passes (a raw bake matches its reference exactly), and each sabotage of the page file (pages
// rewritten, checksums recomputed so that verify passes) fails on the pages it touched.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <numeric>

#include "bake/scene_bake.h"
#include "codec/metrics.h"
#include "common/hash.h"
#include "common/srgb.h"
#include "format/layer_codec.h"
#include "render/atlas_check.h"
#include "samples/sample_scene.h"
#include "scene/gltf_export.h"
#include "tests/render/page_file_rewrite.h"

namespace vt::render {
namespace {

using Remap = PageRemap;
using Edit = PageEdit;
constexpr auto rewrite = rewrite_page_file;

const Remap kSame = [](const PageId& id, uint32_t) { return id; };
const Edit kNoEdit = [](const PageId&, uint32_t, std::vector<uint8_t>&) { return false; };

class AtlasCheck : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ =
        (std::filesystem::temp_directory_path() / ("vt_atlas_check_" + std::to_string(::getpid())))
            .string();
    std::filesystem::remove_all(dir_);
    SampleSceneOptions so;
    so.ground_cells = 4;
    so.sphere_segments = 12;
    so.texture_size = 256;  // the emissive lines fall between texel centres below that
    Status s = write_sample_scene(dir_ + "/scene", so);
    for (const char* codec : {"dct", "raw"}) {
      if (!s.ok()) break;
      SceneBakeOptions o;
      o.build.output = dir_ + "/" + codec + ".vtpf";
      o.build.codec.codec = std::string(codec) == "raw" ? CodecKind::kRaw : CodecKind::kDct;
      o.unwrap.size_pages = 4;
      auto baked = bake_scene(dir_ + "/scene/scene.gltf", o);
      if (!baked.ok()) s = baked.status();
    }
    if (s.ok()) {
      auto original = scene::load_scene(dir_ + "/scene/scene.gltf");
      auto unwrapped = scene::load_scene(dir_ + "/dct.glb");
      s = !original.ok() ? original.status() : unwrapped.status();
      if (s.ok()) original_ = std::move(*original), unwrapped_ = std::move(*unwrapped);
    }
    if (!s.ok()) setup_error_ = s.message();
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(dir_); }
  void SetUp() override { ASSERT_TRUE(setup_error_.empty()) << setup_error_; }

  static Expected<AtlasCheckReport> check(const std::string& file,
                                          const AtlasCheckOptions& o = {}) {
    VT_ASSIGN_OR_RETURN(auto reader, PageFileReader::open(file));
    VT_RETURN_IF_ERROR(reader->verify());  // sabotaged files keep valid checksums
    const std::string glb = std::filesystem::path(file).replace_extension(".glb").string();
    scene::Scene unwrapped = unwrapped_;
    if (std::filesystem::exists(glb)) {
      VT_ASSIGN_OR_RETURN(unwrapped, scene::load_scene(glb));
    }
    return check_atlas_pages(std::move(reader), original_, unwrapped, o);
  }

  // The sabotaged copy of the DCT bake, checked.
  static AtlasCheckReport sabotage(const std::string& name, const Remap& remap, const Edit& edit) {
    const std::string out = dir_ + "/" + name + ".vtpf";
    Status s = rewrite(dir_ + "/dct.vtpf", out, remap, edit);
    EXPECT_TRUE(s.ok()) << s.message();
    auto r = check(out);
    EXPECT_TRUE(r.ok()) << r.status().message();
    return r.ok() ? *r : AtlasCheckReport{};
  }

  static uint32_t layer_index(LayerSemantic s) {
    auto reader = PageFileReader::open(dir_ + "/dct.vtpf");
    for (uint32_t i = 0; reader.ok() && i < (*reader)->layers().size(); ++i)
      if ((*reader)->layers()[i].semantic == s) return i;
    ADD_FAILURE() << "no layer " << to_string(s);
    return 0;
  }

  // Two level-0 pages of `layer` whose texels differ most: the brightest page and the page
  // farthest from it.
  static std::pair<PageId, PageId> distinct_pages(uint32_t layer) {
    auto reader = PageFileReader::open(dir_ + "/dct.vtpf");
    EXPECT_TRUE(reader.ok());
    const PageGeometry& g = (*reader)->geometry();
    std::vector<PageId> ids;
    std::vector<std::vector<uint8_t>> pages;
    for (uint32_t y = 0; y < g.pages_y(0); ++y)
      for (uint32_t x = 0; x < g.pages_x(0); ++x) {
        std::vector<uint8_t> t((*reader)->decoded_page_bytes(layer));
        if (!(*reader)->read_texels({0, x, y}, layer, t).ok()) continue;
        ids.push_back({0, x, y});
        pages.push_back(std::move(t));
      }
    auto sum = [](const std::vector<uint8_t>& p) {
      return std::accumulate(p.begin(), p.end(), 0.0);
    };
    size_t a = 0, b = 0;
    for (size_t i = 0; i < pages.size(); ++i)
      if (sum(pages[i]) > sum(pages[a])) a = i;
    double far = -1;
    for (size_t i = 0; i < pages.size(); ++i) {
      double d = 0;
      for (size_t k = 0; k < pages[i].size(); ++k) d += std::abs(int(pages[i][k]) - pages[a][k]);
      if (d > far) far = d, b = i;
    }
    return {ids[a], ids[b]};
  }

  static const AtlasLayerReport& layer_report(const AtlasCheckReport& r, LayerSemantic s) {
    for (const AtlasLayerReport& l : r.layers)
      if (l.semantic == s) return l;
    static AtlasLayerReport none;
    ADD_FAILURE() << "no report for " << to_string(s);
    return none;
  }

  static bool lists_failed(const AtlasLayerReport& l, const PageId& id) {
    return std::any_of(l.worst.begin(), l.worst.end(),
                       [&](const AtlasPageError& e) { return e.failed && e.id == id; });
  }

  static std::string dir_, setup_error_;
  static scene::Scene original_, unwrapped_;
};
std::string AtlasCheck::dir_, AtlasCheck::setup_error_;
scene::Scene AtlasCheck::original_, AtlasCheck::unwrapped_;

TEST_F(AtlasCheck, CorrectBakePassesWithHeatMapsAndJson) {
  AtlasCheckOptions o;
  o.out_dir = dir_ + "/maps";
  std::filesystem::create_directories(o.out_dir);
  auto r = check(dir_ + "/dct.vtpf", o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(r->ran);
  EXPECT_TRUE(r->passed()) << r->failures.front();
  ASSERT_EQ(r->layers.size(), 4u);  // albedo, normal, orm, emissive
  auto reader = PageFileReader::open(dir_ + "/dct.vtpf");
  ASSERT_TRUE(reader.ok());
  const PageGeometry& g = (*reader)->geometry();
  for (const AtlasLayerReport& l : r->layers) {
    EXPECT_TRUE(l.note.empty()) << l.name << ": " << l.note;
    EXPECT_EQ(l.pages_failed, 0u) << l.name;
    EXPECT_EQ(l.pages_checked, g.total_pages()) << l.name;  // every page is stored or constant
    EXPECT_GE(l.min_psnr, l.bounds.min_psnr) << l.name;
    ASSERT_EQ(l.heat_maps.size(), g.level_count());
    for (const std::string& png : l.heat_maps) EXPECT_TRUE(std::filesystem::exists(png)) << png;
  }
  const nlohmann::json j = to_json(*r);
  EXPECT_TRUE(j["passed"].get<bool>());
  EXPECT_EQ(j["layers"].size(), 4u);
  EXPECT_FALSE(j["layers"][0]["worst_pages"].empty());
}

TEST_F(AtlasCheck, RawBakeMatchesItsReferenceExactly) {
  AtlasCheckOptions o;
  o.stored_texels = true;  // before the runtime's BC transcode
  auto r = check(dir_ + "/raw.vtpf", o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  ASSERT_TRUE(r->passed());
  for (const AtlasLayerReport& l : r->layers) {
    EXPECT_EQ(l.min_psnr, kPsnrIdentical) << l.name;
    EXPECT_EQ(l.worst_max_deg, 0.0) << l.name;
  }
  o.stored_texels = false;  // the upload: the BC transcode's error, within the BC bounds
  r = check(dir_ + "/raw.vtpf", o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(r->passed()) << r->failures.front();
}

// An HDR emissive (strength 4) kept as half floats (--float-texels half) and as 32-bit floats
// (raw codec): the float layers match their reference, stored and as uploaded (BC6H for RGB
// half, within its floor; RGBA32F widened from RGB, exactly).
TEST_F(AtlasCheck, FloatEmissiveLayersMatchTheirReference) {
  scene::Scene hdr = original_;
  for (scene::Material& m : hdr.materials) m.emissive_strength = 4.0f;
  for (FloatTexels kind : {FloatTexels::kHalf, FloatTexels::kFloat}) {
    const std::string name = std::string("hdr_") + to_string(kind);
    SceneBakeOptions o;
    o.build.output = dir_ + "/" + name + ".vtpf";
    o.build.codec.float_texels = kind;
    o.unwrap.size_pages = 4;
    auto baked = bake_scene(hdr, o);
    ASSERT_TRUE(baked.ok()) << baked.status().message();
    const LayerSummary* emissive = nullptr;
    for (const LayerSummary& l : baked->build.layers)
      if (l.spec.semantic == LayerSemantic::kEmissive) emissive = &l;
    ASSERT_NE(emissive, nullptr);
    EXPECT_EQ(emissive->spec.texel_type,
              kind == FloatTexels::kHalf ? TexelType::kF16 : TexelType::kF32);
    auto reader = PageFileReader::open(o.build.output);
    ASSERT_TRUE(reader.ok());
    auto unwrapped = scene::load_scene(dir_ + "/" + name + ".glb");
    ASSERT_TRUE(unwrapped.ok()) << unwrapped.status().message();
    for (bool stored : {true, false}) {
      AtlasCheckOptions co;
      co.stored_texels = stored;
      auto again = PageFileReader::open(o.build.output);
      ASSERT_TRUE(again.ok());
      auto r = check_atlas_pages(std::move(again).value(), hdr, *unwrapped, co);
      ASSERT_TRUE(r.ok()) << r.status().message();
      const AtlasLayerReport& l = layer_report(*r, LayerSemantic::kEmissive);
      EXPECT_EQ(l.pages_failed, 0u) << name << (stored ? " stored" : " uploaded");
      if (kind == FloatTexels::kHalf && !stored) {
        // RGB half uploads as BC6H (lossy): measured 24.54 dB on the float PSNR (peak 1, so
        // values up to 4 weigh in as they are), passing on BC6H's own floor.
        EXPECT_GT(l.min_psnr, 23.5) << name << " uploaded";
      } else {
        EXPECT_EQ(l.min_psnr, kPsnrIdentical) << name << (stored ? " stored" : " uploaded");
      }
    }
  }
}

TEST_F(AtlasCheck, UnchangedRewriteStillPasses) {
  AtlasCheckReport r = sabotage("copy", kSame, kNoEdit);
  EXPECT_TRUE(r.passed());
}

TEST_F(AtlasCheck, SwappedLevel0PagesFailInEveryLayer) {
  for (LayerSemantic s : {LayerSemantic::kAlbedo, LayerSemantic::kNormal, LayerSemantic::kOrm,
                          LayerSemantic::kEmissive}) {
    const uint32_t li = layer_index(s);
    const auto [a, b] = distinct_pages(li);
    AtlasCheckReport r = sabotage(
        std::string("swap_") + to_string(s),
        [&, a = a, b = b](const PageId& id, uint32_t layer) {
          if (layer != li) return id;
          return id == a ? b : id == b ? a : id;
        },
        kNoEdit);
    ASSERT_FALSE(r.passed()) << to_string(s);
    const AtlasLayerReport& l = layer_report(r, s);
    EXPECT_EQ(l.pages_failed, 2u) << to_string(s);
    EXPECT_TRUE(lists_failed(l, a) && lists_failed(l, b)) << to_string(s);
    EXPECT_EQ(r.failures.size(), 1u);  // only the sabotaged layer
    EXPECT_NE(r.failures[0].find(l.name + ": 2 of"), std::string::npos) << r.failures[0];
  }
}

TEST_F(AtlasCheck, PageFromACoarserLevelFails) {
  const uint32_t li = layer_index(LayerSemantic::kAlbedo);
  const PageId a = distinct_pages(li).first;
  AtlasCheckReport r = sabotage(
      "coarser",
      [&](const PageId& id, uint32_t layer) {
        return layer == li && id == a ? PageId{1, a.x / 2, a.y / 2} : id;
      },
      kNoEdit);
  const AtlasLayerReport& l = layer_report(r, LayerSemantic::kAlbedo);
  EXPECT_EQ(l.pages_failed, 1u);
  EXPECT_TRUE(lists_failed(l, a));
}

TEST_F(AtlasCheck, ZeroedBorderFails) {
  const uint32_t li = layer_index(LayerSemantic::kAlbedo);
  const PageId a = distinct_pages(li).first;
  AtlasCheckReport r =
      sabotage("border", kSame, [&](const PageId& id, uint32_t layer, std::vector<uint8_t>& t) {
        if (layer != li || !(id == a)) return false;
        const uint32_t S = 128, B = 4, c = 4;  // RGBA albedo
        for (uint32_t y = 0; y < S; ++y)
          for (uint32_t x = 0; x < S; ++x)
            if (x < B || y < B || x >= S - B || y >= S - B)
              std::fill_n(&t[(size_t(y) * S + x) * c], c, 0);
        return true;
      });
  const AtlasLayerReport& l = layer_report(r, LayerSemantic::kAlbedo);
  EXPECT_EQ(l.pages_failed, 1u);
  ASSERT_FALSE(l.worst.empty());
  EXPECT_EQ(l.worst[0].id, a);  // worst first
}

TEST_F(AtlasCheck, FlippedNormalGreenFails) {
  const uint32_t li = layer_index(LayerSemantic::kNormal);
  AtlasCheckReport r =
      sabotage("green", kSame, [&](const PageId&, uint32_t layer, std::vector<uint8_t>& t) {
        if (layer != li) return false;
        for (size_t i = 1; i < t.size(); i += 2) t[i] = uint8_t(255 - t[i]);
        return true;
      });
  EXPECT_GT(layer_report(r, LayerSemantic::kNormal).pages_failed, 0u);
  EXPECT_GT(layer_report(r, LayerSemantic::kNormal).worst_mean_deg, 4.0);
  EXPECT_EQ(r.failures.size(), 1u);
}

TEST_F(AtlasCheck, SwappedOrmChannelsFail) {
  const uint32_t li = layer_index(LayerSemantic::kOrm);
  AtlasCheckReport r =
      sabotage("orm", kSame, [&](const PageId&, uint32_t layer, std::vector<uint8_t>& t) {
        if (layer != li) return false;
        for (size_t i = 0; i + 2 < t.size(); i += 3) std::swap(t[i], t[i + 2]);
        return true;
      });
  EXPECT_GT(layer_report(r, LayerSemantic::kOrm).pages_failed, 0u);
  EXPECT_EQ(r.failures.size(), 1u);
}

TEST_F(AtlasCheck, HalvedEmissiveFails) {
  const uint32_t li = layer_index(LayerSemantic::kEmissive);
  AtlasCheckReport r =
      sabotage("emissive", kSame, [&](const PageId&, uint32_t layer, std::vector<uint8_t>& t) {
        if (layer != li) return false;
        for (uint8_t& v : t)
          v = uint8_t(std::lround(linear_to_srgb(0.5f * srgb_to_linear(v / 255.0f)) * 255.0f));
        return true;
      });
  EXPECT_GT(layer_report(r, LayerSemantic::kEmissive).pages_failed, 0u);
  EXPECT_EQ(r.failures.size(), 1u);
}

TEST_F(AtlasCheck, InputErrorsSayWhatIsWrong) {
  auto opened = PageFileReader::open(dir_ + "/dct.vtpf");
  ASSERT_TRUE(opened.ok());
  std::shared_ptr<const PageFileReader> reader = std::move(*opened);
  scene::Scene other = original_;
  other.materials.push_back({});
  auto r = check_atlas_pages(reader, other, unwrapped_, {});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("materials"), std::string::npos);

  AtlasCheckOptions o;
  o.memory_limit = 1 << 20;  // skipped with a note, not an error
  r = check_atlas_pages(reader, original_, unwrapped_, o);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r->ran);
  EXPECT_TRUE(r->passed());
  EXPECT_NE(r->note.find("memory limit"), std::string::npos);
}

// A plane of 24 x 24 separate quads, each its own saturated colour: a mosaic of tiny charts
// that BC1 cannot hold (4x4 blocks straddle charts of unrelated colours), worst on the coarse
// levels. A correct bake passes on the runtime floor; swapped pages still fail.
TEST(AtlasCheckFloor, MosaicPassesOnItsRuntimeFloorAndSwappedPagesStillFail) {
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("vt_atlas_floor_" + std::to_string(::getpid())))
          .string();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  scene::Scene sc;
  scene::Mesh mesh;
  constexpr int kCells = 24;
  for (int y = 0; y < kCells; ++y)
    for (int x = 0; x < kCells; ++x) {
      scene::Material m;
      const uint32_t h = hash32(uint32_t(y * kCells + x) * 2654435761u);
      m.base_color_factor = {float(h & 1), float((h >> 1) & 1), float((h >> 2) & 1), 1.0f};
      m.metallic_factor = 0;
      sc.materials.push_back(m);
      scene::Primitive p;
      const float x0 = float(x), z0 = float(y);
      p.positions = {{x0, 0, z0}, {x0 + 1, 0, z0}, {x0 + 1, 0, z0 + 1}, {x0, 0, z0 + 1}};
      p.normals.assign(4, {0, 1, 0});
      p.indices = {0, 2, 1, 0, 3, 2};
      p.material = int(sc.materials.size() - 1);
      mesh.primitives.push_back(std::move(p));
    }
  sc.meshes.push_back(std::move(mesh));
  scene::Node node;
  node.mesh = 0;
  sc.nodes.push_back(node);
  sc.roots = {0};
  ASSERT_TRUE(scene::save_gltf(sc, dir + "/mosaic.gltf").ok());
  SceneBakeOptions o;
  o.build.output = dir + "/mosaic.vtpf";
  o.unwrap.size_pages = 4;
  auto baked = bake_scene(dir + "/mosaic.gltf", o);
  ASSERT_TRUE(baked.ok()) << baked.status().message();
  auto original = scene::load_scene(dir + "/mosaic.gltf");
  auto unwrapped = scene::load_scene(dir + "/mosaic.glb");
  ASSERT_TRUE(original.ok() && unwrapped.ok());
  auto check = [&](const std::string& file) {
    auto reader = PageFileReader::open(file);
    EXPECT_TRUE(reader.ok());
    auto r = check_atlas_pages(std::move(*reader), *original, *unwrapped, {});
    EXPECT_TRUE(r.ok()) << r.status().message();
    return r.ok() ? *r : AtlasCheckReport{};
  };
  const AtlasCheckReport clean = check(o.build.output);
  EXPECT_TRUE(clean.passed()) << (clean.failures.empty() ? "" : clean.failures[0]);
  ASSERT_FALSE(clean.layers.empty());
  const AtlasLayerReport& albedo = clean.layers[0];
  ASSERT_EQ(albedo.semantic, LayerSemantic::kAlbedo);
  // The layer bound alone would have failed it: pages below it passed on their floor.
  EXPECT_LT(albedo.min_psnr, albedo.bounds.min_psnr);
  ASSERT_FALSE(albedo.worst.empty());
  EXPECT_GT(albedo.worst[0].runtime_floor_psnr, 0.0);
  EXPECT_GE(albedo.worst[0].psnr,
            albedo.worst[0].runtime_floor_psnr - albedo.bounds.floor_margin_db);

  // Level-0 pages (0,0) and (1,1) swapped, checksums recomputed: both fail.
  const PageId a{0, 0, 0}, b{0, 1, 1};
  const std::string swapped = dir + "/swapped.vtpf";
  ASSERT_TRUE(rewrite(
                  o.build.output, swapped,
                  [&](const PageId& id, uint32_t layer) {
                    if (layer != 0) return id;
                    return id == a ? b : id == b ? a : id;
                  },
                  kNoEdit)
                  .ok());
  const AtlasCheckReport bad = check(swapped);
  ASSERT_FALSE(bad.passed());
  const AtlasLayerReport& l = bad.layers[0];
  EXPECT_EQ(l.pages_failed, 2u);
  for (const PageId& id : {a, b})
    EXPECT_TRUE(std::any_of(l.worst.begin(), l.worst.end(),
                            [&](const AtlasPageError& e) { return e.failed && e.id == id; }));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace vt::render
