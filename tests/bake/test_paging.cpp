// The border rule, proven on every page of every level: each page texel (payload, border and
// padding alike) equals the texel the address mode gives in the level image reassembled from the
// pages' payloads. Raw codec, so the comparison is bit-exact.
#include <gtest/gtest.h>

#include <cstring>

#include "samples/procedural.h"
#include "tests/bake/bake_test_util.h"

namespace vt {
namespace {

struct BorderCase {
  uint32_t width, height, payload, border;
  AddressMode mode;
  bool float_texels;
};

std::string case_name(const testing::TestParamInfo<BorderCase>& info) {
  const BorderCase& c = info.param;
  return std::to_string(c.width) + "x" + std::to_string(c.height) + "_p" +
         std::to_string(c.payload) + "_b" + std::to_string(c.border) +
         (c.mode == AddressMode::kWrap ? "_wrap" : "_clamp") + (c.float_texels ? "_f32" : "_u8");
}

std::shared_ptr<ImageSource> noise_source(uint32_t w, uint32_t h, bool is_float) {
  // Texel-level noise so that any misplaced texel shows.
  ProceduralImageSource src(ProceduralPattern::kAlbedo, w, h, 3, 7);
  std::vector<float> texels(size_t(w) * h * 3);
  EXPECT_TRUE(src.read_rows(0, h, texels.data()).ok());
  ImageInfo info = src.info();
  if (is_float) {
    info.is_float = true;
    info.color_space = "linear";
    for (size_t i = 0; i < texels.size(); ++i) texels[i] = texels[i] * 3.7f + float(i % 5) * 0.01f;
  }
  return std::make_shared<MemoryImageSource>(info, std::move(texels));
}

class BorderRule : public testing::TestWithParam<BorderCase> {};

TEST_P(BorderRule, EveryPageOfEveryLevel) {
  const BorderCase& c = GetParam();
  BuildOptions o;
  o.layers.push_back(
      test::layer_input(LayerSemantic::kAlbedo, noise_source(c.width, c.height, c.float_texels)));
  o.codec.codec = CodecKind::kRaw;
  o.payload = c.payload;
  o.border = c.border;
  o.address = c.mode;
  o.threads = 2;
  auto built = test::build_in_memory(o);
  ASSERT_TRUE(built);
  const PageGeometry& g = built->desc.geometry;
  PageEncoder enc = test::encoder_for(*built, 0, o);
  const uint32_t tb = built->desc.layers[0].texel_bytes();
  EXPECT_EQ(built->desc.layers[0].texel_type, c.float_texels ? TexelType::kF32 : TexelType::kU8);
  const uint32_t S = g.page_size();
  uint64_t checked = 0;
  for (uint32_t l = 0; l < g.level_count(); ++l) {
    const int64_t lw = g.level_width(l), lh = g.level_height(l);
    auto level = test::reassemble_level(*built, 0, l, enc);
    for (uint32_t py = 0; py < g.pages_y(l); ++py) {
      for (uint32_t px = 0; px < g.pages_x(l); ++px) {
        PageId id{l, px, py};
        auto t = test::page_texels(*built, 0, id, enc);
        ASSERT_FALSE(t.empty()) << "page missing";
        for (uint32_t j = 0; j < S; ++j) {
          int64_t y = address_texel(g.page_origin_y(id) + j, lh, c.mode);
          for (uint32_t i = 0; i < S; ++i) {
            int64_t x = address_texel(g.page_origin_x(id) + i, lw, c.mode);
            ASSERT_EQ(0, std::memcmp(&t[(size_t(j) * S + i) * tb], &level[(y * lw + x) * tb], tb))
                << "level " << l << " page (" << px << ", " << py << ") texel (" << i << ", " << j
                << ")";
            ++checked;
          }
        }
      }
    }
  }
  EXPECT_EQ(checked, g.total_pages() * S * S);
  EXPECT_EQ(built->summary.absent, 0u);
  EXPECT_EQ(built->summary.pages, g.total_pages());
}

INSTANTIATE_TEST_SUITE_P(Sizes, BorderRule,
                         testing::Values(BorderCase{64, 64, 8, 4, AddressMode::kClamp, false},
                                         BorderCase{64, 64, 8, 4, AddressMode::kWrap, false},
                                         BorderCase{70, 45, 8, 4, AddressMode::kClamp, false},
                                         BorderCase{70, 45, 8, 4, AddressMode::kWrap, false},
                                         BorderCase{96, 48, 24, 4, AddressMode::kWrap, true},
                                         BorderCase{101, 37, 24, 4, AddressMode::kClamp, true},
                                         BorderCase{101, 37, 24, 4, AddressMode::kWrap, true},
                                         BorderCase{5, 3, 8, 4, AddressMode::kWrap, false},
                                         BorderCase{250, 130, 120, 4, AddressMode::kClamp, false},
                                         BorderCase{240, 120, 120, 4, AddressMode::kWrap, false}),
                         case_name);

// The pipeline's streamed levels equal the whole-level reference filter (float raw: exact).
TEST(Pyramid, StreamedLevelsEqualWholeLevelFilter) {
  for (MipFilter f : {MipFilter::kBox, MipFilter::kKaiser, MipFilter::kLanczos3}) {
    for (AddressMode m : {AddressMode::kClamp, AddressMode::kWrap}) {
      BuildOptions o;
      o.layers.push_back(
          test::layer_input(LayerSemantic::kCustom, noise_source(83, 59, true), "data"));
      o.codec.codec = CodecKind::kRaw;
      o.payload = 8;
      o.filter = f;
      o.address = m;
      auto built = test::build_in_memory(o);
      ASSERT_TRUE(built);
      PageEncoder enc = test::encoder_for(*built, 0, o);
      const PageGeometry& g = built->desc.geometry;
      DownsampleKernel k = make_downsample_kernel(f);
      DownsampleRules rules;
      rules.address = m;
      auto prev = test::as_floats(test::reassemble_level(*built, 0, 0, enc));
      for (uint32_t l = 1; l < g.level_count(); ++l) {
        auto expect =
            downsample_level(k, rules, prev.data(), g.level_width(l - 1), g.level_height(l - 1), 3);
        auto got = test::as_floats(test::reassemble_level(*built, 0, l, enc));
        ASSERT_EQ(expect.size(), got.size());
        ASSERT_EQ(0, std::memcmp(expect.data(), got.data(), got.size() * 4))
            << to_string(f) << " " << to_string(m) << " level " << l;
        prev = got;
      }
    }
  }
}

// cut_page on a band equals cut_page_from_level on the whole level.
TEST(Paging, CutPageMatchesWholeLevel) {
  PageGeometry g{29, 17, 8, 4};
  ASSERT_TRUE(g.validate().ok());
  std::vector<float> level(29 * 17 * 2);
  for (size_t i = 0; i < level.size(); ++i) level[i] = float(i);
  for (AddressMode m : {AddressMode::kClamp, AddressMode::kWrap}) {
    for (uint32_t py = 0; py < g.pages_y(0); ++py) {
      for (uint32_t px = 0; px < g.pages_x(0); ++px) {
        PageId id{0, px, py};
        std::vector<float> page(16 * 16 * 2);
        cut_page_from_level(g, id, m, level.data(), 2, page.data());
        for (uint32_t j = 0; j < 16; ++j) {
          for (uint32_t i = 0; i < 16; ++i) {
            int64_t x = address_texel(g.page_origin_x(id) + i, 29, m);
            int64_t y = address_texel(g.page_origin_y(id) + j, 17, m);
            ASSERT_EQ(page[(j * 16 + i) * 2 + 1], level[(y * 29 + x) * 2 + 1]);
          }
        }
      }
    }
  }
}

}  // namespace
}  // namespace vt
