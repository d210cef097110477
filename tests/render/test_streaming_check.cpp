// The exact streaming check: the level texture assembly on a hand-made page source (payloads
// tiled, borders ignored, absent pages from their ancestor, fine levels dropped over the side
// limit, levels that halve with ceil in padded mips), then on bakes of the procedural sample
// scene: a correct bake agrees with its baked levels to rounding, and a cache fed wrong borders
// or a wrong page, at level 0 or at a coarse level that halves with ceil, fails.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>

#include "bake/scene_bake.h"
#include "codec/metrics.h"
#include "format/runtime_format.h"
#include "render/scene_draws.h"
#include "render/streaming_check.h"
#include "render/validate.h"
#include "render/vulkan_context.h"
#include "samples/sample_scene.h"

namespace vt::render {
namespace {

// RGBA8 or RG8 pages whose payload texel (x, y) of page (px, py) at level L reads
// (16 L + 4 py + px, x * 16 + y, 7, 9) and whose border reads 0xEE; page (1, 0) of level 0 is
// absent.
class HandMadeSource : public PageSource {
 public:
  // Width 6: level 0 is 6 x 8 (two pages across, the second cut), level 1 3 x 4.
  explicit HandMadeSource(RuntimeFormat format, uint32_t width = 6) : format_(format) {
    g_.width = width;
    g_.height = 8;
    g_.payload = 4;
    g_.border = 2;
  }
  const PageGeometry& geometry() const override { return g_; }
  uint32_t layer_count() const override { return 1; }
  RuntimeFormat upload_format(uint32_t) const override { return format_; }
  size_t upload_bytes(uint32_t) const override {
    return runtime_format_page_bytes(format_, g_.page_size());
  }
  bool present(const PageId& id) const override {
    return !(id.level == 0 && id.x == 1 && id.y == 0);
  }
  Status load(const PageId& id, uint32_t, std::span<uint8_t> out) const override {
    const uint32_t S = g_.page_size(), B = g_.border, ch = channels();
    for (uint32_t y = 0; y < S; ++y)
      for (uint32_t x = 0; x < S; ++x) {
        uint8_t* p = &out[(size_t(y) * S + x) * ch];
        const bool payload = x >= B && y >= B && x < B + g_.payload && y < B + g_.payload;
        const uint8_t v[4] = {uint8_t(16 * id.level + 4 * id.y + id.x),
                              uint8_t((x - B) * 16 + (y - B)), 7, 9};
        for (uint32_t c = 0; c < ch; ++c) p[c] = payload ? v[c] : 0xEE;
      }
    return Status::Ok();
  }
  uint32_t channels() const { return format_ == RuntimeFormat::kRg8 ? 2 : 4; }

 private:
  PageGeometry g_;
  RuntimeFormat format_;
};

// Texel (x, y) of a mip `w` texels wide.
std::array<int, 4> texel_at(const std::vector<uint8_t>& mip, uint32_t w, uint32_t x, uint32_t y) {
  const uint8_t* p = &mip[(size_t(y) * w + x) * 4];
  return {p[0], p[1], p[2], p[3]};
}

TEST(LevelTexture, TilesPayloadsIgnoringBordersAndFillsAbsentPagesFromTheirAncestor) {
  HandMadeSource source(RuntimeFormat::kRgba8);
  ASSERT_TRUE(source.geometry().validate().ok());
  auto t = assemble_level_texture(source, 0, AddressMode::kWrap);
  ASSERT_TRUE(t.ok()) << t.status().message();
  EXPECT_EQ(t->first_level, 0u);
  EXPECT_EQ(t->level_count, 2u);
  EXPECT_EQ(t->absent_pages, 1u);
  ASSERT_EQ(t->texture.levels.size(), 2u);
  EXPECT_EQ(t->texture.levels_width, 6u);
  EXPECT_EQ(t->texture.levels_height, 8u);
  // Padded for two levels: a multiple of 2, at least 4 longer (2 texels past each level).
  EXPECT_EQ(t->texture.width, 10u);
  EXPECT_EQ(t->texture.height, 12u);
  EXPECT_EQ(t->texture.max_level, 1u);
  EXPECT_EQ(t->texture.address_mode, AddressMode::kWrap);
  const auto& l0 = t->texture.levels[0];
  const auto& l1 = t->texture.levels[1];
  ASSERT_EQ(l0.size(), 10u * 12 * 4);
  ASSERT_EQ(l1.size(), 5u * 6 * 4);
  // Page (0, 1) of level 0, texel (3, 2) of its payload at level texel (3, 6).
  EXPECT_EQ(texel_at(l0, 10, 3, 6), (std::array<int, 4>{4, 3 * 16 + 2, 7, 9}));
  EXPECT_EQ(texel_at(l0, 10, 0, 0), (std::array<int, 4>{0, 0, 7, 9}));
  EXPECT_EQ(texel_at(l0, 10, 5, 7), (std::array<int, 4>{5, 1 * 16 + 3, 7, 9}));  // cut page (1, 1)
  // Level 0's absent page (1, 0) covers texels x 4-5, y 0-3: level 1 texel (x / 2, y / 2).
  EXPECT_EQ(texel_at(l0, 10, 5, 3), texel_at(l1, 5, 2, 1));
  EXPECT_EQ(texel_at(l1, 5, 2, 1), (std::array<int, 4>{16, 2 * 16 + 1, 7, 9}));
  // The padding wraps: past the end the first texels, at the mip's end (before texel 0 for a
  // REPEAT sampler) the last ones; corners both ways.
  for (uint32_t y = 0; y < 8; ++y) {
    EXPECT_EQ(texel_at(l0, 10, 6, y), texel_at(l0, 10, 0, y)) << y;
    EXPECT_EQ(texel_at(l0, 10, 9, y), texel_at(l0, 10, 5, y)) << y;
  }
  EXPECT_EQ(texel_at(l0, 10, 2, 8), texel_at(l0, 10, 2, 0));
  EXPECT_EQ(texel_at(l0, 10, 2, 11), texel_at(l0, 10, 2, 7));
  EXPECT_EQ(texel_at(l0, 10, 9, 11), texel_at(l0, 10, 5, 7));
  EXPECT_EQ(texel_at(l1, 5, 3, 0), texel_at(l1, 5, 0, 0));  // level 1: 3 x 4 in 5 x 6
  EXPECT_EQ(texel_at(l1, 5, 4, 5), texel_at(l1, 5, 2, 3));
  for (size_t i = 0; i < l0.size(); ++i) ASSERT_NE(l0[i], 0xEE) << "border texel at byte " << i;
}

TEST(LevelTexture, MissingChannelsReadAsTheGpuReadsThemAndFineLevelsDropOverTheLimit) {
  HandMadeSource source(RuntimeFormat::kRg8);
  auto t = assemble_level_texture(source, 0, AddressMode::kClamp, /*max_side=*/4);
  ASSERT_TRUE(t.ok()) << t.status().message();
  EXPECT_EQ(t->first_level, 1u);  // level 0 is 6 x 8
  ASSERT_EQ(t->texture.levels.size(), 1u);
  EXPECT_EQ(t->texture.levels_width, 3u);
  EXPECT_EQ(t->texture.width, 5u);
  EXPECT_EQ(texel_at(t->texture.levels[0], 5, 2, 1), (std::array<int, 4>{16, 2 * 16 + 1, 0, 255}));
}

// 7 wide: level 1 is ceil(7 / 2) = 4 texels where a Vulkan mip of 7 is 3. Both levels are held,
// each in the corner of a mip of a 12-texel chain, the padding clamped to the level's edges.
TEST(LevelTexture, LevelsThatDoNotHalveAsVulkanMipsSitInPaddedMips) {
  HandMadeSource source(RuntimeFormat::kRgba8, 7);
  auto t = assemble_level_texture(source, 0, AddressMode::kClamp);
  ASSERT_TRUE(t.ok());
  EXPECT_EQ(t->first_level, 0u);
  EXPECT_EQ(t->level_count, 2u);
  ASSERT_EQ(t->texture.levels.size(), 2u);
  EXPECT_EQ(t->texture.max_level, 1u);
  EXPECT_EQ(t->texture.width, 12u);
  const auto& l1 = t->texture.levels[1];
  ASSERT_EQ(l1.size(), 6u * 6 * 4);
  // Level 1's page (0, 0) holds texels 0-3 of both axes: texel (3, 2).
  EXPECT_EQ(texel_at(l1, 6, 3, 2), (std::array<int, 4>{16, 3 * 16 + 2, 7, 9}));
  EXPECT_EQ(texel_at(l1, 6, 4, 2), texel_at(l1, 6, 3, 2));  // past the end: the last texel
  EXPECT_EQ(texel_at(l1, 6, 5, 2), texel_at(l1, 6, 0, 2));  // before texel 0: the first
}

// A close view of a large atlas wants only levels finer than the check holds: that view says
// nothing about the bake (3DS/test1.3ds); a view with nothing drawn and nothing excluded fails.
TEST(StreamingBoundsCheck, AViewWantingOnlyDroppedLevelsIsNotAFailure) {
  const StreamingBounds b = default_streaming_bounds(RuntimeFormat::kBc3);
  StreamingViewMetrics nothing;  // as compare_streaming leaves a view it compared no pixel of
  nothing.psnr = nothing.worst_tile_psnr = 100;
  StreamingViewMetrics close_view = nothing;
  close_view.excluded_fine = 921600;
  EXPECT_TRUE(check_streaming(close_view, b).empty());
  const std::vector<std::string> why = check_streaming(nothing, b);
  ASSERT_EQ(why.size(), 1u);
  EXPECT_EQ(why[0], "exact check: no pixel to compare");
}

TEST(StreamingBoundsCheck, PixelsAtPageBordersAreBoundedApart) {
  const StreamingBounds b = default_streaming_bounds(RuntimeFormat::kBc3);
  StreamingViewMetrics m;
  m.pixels = 200000;
  m.border_pixels = 6000;
  m.psnr = m.worst_tile_psnr = 60;
  // Codec differences at seams (the corpus: up to 18 steps, 0.23% of border pixels) pass.
  m.border_beyond = 14;
  m.border_max_abs = 18;
  EXPECT_TRUE(check_streaming(m, b).empty());
  // A zeroed border fails on its largest difference, many wrong seams on their share.
  StreamingViewMetrics zeroed = m;
  zeroed.border_max_abs = 168;
  ASSERT_EQ(check_streaming(zeroed, b).size(), 1u);
  EXPECT_NE(check_streaming(zeroed, b)[0].find("page borders 168 steps"), std::string::npos);
  StreamingViewMetrics seams = m;
  seams.border_beyond = 600;
  ASSERT_EQ(check_streaming(seams, b).size(), 1u);
  EXPECT_NE(check_streaming(seams, b)[0].find("10.000% of pixels at page borders"),
            std::string::npos);
  // The same differences away from borders fail the interior bounds.
  StreamingViewMetrics interior = m;
  interior.pixels_beyond = 14;
  interior.share_beyond = 14.0 / 194000;
  interior.max_abs = 18;
  EXPECT_EQ(check_streaming(interior, b).size(), 2u);
}

// Pixels drawn by one render only: a flipped alpha test when the render that drew it flagged
// its alpha as within a few steps of the cutoff (the closed masked box at padding 8: a row of
// pixels at 128/255 in one render, 1/65535 below 0.5 in the other), a coverage mismatch when not.
TEST(StreamingCompare, OneRenderPixelsAreAlphaFlipsOnlyWhereTheDrawingRenderFlaggedThem) {
  // Per pixel: virtual status, reference covered.
  const uint32_t status[] = {0xC0000000u, 0x80000000u, 0, 0, 0x80000000u, 0xC0000000u};
  const uint32_t covered[] = {0, 0, 3, 1, 1, 3};
  ReferenceFrame levels;
  VirtualFrame frame;
  levels.color.width = frame.color.width = 6;
  levels.color.height = frame.color.height = 1;
  levels.color.texels.assign(24, 128);
  frame.color.texels.assign(24, 128);
  levels.covered.assign(std::begin(covered), std::end(covered));
  frame.status.assign(std::begin(status), std::end(status));
  LevelTexture texture;
  texture.texture.levels.resize(1);
  texture.level_count = 1;
  auto m = compare_streaming(levels, frame, texture, 4);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->coverage_mismatch, 2u);    // pixels 1 (virtual only) and 3 (reference only)
  EXPECT_EQ(m->excluded_alpha_edge, 3u);  // 0 and 2 (one render, flagged), 5 (both, flagged)
  EXPECT_EQ(m->pixels, 1u);               // 4: both drew it, no flag
}

// Pixels reading page borders have their own bounds and stay out of the tiles: a 16 x 16 tile
// of them 30 steps apart (within the border bound) beside a tile of interior pixels 1 step
// apart; the worst tile is the interior one.
TEST(StreamingCompare, BorderPixelsStayOutOfTheTiles) {
  ReferenceFrame levels;
  VirtualFrame frame;
  levels.color.width = frame.color.width = 32;
  levels.color.height = frame.color.height = 16;
  levels.color.texels.assign(32 * 16 * 4, 100);
  frame.color.texels.assign(32 * 16 * 4, 101);
  levels.covered.assign(32 * 16, 1);
  frame.status.assign(32 * 16, VirtualFrame::kStatusDrawn);
  for (uint32_t y = 0; y < 16; ++y)
    for (uint32_t x = 0; x < 16; ++x) {
      frame.status[y * 32 + x] |= VirtualFrame::kStatusBorderRead;
      for (int c = 0; c < 3; ++c) frame.color.texels[(y * 32 + x) * 4 + c] = 130;
    }
  LevelTexture texture;
  texture.texture.levels.resize(1);
  texture.level_count = 1;
  auto m = compare_streaming(levels, frame, texture, 4);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->pixels, 512u);
  EXPECT_EQ(m->border_pixels, 256u);
  EXPECT_EQ(m->border_max_abs, 30);
  EXPECT_EQ(m->max_abs, 1);
  EXPECT_NEAR(m->worst_tile_psnr, psnr_from_mse(1.0), 1e-9);
  EXPECT_EQ(m->worst_tile_x, 16u);
}

// A page source that passes another one through, except for what `edit` changes in an upload.
class EditedSource : public PageSource {
 public:
  using Edit = std::function<void(const PageId&, uint32_t layer, std::span<uint8_t>)>;
  EditedSource(std::shared_ptr<const PageSource> inner, Edit edit)
      : inner_(std::move(inner)), edit_(std::move(edit)) {}
  const PageGeometry& geometry() const override { return inner_->geometry(); }
  uint32_t layer_count() const override { return inner_->layer_count(); }
  RuntimeFormat upload_format(uint32_t l) const override { return inner_->upload_format(l); }
  size_t upload_bytes(uint32_t l) const override { return inner_->upload_bytes(l); }
  bool present(const PageId& id) const override { return inner_->present(id); }
  Status load(const PageId& id, uint32_t layer, std::span<uint8_t> out) const override {
    VT_RETURN_IF_ERROR(inner_->load(id, layer, out));
    edit_(id, layer, out);
    return Status::Ok();
  }
  const PageSource& inner() const { return *inner_; }

 private:
  std::shared_ptr<const PageSource> inner_;
  Edit edit_;
};

class StreamingCheck : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = (std::filesystem::temp_directory_path() /
            ("vt_streaming_check_" + std::to_string(::getpid())))
               .string();
    std::filesystem::remove_all(dir_);
    SampleSceneOptions so;
    so.ground_cells = 4;
    so.sphere_segments = 12;
    so.texture_size = 128;
    Status s = write_sample_scene(dir_ + "/scene", so);
    // "raw9": 9 pages across, so that level 4 (67.5 texels) halves with ceil, not as a mip.
    for (const char* codec : {"dct", "bc", "raw", "raw9"}) {
      if (!s.ok()) break;
      SceneBakeOptions o;
      o.build.output = dir_ + "/" + codec + ".vtpf";
      const std::string c = codec;
      o.build.codec.codec = c == "dct"  ? CodecKind::kDct
                            : c == "bc" ? CodecKind::kBc
                                        : CodecKind::kRaw;
      o.unwrap.size_pages = c == "raw9" ? 9 : 4;
      auto baked = bake_scene(dir_ + "/scene/scene.gltf", o);
      if (!baked.ok()) s = baked.status();
    }
    if (!s.ok()) setup_error_ = s.message();
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(dir_); }
  void SetUp() override {
    ASSERT_TRUE(setup_error_.empty()) << setup_error_;
    auto ctx = VulkanContext::create();
    if (!ctx.ok()) GTEST_SKIP() << "no Vulkan device: " << ctx.status().message();
    ctx_ = std::move(*ctx);
  }

  static uint32_t albedo(const PageFileReader& reader) {
    for (uint32_t l = 0; l < reader.layers().size(); ++l)
      if (reader.layers()[l].semantic == LayerSemantic::kAlbedo) return l;
    return 0;
  }

  // `codec`.vtpf as the cache reads it: the pages an edit departs from.
  struct File {
    std::shared_ptr<const PageFileReader> reader;
    std::unique_ptr<PageSource> pages;
    uint32_t albedo = 0;
  };
  Expected<File> open_file(const std::string& codec) {
    File f;
    VT_ASSIGN_OR_RETURN(f.reader, PageFileReader::open(dir_ + "/" + codec + ".vtpf"));
    PageFileSourceOptions so;
    so.bc7_as_rgba8 = ctx_->is_lavapipe();
    VT_ASSIGN_OR_RETURN(f.pages, make_page_file_source(f.reader, so));
    f.albedo = albedo(*f.reader);
    return f;
  }

  // validate_bake's setup around validate_views, with `edit` applied to what the cache
  // receives and, unless `cache_only`, to the level texture as well (an edited file).
  // `distance`: the orbit's distance over the default one (far views want coarse levels).
  Expected<ValidationReport> validate(const std::string& codec, const EditedSource::Edit& edit,
                                      bool cache_only = false, float distance = 1.0f) {
    VT_ASSIGN_OR_RETURN(File f, open_file(codec));
    VT_ASSIGN_OR_RETURN(scene::Scene original, scene::load_scene(dir_ + "/scene/scene.gltf"));
    VT_ASSIGN_OR_RETURN(scene::Scene baked, scene::load_scene(dir_ + "/" + codec + ".glb"));
    VT_ASSIGN_OR_RETURN(SceneDraws ref, reference_scene_draws(original));
    VT_ASSIGN_OR_RETURN(SceneDraws virt, virtual_scene_draws(baked));
    std::shared_ptr<const PageSource> file = std::move(f.pages);
    auto source = std::make_shared<EditedSource>(file, edit);
    RenderOptions ro;
    ro.width = 1280;
    ro.height = 720;
    VT_ASSIGN_OR_RETURN(std::unique_ptr<Renderer> renderer, Renderer::create(*ctx_, ro));
    VT_RETURN_IF_ERROR(renderer->set_meshes(virt.meshes));
    VT_RETURN_IF_ERROR(renderer->set_reference_meshes(ref.meshes));
    VT_RETURN_IF_ERROR(renderer->set_reference_textures(ref.textures));
    const Vec3f centre = (ref.bounds_min + ref.bounds_max) * 0.5f;
    const auto cameras =
        orbit_views(centre + (ref.bounds_min - centre) * distance,
                    centre + (ref.bounds_max - centre) * distance, 3, 1280.0f / 720.0f);
    ValidateOptions vo;
    vo.layer = f.albedo;
    vo.address_mode = f.reader->layers()[vo.layer].address_mode;
    vo.thresholds = scene_thresholds();
    vo.exact_meshes = virt.meshes;
    if (cache_only) vo.exact_levels = file;
    return validate_views(*renderer, source, cameras, vo);
  }

  static std::string dir_, setup_error_;
  std::unique_ptr<VulkanContext> ctx_;
};
std::string StreamingCheck::dir_, StreamingCheck::setup_error_;

const EditedSource::Edit kNoEdit = [](const PageId&, uint32_t, std::span<uint8_t>) {};

// Zeroes the 4-texel border of a 128 x 128 upload: texels, or for BC the outer ring of blocks.
void zero_border(std::span<uint8_t> bytes, RuntimeFormat format) {
  constexpr uint32_t S = 128, B = 4;
  const RuntimeFormatInfo& info = *runtime_format_info(format);
  const uint32_t unit = info.bc ? 4 : 1, n = S / unit, ring = B / unit;
  const size_t bpu = bytes.size() / (size_t(n) * n);
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x)
      if (x < ring || y < ring || x >= n - ring || y >= n - ring)
        std::memset(&bytes[(size_t(y) * n + x) * bpu], 0, bpu);
}

std::string failures(const ValidationReport& r) {
  std::string s;
  for (const ViewReport& v : r.views)
    for (const std::string& f : v.failures) s += "view " + std::to_string(v.view) + ": " + f + "\n";
  return s;
}

bool exact_failed(const ValidationReport& r) {
  for (const StreamingViewResult& v : r.exact.views)
    if (!v.failures.empty()) return true;
  return false;
}

// Both checks per view, for docs/BENCHMARKS.md.
void print_views(const char* what, const ValidationReport& r) {
  for (const ViewReport& v : r.views) {
    const StreamingViewMetrics& e = r.exact.views[v.view].metrics;
    std::printf("%s, view %u: loose %.2f dB / tile %.2f dB, exact max %d, %.2f dB, beyond %.4f%%\n",
                what, v.view, v.metrics.psnr_rgb, v.metrics.worst_tile_psnr, e.max_abs, e.psnr,
                100 * e.share_beyond);
  }
}

TEST_F(StreamingCheck, CorrectBakesAgreeWithTheirLevelsToRounding) {
  for (const char* codec : {"dct", "bc", "raw"}) {
    auto r = validate(codec, kNoEdit);
    ASSERT_TRUE(r.ok()) << codec << ": " << r.status().message();
    EXPECT_TRUE(r->passed()) << codec << ":\n" << failures(*r);
    ASSERT_TRUE(r->exact.ran) << r->exact.note;
    EXPECT_EQ(r->exact.first_level, 0u);
    ASSERT_EQ(r->exact.views.size(), 3u);
    for (const StreamingViewResult& v : r->exact.views) {
      EXPECT_GT(v.metrics.pixels, 5000u) << codec;
      EXPECT_LE(v.metrics.share_beyond, r->exact.bounds.max_share_beyond) << codec;
      EXPECT_GE(v.metrics.psnr, 55.0) << codec;
      std::printf("%s: %s %llu px, max %d, %.2f dB, beyond %.4f%%, tile %.2f dB, %.1f ms\n", codec,
                  r->cache_format.c_str(), (unsigned long long)v.metrics.pixels, v.metrics.max_abs,
                  v.metrics.psnr, 100 * v.metrics.share_beyond, v.metrics.worst_tile_psnr,
                  v.render_ms + v.compare_ms);
    }
    const nlohmann::json j = to_json(r->exact);
    EXPECT_TRUE(j["ran"].get<bool>());
    EXPECT_EQ(j["views"].size(), 3u);
    EXPECT_TRUE(j["views"][0]["passed"].get<bool>());
  }
}

TEST_F(StreamingCheck, ZeroedBordersInTheCacheFail) {
  // Every page of levels 0 and 1 reaches the cache with its border zeroed (RGBA8 texels or, for
  // BC, the border's blocks: the 4-texel border is exactly one block row or column).
  auto opened = PageFileReader::open(dir_ + "/raw.vtpf");
  ASSERT_TRUE(opened.ok());
  std::shared_ptr<const PageFileReader> reader = std::move(*opened);
  auto plain = make_page_file_source(reader, {});
  ASSERT_TRUE(plain.ok());
  const uint32_t layer = albedo(*reader);
  const RuntimeFormat format = (*plain)->upload_format(layer);
  const bool as_rgba8 = ctx_->is_lavapipe() && format == RuntimeFormat::kBc7;
  auto r = validate("raw", [&](const PageId& id, uint32_t l, std::span<uint8_t> bytes) {
    if (id.level <= 1 && l == layer) zero_border(bytes, as_rgba8 ? RuntimeFormat::kRgba8 : format);
  });
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_FALSE(r->passed());
  EXPECT_TRUE(exact_failed(*r)) << failures(*r);
  print_views("zeroed borders", *r);
}

TEST_F(StreamingCheck, APageReplacedByItsNeighbourInTheCacheFails) {
  // The cache receives level-0 page (2, 1) in place of (1, 1) (a page-table or cache fault: the
  // level texture holds the file's pages), so the page's interior shows the wrong texels. The
  // same page swapped in the file itself differs only at its seams, within the codec's border
  // tolerance here; the atlas check catches that one (test_atlas_check.cpp).
  auto file = open_file("raw");
  ASSERT_TRUE(file.ok()) << file.status().message();
  const PageSource& truth = *file->pages;
  const uint32_t layer = file->albedo;
  auto r = validate(
      "raw",
      [&](const PageId& id, uint32_t l, std::span<uint8_t> bytes) {
        const PageId next{0, id.x + 1, id.y};
        if (!(id == PageId{0, 1, 1}) || l != layer) return;
        if (truth.geometry().contains(next) && truth.present(next)) {
          EXPECT_TRUE(truth.load(next, l, bytes).ok());
        }
      },
      /*cache_only=*/true);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(exact_failed(*r)) << failures(*r);
  print_views("neighbour page", *r);
}

// The coarsest level of a 9-page atlas (1,080 texels: level 4 is 68 texels, a Vulkan mip of
// level 0 would be 67) reaches the cache wrong: its one page replaced by a page of level 3 (a
// cache fault; the level texture holds the file). Views from far away want levels 3 and 4.
// The check held only the levels that halve as Vulkan mips (0-3) before, excluded every pixel
// wanting level 4 and could not see this page.
TEST_F(StreamingCheck, AWrongPageOfALevelThatHalvesWithCeilFails) {
  auto file = open_file("raw9");
  ASSERT_TRUE(file.ok()) << file.status().message();
  const PageGeometry& g = file->reader->geometry();
  ASSERT_EQ(g.level_count(), 5u);
  ASSERT_EQ(g.level_width(4), 68u);
  const PageSource& truth = *file->pages;
  const uint32_t layer = file->albedo;

  auto correct = validate("raw9", kNoEdit, /*cache_only=*/false, /*distance=*/12.0f);
  ASSERT_TRUE(correct.ok()) << correct.status().message();
  EXPECT_EQ(correct->exact.levels_held, 5u);
  EXPECT_FALSE(exact_failed(*correct)) << failures(*correct);
  uint64_t compared = 0;
  for (const StreamingViewResult& v : correct->exact.views) {
    compared += v.metrics.pixels;
    EXPECT_EQ(v.metrics.excluded_coarse, 0u);
  }
  EXPECT_GT(compared, 1000u);
  print_views("far views", *correct);

  auto wrong = validate(
      "raw9",
      [&](const PageId& id, uint32_t l, std::span<uint8_t> bytes) {
        if (id.level == 4 && l == layer) EXPECT_TRUE(truth.load(PageId{3, 0, 0}, l, bytes).ok());
      },
      /*cache_only=*/true, /*distance=*/12.0f);
  ASSERT_TRUE(wrong.ok()) << wrong.status().message();
  EXPECT_TRUE(exact_failed(*wrong)) << failures(*wrong);
  bool differs = false;
  for (const StreamingViewResult& v : wrong->exact.views)
    for (const std::string& f : v.failures) differs |= f.find("largest difference") != f.npos;
  EXPECT_TRUE(differs) << failures(*wrong);
  print_views("level 4 page wrong", *wrong);
}

}  // namespace
}  // namespace vt::render
