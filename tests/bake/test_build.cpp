// The build pipeline end to end: non-finite policies, coverage and absent pages, determinism
// across thread counts, the out-of-core path, codecs, and a file written and read back.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "format/page_file.h"
#include "format/page_file_inspect.h"
#include "samples/procedural.h"
#include "tests/bake/bake_test_util.h"
#include "tests/scene/bmp_tga_files.h"
#include "tests/scene/pcx_files.h"

namespace vt {
namespace {

namespace fs = std::filesystem;

std::shared_ptr<ImageSource> procedural(uint32_t w, uint32_t h, uint32_t ch = 3,
                                        ProceduralPattern p = ProceduralPattern::kAlbedo) {
  return std::make_shared<ProceduralImageSource>(p, w, h, ch, 11);
}

std::shared_ptr<ImageSource> memory_image(uint32_t w, uint32_t h, uint32_t ch,
                                          std::vector<float> texels, bool is_float) {
  ImageInfo info;
  info.width = w, info.height = h, info.channels = ch, info.is_float = is_float;
  info.color_space = is_float ? "linear" : "sRGB";
  return std::make_shared<MemoryImageSource>(info, std::move(texels));
}

// A build of one albedo layer from the image file at `path`: 24-texel payloads, `codec`.
Expected<BuildOptions> albedo_file_build(const std::string& path, CodecKind codec) {
  VT_ASSIGN_OR_RETURN(std::unique_ptr<ImageSource> src, open_image_file(path));
  BuildOptions o;
  o.layers.push_back(test::layer_input(LayerSemantic::kAlbedo, std::move(src)));
  o.payload = 24;
  o.codec.codec = codec;
  return o;
}

fs::path temp_dir() {
  fs::path d =
      fs::temp_directory_path() / ("vt_bake_tests_" + std::to_string(getpid()) + "_" +
                                   testing::UnitTest::GetInstance()->current_test_info()->name());
  fs::create_directories(d);
  return d;
}

class NonFinite : public testing::Test {
 protected:
  BuildOptions options(NonFinitePolicy policy) {
    const uint32_t w = 20, h = 12;
    std::vector<float> t(w * h * 3, 0.5f);
    t[(3 * w + 5) * 3 + 1] = std::numeric_limits<float>::quiet_NaN();
    t[(3 * w + 7) * 3 + 0] = std::numeric_limits<float>::infinity();
    t[(10 * w + 2) * 3 + 2] = -1.0f;
    t[(11 * w + 19) * 3 + 0] = -std::numeric_limits<float>::infinity();
    BuildOptions o;
    o.layers.push_back(test::layer_input(LayerSemantic::kAlbedo, memory_image(w, h, 3, t, true)));
    o.codec.codec = CodecKind::kRaw;
    o.payload = 8;
    o.non_finite = policy;
    return o;
  }
};

TEST_F(NonFinite, BlackReportsAndZeroes) {
  BuildOptions o = options(NonFinitePolicy::kBlack);
  auto b = test::build_in_memory(o);
  ASSERT_TRUE(b);
  const NonFiniteReport& r = b->summary.layers[0].non_finite;
  EXPECT_EQ(r.non_finite, 3u);
  EXPECT_EQ(r.negative, 1u);
  EXPECT_EQ(r.first_x, 5u);
  EXPECT_EQ(r.first_y, 3u);
  EXPECT_EQ(r.first_channel, 1u);
  auto level = test::as_floats(test::reassemble_level(*b, 0, 0, test::encoder_for(*b, 0, o)));
  EXPECT_EQ(level[(3 * 20 + 5) * 3 + 1], 0.0f);
  EXPECT_EQ(level[(3 * 20 + 7) * 3 + 0], 0.0f);
  EXPECT_EQ(level[(10 * 20 + 2) * 3 + 2], 0.0f);
  for (uint32_t l = 0; l < b->desc.geometry.level_count(); ++l) {
    for (float v : test::as_floats(test::reassemble_level(*b, 0, l, test::encoder_for(*b, 0, o)))) {
      ASSERT_TRUE(std::isfinite(v) && v >= 0);
    }
  }
}

TEST_F(NonFinite, ClampKeepsInfinityAsLargestFloat) {
  BuildOptions o = options(NonFinitePolicy::kClamp);
  auto b = test::build_in_memory(o);
  ASSERT_TRUE(b);
  auto enc = test::encoder_for(*b, 0, o);
  auto level = test::as_floats(test::reassemble_level(*b, 0, 0, enc));
  EXPECT_EQ(level[(3 * 20 + 7) * 3 + 0], std::numeric_limits<float>::max());
  EXPECT_EQ(level[(3 * 20 + 5) * 3 + 1], 0.0f);
  EXPECT_EQ(level[(11 * 20 + 19) * 3 + 0], 0.0f);
  for (uint32_t l = 1; l < b->desc.geometry.level_count(); ++l) {
    for (float v : test::as_floats(test::reassemble_level(*b, 0, l, enc))) {
      ASSERT_TRUE(std::isfinite(v));  // float max through a filter never overflows
    }
  }
}

TEST_F(NonFinite, ErrorNamesTheFirstTexel) {
  BuildOptions o = options(NonFinitePolicy::kError);
  // The plan's training read does not judge texels; the build's one pass does, in raster order.
  auto plan = plan_build(o);
  ASSERT_TRUE(plan.ok());
  test::MemorySink sink;
  auto sum = build_pages(*plan, sink);
  ASSERT_FALSE(sum.ok());
  EXPECT_EQ(sum.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(sum.status().message().find("(5, 3)"), std::string::npos) << sum.status().message();
  EXPECT_FALSE(parse_non_finite_policy("zero").ok());
}

TEST(Build, IdenticalForAnyThreadCountAndOutOfCore) {
  BuildOptions o;
  o.layers.push_back(test::layer_input(LayerSemantic::kAlbedo, procedural(203, 150, 4)));
  o.payload = 24;
  o.codec.codec = CodecKind::kDct;
  o.threads = 1;
  auto one = test::build_in_memory(o);
  o.threads = 5;
  auto five = test::build_in_memory(o);
  o.memory_limit = 1;  // every level past 0 goes to a scratch file
  o.scratch_dir = fs::temp_directory_path().string();
  auto ooc = test::build_in_memory(o);
  ASSERT_TRUE(one && five && ooc);
  EXPECT_FALSE(one->summary.levels[1].scratch);
  EXPECT_TRUE(ooc->summary.levels[1].scratch);
  EXPECT_GT(ooc->summary.scratch_bytes, 0u);
  EXPECT_EQ(one->sink.pages.size(), one->summary.stored + one->summary.constant);
  for (const auto* other : {five.get(), ooc.get()}) {
    ASSERT_EQ(one->sink.pages.size(), other->sink.pages.size());
    for (const auto& [key, page] : one->sink.pages) {
      auto it = other->sink.pages.find(key);
      ASSERT_NE(it, other->sink.pages.end());
      ASSERT_EQ(page.state, it->second.state);
      ASSERT_EQ(page.bytes, it->second.bytes);
    }
  }
  EXPECT_EQ(one->desc.layers[0].codec_tables, five->desc.layers[0].codec_tables);
}

TEST(Build, DctTablesAreTrainedOnTheLayersOwnPages) {
  BuildOptions o;
  LayerInput in;
  in.source = procedural(600, 480, 3);  // 5 x 4 level-0 pages: fewer than a training set
  o.layers.push_back(in);
  o.codec.codec = CodecKind::kDct;
  auto b = test::build_in_memory(o);
  ASSERT_TRUE(b);
  // The header the writer starts from already holds the trained tables.
  const auto& trained_bytes = b->desc.layers[0].codec_tables;
  LayerSpec untrained_spec = b->desc.layers[0];
  ASSERT_TRUE(PageEncoder::create(untrained_spec, o.codec, b->desc.geometry.page_size()).ok());
  EXPECT_NE(trained_bytes, untrained_spec.codec_tables);
  EXPECT_EQ(b->summary.layers[0].spec.codec_tables, trained_bytes);
  auto trained = dct_parse_tables(trained_bytes);
  auto untrained = dct_parse_tables(untrained_spec.codec_tables);
  ASSERT_TRUE(trained.ok() && untrained.ok());
  // Every stored page decodes with the file's tables, and the same texels cost fewer bytes with
  // them than with the untrained ones.
  const int S = int(b->desc.geometry.page_size());
  size_t with_trained = 0, with_untrained = 0;
  for (const auto& [key, page] : b->sink.pages) {
    if (page.state != PageState::kStored) continue;
    std::vector<uint8_t> texels(size_t(S) * S * 3), again;
    ASSERT_TRUE(dct_decode_page(**trained, page.bytes, S, S, texels.data()).ok());
    ASSERT_TRUE(dct_encode_page(**trained, texels.data(), S, S, again).ok());
    with_trained += again.size();
    ASSERT_TRUE(dct_encode_page(**untrained, texels.data(), S, S, again).ok());
    with_untrained += again.size();
  }
  EXPECT_GT(with_trained, 0u);
  EXPECT_LT(with_trained, with_untrained);
  EXPECT_GT(b->summary.layers[0].psnr_db, 28.5);  // 29.4 measured; training changes only bytes
}

TEST(Build, WrapOutOfCoreMatchesInMemory) {
  BuildOptions o;
  o.layers.push_back(test::layer_input(LayerSemantic::kAlbedo, procedural(77, 131, 3)));
  o.payload = 8;
  o.codec.codec = CodecKind::kRaw;
  o.address = AddressMode::kWrap;
  o.filter = MipFilter::kLanczos3;
  auto mem = test::build_in_memory(o);
  o.memory_limit = 1;
  o.scratch_dir = fs::temp_directory_path().string();
  auto ooc = test::build_in_memory(o);
  ASSERT_TRUE(mem && ooc);
  for (const auto& [key, page] : mem->sink.pages) {
    ASSERT_EQ(page.bytes, ooc->sink.pages.at(key).bytes);
  }
}

TEST(Build, ConstantPagesFoldedAndCoverageMakesAbsentPages) {
  const uint32_t w = 64, h = 32;
  std::vector<float> t(w * h * 3, 0.25f);
  auto cov = std::make_shared<std::vector<uint8_t>>(w * h, 0);
  for (uint32_t y = 2; y < 10; ++y) {
    for (uint32_t x = 3; x < 12; ++x) {
      (*cov)[y * w + x] = 1;
      t[(y * w + x) * 3 + 1] = 0.75f;  // the chart is greener than the background
    }
  }
  BuildOptions o;
  LayerInput in = test::layer_input(LayerSemantic::kAlbedo, memory_image(w, h, 3, t, false));
  in.coverage = CoverageMask::from_bytes(w, h, cov->data());
  o.layers.push_back(in);
  o.payload = 8;
  o.codec.codec = CodecKind::kRaw;
  auto b = test::build_in_memory(o);
  ASSERT_TRUE(b);
  const PageGeometry& g = b->desc.geometry;
  EXPECT_GT(b->summary.absent, 0u);
  EXPECT_EQ(b->summary.levels[0].stored + b->summary.levels[0].constant,
            4u);  // pages over x 0-1, y 0-1
  EXPECT_EQ(b->summary.pages, g.total_pages());
  // Pull-push: the background colour (green 0.25) never appears in a stored page.
  auto enc = test::encoder_for(*b, 0, o);
  for (const auto& [key, page] : b->sink.pages) {
    PageId id{std::get<1>(key), std::get<3>(key), std::get<2>(key)};
    auto tex = test::page_texels(*b, 0, id, enc);
    for (size_t i = 0; i < tex.size(); i += 3) {
      ASSERT_EQ(tex[i + 1], tex[1]) << "page " << id.level << "," << id.x << "," << id.y;
    }
  }
  // A plain constant image folds to constants only.
  BuildOptions c;
  c.layers.push_back(test::layer_input(
      LayerSemantic::kAlbedo, memory_image(w, h, 3, std::vector<float>(w * h * 3, 0.5f), false)));
  c.payload = 8;
  auto cb = test::build_in_memory(c);
  ASSERT_TRUE(cb);
  EXPECT_EQ(cb->summary.constant, g.total_pages());
  EXPECT_EQ(cb->summary.stored, 0u);
}

TEST(Build, CodecsAndLayers) {
  BuildOptions o;
  o.layers.push_back(test::layer_input(LayerSemantic::kAlbedo, procedural(96, 96, 3)));
  o.layers.push_back(
      test::layer_input(LayerSemantic::kNormal, procedural(96, 96, 3, ProceduralPattern::kNormal)));
  o.payload = 24;
  for (CodecKind k : {CodecKind::kDct, CodecKind::kBc}) {
    o.codec.codec = k;
    auto b = test::build_in_memory(o);
    ASSERT_TRUE(b);
    ASSERT_EQ(b->summary.layers.size(), 2u);
    EXPECT_EQ(b->desc.layers[0].color_space, ColorSpace::kSrgb);
    EXPECT_EQ(b->desc.layers[1].channels, 2);
    EXPECT_EQ(b->desc.layers[1].runtime_format, RuntimeFormat::kBc5);
    EXPECT_EQ(b->desc.layers[0].runtime_format, RuntimeFormat::kBc1);
    EXPECT_EQ(b->desc.layers[0].codec, k == CodecKind::kDct ? PageCodec::kDct : PageCodec::kBcZstd);
    for (const auto& l : b->summary.layers) {
      EXPECT_GT(l.psnr_db, 25.0) << l.name;
      EXPECT_LT(l.psnr_db, 80.0) << l.name;  // lossy codecs do lose something
    }
  }
  // Normal layer texels decode to unit-ish vectors with z >= 0.
  o.codec.codec = CodecKind::kRaw;
  auto b = test::build_in_memory(o);
  ASSERT_TRUE(b);
  auto enc = test::encoder_for(*b, 1, o);
  for (uint32_t l = 0; l < b->desc.geometry.level_count(); ++l) {
    auto lvl = test::reassemble_level(*b, 1, l, enc);
    for (size_t i = 0; i < lvl.size(); i += 2) {
      double x = lvl[i] / 127.5 - 1, y = lvl[i + 1] / 127.5 - 1;
      ASSERT_LE(x * x + y * y, 1.0 + 2 * 2.0 / 255);
    }
  }
}

TEST(Build, RejectsBadOptions) {
  BuildOptions o;
  EXPECT_FALSE(plan_build(o).ok());
  o.layers.push_back(test::layer_input(LayerSemantic::kAlbedo, procedural(16, 16)));
  o.layers.push_back(test::layer_input(LayerSemantic::kOrm, procedural(17, 16)));
  EXPECT_EQ(plan_build(o).status().code(), ErrorCode::kInvalidArgument);
  o.layers.pop_back();
  o.payload = 9;  // page size not a multiple of 4
  EXPECT_FALSE(plan_build(o).ok());
  o.payload = 8;
  o.layers[0].color_space = "ProPhoto";
  EXPECT_EQ(plan_build(o).status().code(), ErrorCode::kNotFound);
}

TEST(Build, FileWrittenAndReadBack) {
  fs::path dir = temp_dir();
  // A PNG and a tiled EXR through OpenImageIO.
  ProceduralImageSource png_src(ProceduralPattern::kAlbedo, 150, 90, 4, 5);
  ASSERT_TRUE(write_image_file(png_src, (dir / "in.png").string()).ok());
  ProceduralImageSource exr_src(ProceduralPattern::kAlbedo, 150, 90, 3, 5);
  ImageInfo exr_info = exr_src.info();
  std::vector<float> exr_texels(150 * 90 * 3);
  ASSERT_TRUE(exr_src.read_rows(0, 90, exr_texels.data()).ok());
  exr_info.is_float = true;
  exr_info.color_space = "linear";
  MemoryImageSource exr_mem(exr_info, exr_texels);
  ASSERT_TRUE(write_image_file(exr_mem, (dir / "in.exr").string(), 32).ok());

  for (const char* name : {"in.png", "in.exr"}) {
    auto options = albedo_file_build((dir / name).string(), CodecKind::kRaw);
    ASSERT_TRUE(options.ok()) << options.status().message();
    BuildOptions o = *options;
    o.output = (dir / (std::string(name) + ".vtpf")).string();
    auto sum = build_page_file(o);
    ASSERT_TRUE(sum.ok()) << sum.status().message();
    EXPECT_GT(sum->file_bytes, 0u);

    // Same pages as an in-memory build of the same input.
    auto src2 = open_image_file((dir / name).string());
    ASSERT_TRUE(src2.ok());
    o.layers[0].source = std::shared_ptr<ImageSource>(std::move(src2).value());
    auto mem = test::build_in_memory(o);
    ASSERT_TRUE(mem);
    auto reader = PageFileReader::open(o.output);
    ASSERT_TRUE(reader.ok()) << reader.status().message();
    ASSERT_TRUE((*reader)->verify().ok());
    EXPECT_EQ((*reader)->geometry().width, 150u);
    EXPECT_EQ((*reader)->layers()[0].channels, std::string(name) == "in.png" ? 4 : 3);
    auto enc = test::encoder_for(*mem, 0, o);
    std::vector<uint8_t> got((*reader)->decoded_page_bytes(0));
    const PageGeometry& g = (*reader)->geometry();
    for (uint32_t l = 0; l < g.level_count(); ++l) {
      for (uint32_t y = 0; y < g.pages_y(l); ++y) {
        for (uint32_t x = 0; x < g.pages_x(l); ++x) {
          PageId id{l, x, y};
          ASSERT_TRUE((*reader)->read_texels(id, 0, got).ok());
          ASSERT_EQ(got, test::page_texels(*mem, 0, id, enc)) << name << " " << l;
        }
      }
    }
    // The PNG is sRGB 8-bit with alpha: a raw build keeps its opaque texels exactly.
    if (std::string(name) == "in.png") {
      std::vector<float> src_rows(150 * 90 * 4);
      ASSERT_TRUE(png_src.read_rows(0, 90, src_rows.data()).ok());
      auto lvl0 = test::reassemble_level(*mem, 0, 0, enc);
      size_t exact = 0, opaque = 0;
      for (size_t i = 0; i < 150 * 90; ++i) {
        if (src_rows[i * 4 + 3] < 1.0f) continue;
        ++opaque;
        bool same = true;
        for (int c = 0; c < 4; ++c)
          same &= lvl0[i * 4 + c] == uint8_t(std::lround(src_rows[i * 4 + c] * 255));
        exact += same;
      }
      EXPECT_GT(opaque, 0u);
      EXPECT_EQ(exact, opaque);
    }
  }
  fs::remove_all(dir);
}

// Alpha is stored only where some texel is not opaque: an all-255 alpha PNG builds an RGB
// (BC1) layer whose texels equal the colour channels; one texel at 254 keeps RGBA (BC3).
TEST(Build, OpaqueAlphaDropped) {
  fs::path dir = temp_dir();
  const uint32_t w = 40, h = 30;
  std::vector<float> texels(size_t(w) * h * 4);
  for (size_t i = 0; i < size_t(w) * h; ++i) {
    for (int c = 0; c < 3; ++c) texels[i * 4 + c] = float((i * 7 + size_t(c) * 61) % 256) / 255;
    texels[i * 4 + 3] = 1.0f;
  }
  ImageInfo info;
  info.width = w, info.height = h, info.channels = 4, info.alpha_channel = 3;
  info.color_space = "sRGB";
  for (bool translucent : {false, true}) {
    std::vector<float> t = texels;
    if (translucent) t[(size_t(17) * w + 23) * 4 + 3] = 254.0f / 255;
    MemoryImageSource mem(info, t);
    std::string png = (dir / (translucent ? "t.png" : "o.png")).string();
    ASSERT_TRUE(write_image_file(mem, png).ok());
    for (CodecKind codec : {CodecKind::kRaw, CodecKind::kBc}) {
      auto options = albedo_file_build(png, codec);
      ASSERT_TRUE(options.ok()) << options.status().message();
      BuildOptions o = *options;
      o.output = png + ".vtpf";
      auto sum = build_page_file(o);
      ASSERT_TRUE(sum.ok()) << sum.status().message();
      EXPECT_EQ(sum->layers[0].alpha_dropped, !translucent);
      auto reader = PageFileReader::open(o.output);
      ASSERT_TRUE(reader.ok()) << reader.status().message();
      const LayerSpec& spec = (*reader)->layers()[0];
      EXPECT_EQ(spec.channels, translucent ? 4 : 3);
      EXPECT_EQ(spec.runtime_format, translucent ? RuntimeFormat::kBc3 : RuntimeFormat::kBc1);
      if (codec != CodecKind::kRaw || translucent) continue;
      // Raw: the stored level-0 payload equals the PNG's RGB exactly.
      test::expect_level0_rgb(o.output, w, h, [&](uint32_t x, uint32_t y, uint32_t c) {
        return uint8_t(std::lround(t[(size_t(y) * w + x) * 4 + c] * 255));
      });
    }
  }
  fs::remove_all(dir);
}

// Colour under zero alpha is lost in the premultiplied working form; stored black, the run
// time's straight-colour filtering would darken every alpha edge. A half-transparent image whose
// transparent half is black stores the opaque half's colour there, at every level, alpha 0 kept.
TEST(Build, ColourUnderZeroAlphaIsTheEdgeColourNotBlack) {
  const uint32_t w = 40, h = 30, opaque_w = 26;  // every level-0 page (payload 24) has alpha
  const uint8_t colour[3] = {200, 120, 40};
  std::vector<float> t(size_t(w) * h * 4, 0.0f);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < opaque_w; ++x) {
      for (int c = 0; c < 3; ++c) t[(size_t(y) * w + x) * 4 + c] = colour[c] / 255.0f;
      t[(size_t(y) * w + x) * 4 + 3] = 1.0f;
    }
  ImageInfo info;
  info.width = w, info.height = h, info.channels = 4, info.alpha_channel = 3;
  info.color_space = "sRGB";
  BuildOptions o;
  o.layers.push_back(
      test::layer_input(LayerSemantic::kAlbedo, std::make_shared<MemoryImageSource>(info, t)));
  o.payload = 24;
  o.codec.codec = CodecKind::kRaw;  // Kaiser (the default): its overshoot must not show
  auto built = test::build_in_memory(o);
  ASSERT_TRUE(built);
  auto enc = test::encoder_for(*built, 0, o);
  const PageGeometry& g = built->desc.geometry;
  for (uint32_t l = 0; l < 2; ++l) {
    std::vector<uint8_t> present;
    auto level = test::reassemble_level(*built, 0, l, enc, &present);
    size_t transparent = 0;
    for (size_t i = 0; i < size_t(g.level_width(l)) * g.level_height(l); ++i) {
      ASSERT_TRUE(present[i]) << "level " << l << " texel " << i;
      for (int c = 0; c < 3; ++c) ASSERT_EQ(level[i * 4 + c], colour[c]) << l << " " << i;
      transparent += level[i * 4 + 3] == 0;
    }
    EXPECT_GT(transparent, 0u) << "level " << l;  // alpha 0 stays 0 where it was
  }
}

// PNG, TGA and SGI store straight colour: a translucent texel's colour is baked as stored, not
// as OpenImageIO's default read gives PNG and TGA (premultiplied, so a second premultiply
// darkened them), nor divided by alpha where a format has no word on it (SGI).
TEST(Build, TranslucentTexelsKeepTheirColour) {
  fs::path dir = temp_dir();
  const uint32_t w = 8, h = 8;
  const uint8_t texel[4] = {100, 40, 190, 40};
  std::vector<float> t(size_t(w) * h * 4);
  for (size_t i = 0; i < size_t(w) * h; ++i)
    for (int c = 0; c < 4; ++c) t[i * 4 + c] = (i % 2 ? 255 : texel[c]) / 255.0f;
  ImageInfo info;
  info.width = w, info.height = h, info.channels = 4, info.alpha_channel = 3;
  info.color_space = "sRGB";
  MemoryImageSource mem(info, t);
  for (const char* name : {"translucent.png", "translucent.tga", "translucent.sgi"}) {
    const std::string path = (dir / name).string();
    ASSERT_TRUE(write_image_file(mem, path).ok()) << name;
    auto options = albedo_file_build(path, CodecKind::kRaw);
    ASSERT_TRUE(options.ok()) << options.status().message();
    const BuildOptions& o = *options;
    auto built = test::build_in_memory(o);
    ASSERT_TRUE(built);
    auto level = test::reassemble_level(*built, 0, 0, test::encoder_for(*built, 0, o));
    for (size_t i = 0; i < size_t(w) * h; ++i)
      for (int c = 0; c < 4; ++c)
        ASSERT_EQ(level[i * 4 + c], i % 2 ? 255 : texel[c]) << name << " " << i << " " << c;
  }
  fs::remove_all(dir);
}

// A BMP or TGA whose fourth byte is 0 everywhere holds no alpha (BI_RGB padding, a TGA header with
// no alpha bits): read as RGB, not as a fully transparent image. Alpha that is not 0 everywhere,
// and a zero alpha in formats that only store real alpha (PNG), stay.
TEST(Build, PaddingAlphaOfBmpAndTgaReadsOpaque) {
  fs::path dir = temp_dir();
  const uint32_t w = 5, h = 3;
  std::vector<uint8_t> rgba(size_t(w) * h * 4);
  for (size_t i = 0; i < size_t(w) * h; ++i)
    for (int c = 0; c < 3; ++c) rgba[i * 4 + c] = uint8_t(17 * i + 80 * c);
  auto check = [&](const std::string& path, uint32_t channels) {
    auto src = open_image_file(path);
    ASSERT_TRUE(src.ok()) << src.status().message();
    const ImageInfo& info = (*src)->info();
    ASSERT_EQ(info.channels, channels) << path;
    EXPECT_EQ(info.alpha_channel, channels == 4 ? 3 : -1) << path;
    std::vector<float> texels(size_t(w) * h * channels);
    ASSERT_TRUE((*src)->read_rows(0, h, texels.data()).ok());
    for (size_t i = 0; i < size_t(w) * h; ++i)
      for (uint32_t c = 0; c < channels; ++c)
        ASSERT_EQ(std::lround(texels[i * channels + c] * 255), rgba[i * 4 + c]) << path << " " << i;
  };
  const std::string bmp = (dir / "padding.bmp").string(), tga = (dir / "padding.tga").string();
  ASSERT_TRUE(test::write_bmp32(bmp, w, h, rgba));
  check(bmp, 3);
  for (uint8_t bits : {0, 8}) {
    ASSERT_TRUE(test::write_tga32(tga, w, h, rgba, bits));
    check(tga, 3);
  }
  rgba[7 * 4 + 3] = 1;  // one texel with alpha: the channel is alpha
  ASSERT_TRUE(test::write_bmp32(bmp, w, h, rgba));
  check(bmp, 4);
  ASSERT_TRUE(test::write_tga32(tga, w, h, rgba, 0));
  check(tga, 4);
  // Cut short: the alpha read fails, and the error is the file's (OpenImageIO's TGA reader would
  // answer the texels' reads from what it decoded before the end).
  ASSERT_TRUE(test::write_tga32(tga, w, h, rgba, 0));
  fs::resize_file(tga, 18 + 4 * w);
  auto cut = open_image_file(tga);
  ASSERT_FALSE(cut.ok());
  EXPECT_EQ(cut.status().code(), ErrorCode::kCorrupt);
  EXPECT_NE(cut.status().message().find("padding.tga"), std::string::npos)
      << cut.status().message();
  rgba[7 * 4 + 3] = 0;
  std::vector<float> zero_alpha(rgba.begin(), rgba.end());
  for (float& v : zero_alpha) v /= 255;
  ImageInfo info;
  info.width = w, info.height = h, info.channels = 4, info.alpha_channel = 3;
  MemoryImageSource mem(info, zero_alpha);
  const std::string png = (dir / "transparent.png").string();
  ASSERT_TRUE(write_image_file(mem, png).ok());
  check(png, 4);
  fs::remove_all(dir);
}

// OpenEXR stores colour premultiplied: written so, and divided out again when read, so that an
// EXR reads as straight colour like every other file.
TEST(Build, ExrColourIsPremultipliedInTheFileAndStraightWhenRead) {
  fs::path dir = temp_dir();
  const std::vector<float> t = {0.8f, 0.4f, 0.2f, 0.25f, 2.0f, 1.0f, 0.5f, 1.0f};  // 2 x 1
  ImageInfo info;
  info.width = 2, info.height = 1, info.channels = 4, info.alpha_channel = 3;
  info.is_float = true;
  info.color_space = "linear";
  MemoryImageSource mem(info, t);
  const std::string exr = (dir / "translucent.exr").string();
  ASSERT_TRUE(write_image_file(mem, exr).ok());
  {
    auto raw = OIIO::ImageInput::open(exr);
    ASSERT_TRUE(raw);
    std::vector<float> stored(8);
    ASSERT_TRUE(raw->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, stored.data()));
    EXPECT_NEAR(stored[0], 0.8f * 0.25f, 1e-3f);  // half floats
    EXPECT_NEAR(stored[4], 2.0f, 1e-3f);
  }
  auto src = open_image_file(exr);
  ASSERT_TRUE(src.ok()) << src.status().message();
  std::vector<float> back(8);
  ASSERT_TRUE((*src)->read_rows(0, 1, back.data()).ok());
  for (size_t i = 0; i < t.size(); ++i) EXPECT_NEAR(back[i], t[i], t[i] / 1024) << i;
  fs::remove_all(dir);
}

// A PCX image alone (OpenImageIO reads none): the scene importers' decoder, whatever the letter
// case of its extension; a file that is no PCX is refused naming it.
TEST(Build, PcxImagesAreRead) {
  fs::path dir = temp_dir();
  const std::string rgb = (dir / "skin.PCX").string(), paletted = (dir / "pal.pcx").string();
  std::ofstream(rgb, std::ios::binary) << test::pcx_rgb_3x1();
  std::ofstream(paletted, std::ios::binary) << test::pcx_paletted_3x2();
  auto src = open_image_file(rgb);
  ASSERT_TRUE(src.ok()) << src.status().message();
  ASSERT_EQ((*src)->info().width, 3u);
  ASSERT_EQ((*src)->info().channels, 3u);
  EXPECT_EQ((*src)->info().alpha_channel, -1);
  std::vector<float> texels(9);
  ASSERT_TRUE((*src)->read_rows(0, 1, texels.data()).ok());
  const int want[9] = {200, 40, 70, 20, 50, 80, 30, 60, 90};
  for (int i = 0; i < 9; ++i) EXPECT_EQ(std::lround(texels[i] * 255), want[i]) << i;
  auto pal = open_image_file(paletted);
  ASSERT_TRUE(pal.ok()) << pal.status().message();
  EXPECT_EQ((*pal)->info().height, 2u);
  std::ofstream(paletted, std::ios::binary) << "not a PCX image at all";
  auto bad = open_image_file(paletted);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("pal.pcx: not a readable PCX image"), std::string::npos)
      << bad.status().message();
  fs::remove_all(dir);
}

TEST(Build, MissingFileIsAClearError) {
  auto src = open_image_file("/nonexistent/dir/missing.exr");
  ASSERT_FALSE(src.ok());
  EXPECT_NE(src.status().message().find("missing.exr"), std::string::npos);
}

}  // namespace
}  // namespace vt

namespace vt {
namespace {

// Alpha-tested foliage: thin opaque blades on a transparent background fade away in plain
// mips; with coverage-preserving alpha each level keeps level 0's fraction above the reference.
TEST(Build, CoveragePreservingAlpha) {
  const uint32_t w = 128, h = 128;
  std::vector<float> t(w * h * 4, 0.0f);
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < w; ++x) {
      float* p = &t[(y * w + x) * 4];
      p[0] = 0.2f, p[1] = 0.6f, p[2] = 0.1f;
      p[3] = (x % 6 == 0 || (x + y / 3) % 11 == 0) ? 1.0f : 0.0f;
    }
  }
  auto fractions = [&](float reference) {
    BuildOptions o;
    o.layers.push_back(test::layer_input(LayerSemantic::kAlbedo, memory_image(w, h, 4, t, false)));
    o.codec.codec = CodecKind::kRaw;
    o.payload = 24;
    o.alpha_coverage_reference = reference;
    auto b = test::build_in_memory(o);
    EXPECT_TRUE(b);
    std::vector<double> f;
    if (!b) return f;
    auto enc = test::encoder_for(*b, 0, o);
    for (uint32_t l = 0; l < 4; ++l) {
      auto lvl = test::reassemble_level(*b, 0, l, enc);
      size_t above = 0;
      for (size_t i = 3; i < lvl.size(); i += 4) above += lvl[i] >= 128;
      f.push_back(double(above) / double(lvl.size() / 4));
    }
    return f;
  };
  auto plain = fractions(0);
  auto kept = fractions(0.5f);
  ASSERT_EQ(kept.size(), 4u);
  EXPECT_DOUBLE_EQ(plain[0], kept[0]);
  EXPECT_GT(kept[0], 0.2);
  for (uint32_t l = 1; l < 4; ++l) {
    EXPECT_NEAR(kept[l], kept[0], 0.06) << "level " << l;
  }
  EXPECT_GT(std::abs(plain[3] - plain[0]), std::abs(kept[3] - kept[0]));
}

}  // namespace
}  // namespace vt
