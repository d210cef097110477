// render::make_contact_sheet over a hand-made report and PNGs the test writes: every image a view
// lists becomes a thumbnail in its row, in order; failing views and heat maps are framed in red
// and failing pages outlined; the bitmap font draws exact glyphs. Also failure_lines and the
// report's new JSON keys. No Vulkan.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "render/contact_sheet.h"
#include "render/report.h"

namespace vt::render {
namespace {

Rgba8Image solid(uint32_t w, uint32_t h, Rgb8 c) {
  Rgba8Image img;
  img.width = w;
  img.height = h;
  img.texels.resize(size_t(w) * h * 4);
  for (size_t i = 0; i < size_t(w) * h; ++i) {
    img.texels[i * 4] = c.r, img.texels[i * 4 + 1] = c.g, img.texels[i * 4 + 2] = c.b;
    img.texels[i * 4 + 3] = 255;
  }
  return img;
}

bool is(const Rgba8Image& img, int x, int y, Rgb8 c) {
  const uint8_t* p = &img.texels[(size_t(y) * img.width + size_t(x)) * 4];
  return p[0] == c.r && p[1] == c.g && p[2] == c.b;
}

// Bounding box of the pixels of colour `c`: {x0, y0, x1, y1} inclusive; x0 = -1 when none.
std::array<int, 4> box_of(const Rgba8Image& img, Rgb8 c) {
  std::array<int, 4> b{-1, -1, -1, -1};
  for (int y = 0; y < int(img.height); ++y) {
    for (int x = 0; x < int(img.width); ++x) {
      if (!is(img, x, y, c)) continue;
      if (b[0] < 0) b = {x, y, x, y};
      b[0] = std::min(b[0], x), b[1] = std::min(b[1], y);
      b[2] = std::max(b[2], x), b[3] = std::max(b[3], y);
    }
  }
  return b;
}

int count_in_rows(const Rgba8Image& img, int y0, int y1, Rgb8 c) {
  int n = 0;
  for (int y = y0; y <= y1; ++y)
    for (int x = 0; x < int(img.width); ++x) n += is(img, x, y, c);
  return n;
}

TEST(BitmapFont, DrawsExactGlyphsAndUpperCasesLetters) {
  const char* kOne[7] = {"..#..", ".##..", "..#..", "..#..", "..#..", "..#..", ".###."};
  Rgba8Image img = solid(8, 9, {0, 0, 0});
  draw_text(img, 1, 1, "1", {255, 255, 255});
  for (int y = 0; y < 9; ++y) {
    for (int x = 0; x < 8; ++x) {
      const bool on = y >= 1 && y < 8 && x >= 1 && x < 6 && kOne[y - 1][x - 1] == '#';
      EXPECT_EQ(is(img, x, y, {255, 255, 255}), on) << x << ", " << y;
    }
  }
  // Lower case is upper case; scale 2 doubles every font pixel.
  Rgba8Image lower = solid(12, 8, {0, 0, 0}), upper = lower;
  draw_text(lower, 0, 0, "pf", {9, 9, 9});
  draw_text(upper, 0, 0, "PF", {9, 9, 9});
  EXPECT_EQ(lower.texels, upper.texels);
  Rgba8Image big = solid(10, 14, {0, 0, 0});
  draw_text(big, 0, 0, "1", {255, 255, 255}, 2);
  for (int y = 0; y < 14; ++y)
    for (int x = 0; x < 10; ++x)
      EXPECT_EQ(is(big, x, y, {255, 255, 255}), kOne[y / 2][x / 2] == '#') << x << ", " << y;
  // Clipped at the edges rather than written out of bounds.
  draw_text(big, -3, 10, "WWW", {1, 2, 3});
  EXPECT_EQ(text_width("AB"), 11u);
  EXPECT_EQ(text_width("AB", 2), 22u);
  EXPECT_EQ(text_width(""), 0u);
}

class ContactSheet : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (std::filesystem::temp_directory_path() /
            ("vt_contact_sheet_" + std::to_string(::getpid())))
               .string();
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string write(const std::string& name, const Rgba8Image& img) {
    const std::string path = dir_ + "/" + name;
    EXPECT_TRUE(write_png(path, img).ok()) << path;
    return path;
  }

  // View 0 passes with four 64 x 36 images; view 1 fails with five (a later check's lit render
  // included); the atlas check's albedo layer fails page (1, 0) of level 0 (2 x 2 pages).
  ValidationReport report() {
    ValidationReport r;
    r.page_file = dir_ + "/bake.vtpf";
    for (uint32_t v = 0; v < 2; ++v) {
      ViewReport view;
      view.view = v;
      view.metrics.psnr_rgb = v ? 21.5 : 37.25;
      view.metrics.worst_tile_psnr = v ? 12.0 : 26.0;
      const char* names[] = {"reference", "virtual", "diff", "residency", "lit"};
      for (uint32_t i = 0; i < (v ? 5u : 4u); ++i) {
        view.images.push_back(write("view_" + std::to_string(v) + "_" + names[i] + ".png",
                                    solid(64, 36, colour(v, i))));
      }
      if (v == 1) view.failures = {"PSNR 21.50 dB below 30.00 dB"};
      r.views.push_back(view);
    }
    r.atlas.ran = true;
    AtlasLayerReport layer;
    layer.name = "albedo";
    layer.pages_checked = 5;
    layer.pages_failed = 1;
    AtlasPageError bad;
    bad.id = {0, 1, 0};
    bad.failed = true;
    bad.psnr = 9.5;
    layer.worst = {bad};
    layer.heat_maps = {write("atlas_albedo_level0.png", solid(128, 128, kLevel0)),
                       write("atlas_albedo_level1.png", solid(64, 64, kLevel1))};
    r.atlas.layers = {layer};
    r.atlas.failures = {
        "albedo: 1 of 5 pages fail (>= 27.0 dB, mean shift <= 8.0): (0, 1, 0) "
        "9.5 dB, mean shift 3.0"};
    return r;
  }

  static Rgb8 colour(uint32_t view, uint32_t image) {
    return {uint8_t(10 + 40 * image), uint8_t(100 + 50 * view), 200};
  }

  static ContactSheetOptions options() {
    ContactSheetOptions o;
    o.thumb_width = 32;
    o.heat_map_height = 64;
    PageGeometry g;
    g.width = g.height = 240;  // 2 x 2 pages at level 0, 1 x 1 at level 1
    o.geometry = g;
    return o;
  }

  static constexpr Rgb8 kLevel0{0, 190, 40}, kLevel1{0, 150, 40}, kFrame{255, 48, 48};
  std::string dir_;
};

TEST_F(ContactSheet, OneRowPerViewWithEveryListedImageInOrder) {
  auto sheet = make_contact_sheet(report(), options());
  ASSERT_TRUE(sheet.ok()) << sheet.status().message();
  std::array<int, 4> first[2];
  for (uint32_t v = 0; v < 2; ++v) {
    int prev_right = -1;
    for (uint32_t i = 0; i < (v ? 5u : 4u); ++i) {
      const auto b = box_of(*sheet, colour(v, i));
      ASSERT_GE(b[0], 0) << "view " << v << " image " << i << " missing";
      EXPECT_EQ(b[2] - b[0] + 1, 32) << v << " " << i;  // 64 x 36 -> 32 x 18
      EXPECT_EQ(b[3] - b[1] + 1, 18) << v << " " << i;
      EXPECT_GT(b[0], prev_right);  // left to right in the order listed
      prev_right = b[2];
      if (i == 0) first[v] = b;
      EXPECT_EQ(b[1], first[v][1]);  // one line
    }
  }
  EXPECT_EQ(first[0][0], first[1][0]);  // rows start at the same x
  EXPECT_GT(first[1][1], first[0][3]);  // view 1 below view 0
  // The failing view is framed in red, the passing one is not.
  EXPECT_EQ(count_in_rows(*sheet, first[0][1], first[0][3], kFrame), 0);
  EXPECT_GT(count_in_rows(*sheet, first[1][1], first[1][3], kFrame), 0);
  EXPECT_TRUE(is(*sheet, first[1][0] - 6, first[1][1], kFrame));  // the frame's left edge
}

TEST_F(ContactSheet, HeatMapsInALastRowWithFailingPagesOutlined) {
  auto sheet = make_contact_sheet(report(), options());
  ASSERT_TRUE(sheet.ok()) << sheet.status().message();
  const auto l0 = box_of(*sheet, kLevel0), l1 = box_of(*sheet, kLevel1);
  ASSERT_GE(l0[0], 0);
  ASSERT_GE(l1[0], 0);
  const auto view1 = box_of(*sheet, colour(1, 0));
  EXPECT_GT(l0[1], view1[3]);  // below the views
  EXPECT_EQ(l0[1], l1[1]);
  EXPECT_LT(l0[2], l1[0]);           // level 0, then level 1
  EXPECT_EQ(l1[2] - l1[0] + 1, 64);  // 64 x 64 stays 64 x 64
  EXPECT_EQ(l0[3] - l0[1] + 1, 64);  // 128 x 128 -> 64 x 64
  const int x = l0[0], y = l0[1];    // page (1, 0) covers x 32..63, y 0..31
  EXPECT_TRUE(is(*sheet, x + 31, y + 10, {255, 0, 0}));
  EXPECT_TRUE(is(*sheet, x + 40, y + 32, {255, 0, 0}));  // just outside the page
  EXPECT_TRUE(is(*sheet, x + 40, y + 31, kLevel0));      // inside the page: the heat map's colour
  EXPECT_TRUE(is(*sheet, x + 10, y + 40, kLevel0));      // another page: untouched
  EXPECT_TRUE(is(*sheet, x - 1, y + 20, kFrame));        // the failing level's frame
  EXPECT_FALSE(is(*sheet, l1[0] - 1, l1[1] + 20, kFrame));
}

TEST_F(ContactSheet, WritesAPngAndNamesAnUnreadableImage) {
  ValidationReport r = report();
  const std::string path = dir_ + "/contact_sheet.png";
  ASSERT_TRUE(write_contact_sheet(path, r, options()).ok());
  auto back = read_png(path);
  ASSERT_TRUE(back.ok()) << back.status().message();
  auto made = make_contact_sheet(r, options());
  ASSERT_TRUE(made.ok());
  EXPECT_EQ(back->width, made->width);
  EXPECT_EQ(back->texels, made->texels);

  r.views[1].images.push_back(dir_ + "/view_1_gone.png");
  auto missing = make_contact_sheet(r, options());
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), ErrorCode::kIo);
  EXPECT_NE(missing.status().message().find(dir_ + "/view_1_gone.png"), std::string::npos)
      << missing.status().message();

  EXPECT_EQ(make_contact_sheet(ValidationReport{}).status().code(), ErrorCode::kInvalidArgument);
}

TEST_F(ContactSheet, AtlasOnlyReportGivesASheetOfHeatMaps) {
  ValidationReport r = report();
  r.views.clear();
  auto sheet = make_contact_sheet(r, options());
  ASSERT_TRUE(sheet.ok()) << sheet.status().message();
  EXPECT_GE(box_of(*sheet, kLevel0)[0], 0);
  EXPECT_LT(box_of(*sheet, colour(0, 0))[0], 0);
}

TEST(ValidationReportText, FailureLinesNameViewsReasonsLayersAndPages) {
  ValidationReport r;
  EXPECT_TRUE(failure_lines(r).size() == 1);  // no view, no atlas check: not a pass
  ViewReport pass, fail;
  pass.view = 0;
  fail.view = 3;
  fail.failures = {"PSNR 20.00 dB below 30.00 dB", "did not converge in 48 frames"};
  r.views = {pass, fail};
  r.atlas.ran = true;
  EXPECT_EQ(failure_lines(r), (std::vector<std::string>{
                                  "FAIL: views 3",
                                  "view 3: PSNR 20.00 dB below 30.00 dB; did not converge in 48 "
                                  "frames"}));
  AtlasLayerReport orm;
  orm.name = "orm";
  orm.pages_failed = 2;
  r.atlas.layers = {orm};
  r.atlas.failures = {"orm: 2 of 9 pages fail (>= 29.0 dB, mean shift <= 8.0): (0, 1, 2) 9.0 dB"};
  const auto lines = failure_lines(r);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "FAIL: views 3; layers orm (pages as (level, x, y))");
  EXPECT_EQ(lines[2], "layer " + r.atlas.failures[0]);
  r.views = {pass};
  EXPECT_EQ(failure_lines(r)[0], "FAIL: layers orm (pages as (level, x, y))");
  r.atlas = {};
  r.atlas.ran = true;
  EXPECT_TRUE(failure_lines(r).empty());
}

TEST(ValidationReportText, JsonHasWarningsContactSheetAndStageTimes) {
  ValidationReport r;
  r.warnings = {"scene.gltf: asset.version is missing; read as glTF 2.0"};
  r.contact_sheet = "out/contact_sheet.png";
  r.seconds.load = 1.5;
  r.seconds.views = 4;
  ViewReport v;
  v.converge.feedback_ms = {2, 3};
  v.converge.stream_ms = {1, 4};
  r.views = {v};
  const nlohmann::json j = nlohmann::json::parse(report_json(r));
  EXPECT_EQ(j["warnings"], nlohmann::json(r.warnings));
  EXPECT_EQ(j["contact_sheet"], "out/contact_sheet.png");
  EXPECT_EQ(j["seconds"]["load"], 1.5);
  EXPECT_EQ(j["seconds"]["views"], 4.0);
  for (const char* k : {"atlas_check", "setup", "contact_sheet", "total"})
    EXPECT_TRUE(j["seconds"].contains(k)) << k;
  EXPECT_EQ(j["views"][0]["converge_ms"], 10.0);
}

}  // namespace
}  // namespace vt::render
