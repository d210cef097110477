// UDIM grids: tiles found by number, placed in the grid, missing tiles black, mismatched tiles a
// clear error naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "bake/build.h"
#include "bake/image_source.h"
#include "format/page_file.h"
#include "format/page_file_inspect.h"
#include "tests/bake/bake_test_util.h"
#include "tests/transfer/scratch_dir.h"

namespace vt {
namespace {

namespace fs = std::filesystem;

// An 8-bit tile whose texels depend on the tile number, so misplaced tiles are caught.
std::vector<float> tile_texels(uint32_t w, uint32_t h, uint32_t ch, uint32_t udim) {
  std::vector<float> t(size_t(w) * h * ch);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x)
      for (uint32_t c = 0; c < ch; ++c)
        t[(size_t(y) * w + x) * ch + c] = float((x * 11 + y * 5 + c * 70 + udim * 37) % 256) / 255;
  return t;
}

Status write_tile(const fs::path& path, uint32_t w, uint32_t h, uint32_t ch, uint32_t udim) {
  ImageInfo info;
  info.width = w, info.height = h, info.channels = ch, info.color_space = "sRGB";
  MemoryImageSource src(info, tile_texels(w, h, ch, udim));
  return write_image_file(src, path.string());
}

TEST(Udim, GridAssembledExactlyWithMissingTilesBlack) {
  test::ScratchDir dir;
  const uint32_t tw = 20, th = 14;
  // u 0..2 on row v = 0, u 0 on row v = 1; (1, 1) and (2, 1) are missing. A decoy file with
  // another prefix must be ignored.
  for (uint32_t n : {1001u, 1002u, 1003u, 1011u})
    ASSERT_TRUE(write_tile(dir.file("tex." + std::to_string(n) + ".png"), tw, th, 3, n).ok());
  ASSERT_TRUE(write_tile(dir.file("other.1004.png"), tw, th, 3, 1004).ok());

  auto src = open_udim_image(dir.file("tex.<UDIM>.png"));
  ASSERT_TRUE(src.ok()) << src.status().message();
  ASSERT_EQ((*src)->info().width, 3 * tw);
  ASSERT_EQ((*src)->info().height, 2 * th);
  ASSERT_EQ((*src)->info().channels, 3u);
  const uint32_t w = 3 * tw, h = 2 * th;
  auto expected = [&](uint32_t x, uint32_t y, uint32_t c) -> uint8_t {
    uint32_t u = x / tw, v = y / th, n = 1001 + u + 10 * v;
    if (v == 1 && u > 0) return 0;
    float f = tile_texels(tw, th, 3, n)[(size_t(y % th) * tw + x % tw) * 3 + c];
    return uint8_t(std::lround(f * 255));
  };

  BuildOptions o;
  o.layers.push_back(
      test::layer_input(LayerSemantic::kAlbedo, std::shared_ptr<ImageSource>(std::move(*src))));
  o.payload = 24;  // pages straddle tile edges
  o.codec.codec = CodecKind::kRaw;
  o.output = dir.file("grid.vtpf");
  auto sum = build_page_file(o);
  ASSERT_TRUE(sum.ok()) << sum.status().message();

  test::expect_level0_rgb(o.output, w, h, expected);
}

TEST(Udim, MismatchedOrMissingTilesAreClearErrors) {
  test::ScratchDir dir;
  ASSERT_TRUE(write_tile(dir.file("t.1001.png"), 16, 16, 3, 1001).ok());
  ASSERT_TRUE(write_tile(dir.file("t.1002.png"), 16, 8, 3, 1002).ok());
  auto src = open_udim_image(dir.file("t.<UDIM>.png"));
  ASSERT_FALSE(src.ok());
  EXPECT_NE(src.status().message().find("t.1002.png"), std::string::npos) << src.status().message();

  ASSERT_TRUE(write_tile(dir.file("c.1001.png"), 16, 16, 3, 1001).ok());
  ASSERT_TRUE(write_tile(dir.file("c.1002.png"), 16, 16, 4, 1002).ok());
  src = open_udim_image(dir.file("c.<UDIM>.png"));
  ASSERT_FALSE(src.ok());
  EXPECT_NE(src.status().message().find("c.1002.png"), std::string::npos);

  src = open_udim_image(dir.file("none.<UDIM>.png"));
  ASSERT_FALSE(src.ok());
  EXPECT_NE(src.status().message().find("none.<UDIM>.png"), std::string::npos);
}

}  // namespace
}  // namespace vt
