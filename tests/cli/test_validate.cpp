// End-to-end: `vtbake sample-scene` -> `vtbake bake` -> `vtbake validate` through the binary.
// A correct bake must pass from automatic views and from a camera file; the same bake with its
// pages shuffled (a wrong page in the index, checksums valid) must fail with exit status 1,
// naming the failing view and layer and its pages on stderr. Every run leaves a contact sheet;
// --json prints report.json. Skips without Vulkan.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "format/page_file.h"
#include "tests/cli/cli_test_util.h"
#include "tests/render/page_file_rewrite.h"

namespace vt {
namespace {

using vt::testing::fresh_test_dir;
using vt::testing::remove_test_dir;
using vt::testing::RunResult;
using vt::testing::write_sample_scene;
RunResult run(const std::string& args) {
  return vt::testing::run_vtbake(args, true);
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream f(path);
  return nlohmann::json::parse(f, nullptr, /*allow_exceptions=*/false);
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// Width and height of an image file; {0, 0} when it cannot be read.
std::pair<int, int> image_size(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return {0, 0};
  return {in->spec().width, in->spec().height};
}

// Copies a page file, giving each stored page of `layer` the content of the next stored page of
// its level (row order, wrapping): every page decodes cleanly and passes its checksum, but shows
// the wrong part of the texture. rotate = false copies faithfully.
Status rewrite_page_file(const std::string& in, const std::string& out, uint32_t layer,
                         bool rotate) {
  VT_ASSIGN_OR_RETURN(auto reader, PageFileReader::open(in));
  const PageGeometry& g = reader->geometry();
  std::map<std::array<uint32_t, 3>, PageId> next;
  for (uint32_t l = 0; rotate && l < g.level_count(); ++l) {
    std::vector<PageId> stored;
    for (uint32_t y = 0; y < g.pages_y(l); ++y)
      for (uint32_t x = 0; x < g.pages_x(l); ++x) {
        VT_ASSIGN_OR_RETURN(PageEntry e, reader->entry({l, x, y}, layer));
        if (e.state == PageState::kStored) stored.push_back({l, x, y});
      }
    for (size_t i = 0; i < stored.size(); ++i)
      next[{l, stored[i].x, stored[i].y}] = stored[(i + 1) % stored.size()];
  }
  return vt::render::rewrite_page_file(
      in, out,
      [&](const PageId& id, uint32_t li) {
        auto it = li == layer ? next.find({id.level, id.x, id.y}) : next.end();
        return it == next.end() ? id : it->second;
      },
      [](const PageId&, uint32_t, std::vector<uint8_t>&) { return false; });
}

class ValidateCli : public ::testing::Test {
 protected:
  // One scene and one bake for the whole suite: baking is the slow part.
  static void SetUpTestSuite() {
    dir_ = fresh_test_dir("validate_cli");
    setup_error_ =
        write_sample_scene(dir_, "--ground-cells 4 --sphere-segments 12 --texture-size 64");
    if (!setup_error_.empty()) return;
    RunResult b = run("bake " + dir_ + "/scene.gltf -o " + dir_ +
                      "/bake.vtpf --size 4 --supersample 1 --quiet");
    if (b.exit_code != 0) setup_error_ = "bake failed: " + b.out;
  }
  static void TearDownTestSuite() { remove_test_dir(dir_); }

  void SetUp() override { ASSERT_TRUE(setup_error_.empty()) << setup_error_; }

  // Runs validate; true when the test must skip (no Vulkan device on this machine).
  static bool no_vulkan(const RunResult& r) {
    return r.exit_code == 2 && (contains(r.out, "Vulkan") || contains(r.out, "vulkan"));
  }

  static std::string dir_;
  static std::string setup_error_;
};
std::string ValidateCli::dir_;
std::string ValidateCli::setup_error_;

// Looks down at the ground (12 x 12 at y = 0) from above the front edge: level 0 and 1 pages.
const char* kGroundCamera =
    R"({"cameras":[{"eye":[0,5,7],"target":[0,0,0],"fov_y_deg":50,"near":0.5,"far":40}]})";

TEST_F(ValidateCli, BakedSampleScenePassesFromAutomaticViews) {
  const std::string out = dir_ + "/auto";
  RunResult r = run("validate " + dir_ + "/scene.gltf " + dir_ +
                    "/bake.vtpf --views 2 --size 320x180 --out " + out);
  if (no_vulkan(r)) GTEST_SKIP() << "no Vulkan device: " << r.out;
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_TRUE(contains(r.out, "PASS")) << r.out;
  nlohmann::json report = read_json(out + "/report.json");
  ASSERT_TRUE(report.is_object());
  EXPECT_EQ(report["passed"], true);
  EXPECT_EQ(report["width"], 320);
  EXPECT_EQ(report["height"], 180);
  ASSERT_EQ(report["views"].size(), 2u);
  for (const auto& v : report["views"]) {
    EXPECT_EQ(v["passed"], true) << v.dump();
    EXPECT_EQ(v["converged"], true);
    EXPECT_GT(v["pixels_compared"].get<uint64_t>(), 320u * 180u / 10) << v.dump();
    EXPECT_GE(v["psnr_rgb"].get<double>(), report["thresholds"]["min_psnr"].get<double>());
    EXPECT_GT(v["pages_uploaded"].get<uint64_t>(), 0u);
    // reference, virtual, difference, residency; the lit pair and the normals pair (the bake
    // has normal, ORM and emissive layers)
    ASSERT_EQ(v["images"].size(), 8u);
    for (const auto& image : v["images"]) {
      EXPECT_TRUE(std::filesystem::exists(image.get<std::string>())) << image;
    }
  }
  // One sheet: two view rows of six 320-wide thumbnails (no larger than the renders), and
  // the heat maps.
  EXPECT_EQ(report["contact_sheet"], out + "/contact_sheet.png");
  const auto [w, h] = image_size(out + "/contact_sheet.png");
  EXPECT_GE(w, 6 * 320);
  EXPECT_GE(h, 2 * 180 + 64);
  EXPECT_TRUE(report["warnings"].is_array());
  for (const char* k : {"load", "atlas_check", "setup", "views", "contact_sheet", "total"}) {
    EXPECT_GT(report["seconds"][k].get<double>(), 0.0) << k;
  }
  EXPECT_GE(report["seconds"]["total"].get<double>(),
            report["seconds"]["views"].get<double>() + report["seconds"]["load"].get<double>());
}

TEST_F(ValidateCli, JsonPrintsTheReportOnStdout) {
  const std::string out = dir_ + "/json";
  RunResult r =
      vt::testing::run_vtbake("validate " + dir_ + "/scene.gltf " + dir_ +
                                  "/bake.vtpf --views 1 --size 160x90 --json --out " + out,
                              /*merge_stderr=*/false);
  if (r.exit_code == 2) GTEST_SKIP() << "no Vulkan device (or bad input): " << r.out;
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const nlohmann::json printed = nlohmann::json::parse(r.out, nullptr, false);
  ASSERT_TRUE(printed.is_object()) << r.out;
  // The printed object is report.json opened by the envelope (docs/JSON.md).
  EXPECT_EQ(printed["schema"], 1);
  EXPECT_EQ(printed["command"], "validate");
  EXPECT_EQ(printed["ok"], true);
  EXPECT_EQ(printed["output"], out);
  nlohmann::json body = printed;
  for (const char* key : {"schema", "command", "ok", "exit", "input", "output"}) body.erase(key);
  EXPECT_EQ(body, read_json(out + "/report.json"));
  EXPECT_EQ(printed["views"].size(), 1u);
  // A report folder whose name is not UTF-8 (Latin-1): the report is written, its path quoted
  // with U+FFFD (the JSON writer threw: an internal error after all the work).
  const std::string latin1 = dir_ + "/caf\xe9";
  RunResult l =
      vt::testing::run_vtbake("validate " + dir_ + "/scene.gltf " + dir_ +
                                  "/bake.vtpf --views 1 --size 160x90 --out '" + latin1 + "'",
                              /*merge_stderr=*/true);
  ASSERT_EQ(l.exit_code, 0) << l.out;
  EXPECT_TRUE(read_json(latin1 + "/report.json").is_object());
}

TEST_F(ValidateCli, CameraFileViewPassesAndAShuffledBakeFails) {
  const std::string cams = dir_ + "/ground_camera.json";
  write_text(cams, kGroundCamera);
  const std::string scene = dir_ + "/scene.gltf", glb = dir_ + "/bake.glb";
  const std::string args = " --cameras " + cams + " --size 320x180 --unwrapped " + glb;

  RunResult good =
      run("validate " + scene + " " + dir_ + "/bake.vtpf" + args + " --out " + dir_ + "/cam_good");
  if (no_vulkan(good)) GTEST_SKIP() << "no Vulkan device: " << good.out;
  ASSERT_EQ(good.exit_code, 0) << good.out;
  nlohmann::json report = read_json(dir_ + "/cam_good/report.json");
  ASSERT_EQ(report["views"].size(), 1u);  // the file's one camera, not the 6 automatic views
  EXPECT_GT(report["views"][0]["pixels_compared"].get<uint64_t>(), 320u * 180u / 2);

  // Which layer the renderer validates: the albedo one.
  auto reader = PageFileReader::open(dir_ + "/bake.vtpf");
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  uint32_t albedo = 0;
  while (albedo < (*reader)->layers().size() &&
         (*reader)->layers()[albedo].semantic != LayerSemantic::kAlbedo) {
    ++albedo;
  }
  ASSERT_LT(albedo, (*reader)->layers().size());

  // Control: a faithful rewrite passes too, so the failure below comes from the shuffle.
  const std::string copy = dir_ + "/copy.vtpf", shuffled = dir_ + "/shuffled.vtpf";
  Status s = rewrite_page_file(dir_ + "/bake.vtpf", copy, albedo, /*rotate=*/false);
  ASSERT_TRUE(s.ok()) << s.message();
  RunResult same = run("validate " + scene + " " + copy + args + " --out " + dir_ + "/cam_copy");
  EXPECT_EQ(same.exit_code, 0) << same.out;

  s = rewrite_page_file(dir_ + "/bake.vtpf", shuffled, albedo, /*rotate=*/true);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_EQ(run("verify " + shuffled + " --quiet").exit_code, 0);  // checksums still valid
  RunResult bad =
      run("validate " + scene + " " + shuffled + args + " --out " + dir_ + "/cam_shuffled");
  EXPECT_EQ(bad.exit_code, 1) << bad.out;
  EXPECT_TRUE(contains(bad.out, "FAIL")) << bad.out;
  // stderr names the view with its reason, the layer and its pages.
  EXPECT_TRUE(contains(bad.out, "vtbake validate: FAIL: views 0; layers albedo")) << bad.out;
  EXPECT_TRUE(contains(bad.out, "vtbake validate: view 0: ")) << bad.out;
  EXPECT_TRUE(contains(bad.out, "worst tile (pixel ")) << bad.out;
  EXPECT_TRUE(contains(bad.out, "vtbake validate: layer albedo: ")) << bad.out;
  EXPECT_TRUE(contains(bad.out, " pages fail (")) << bad.out;
  EXPECT_TRUE(std::filesystem::exists(dir_ + "/cam_shuffled/contact_sheet.png"));
  report = read_json(dir_ + "/cam_shuffled/report.json");
  ASSERT_EQ(report["views"].size(), 1u);
  EXPECT_EQ(report["passed"], false);
  EXPECT_EQ(report["views"][0]["passed"], false);
  EXPECT_LT(report["views"][0]["worst_tile_psnr"].get<double>(),
            report["thresholds"]["min_tile_psnr"].get<double>());
}

TEST_F(ValidateCli, CameraLookingAwayFromTheSceneFails) {
  const std::string cams = dir_ + "/away.json";
  write_text(cams, R"({"cameras":[{"eye":[0,5,7],"target":[0,10,14]}]})");
  RunResult r = run("validate " + dir_ + "/scene.gltf " + dir_ + "/bake.vtpf --cameras " + cams +
                    " --size 64x36 --out " + dir_ + "/away");
  if (no_vulkan(r)) GTEST_SKIP() << "no Vulkan device: " << r.out;
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(contains(r.out, "no pixel drawn by both renders")) << r.out;
}

// The atlas check alone needs no Vulkan: a shuffled bake fails it (exit 1, the layer and its pages
// on stderr), the contact sheet holds the heat maps, and the importer's warnings of the original
// scene are printed and in the report.
TEST_F(ValidateCli, AtlasOnlyFailsNamingPagesAndReportsSceneWarnings) {
  auto reader = PageFileReader::open(dir_ + "/bake.vtpf");
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  uint32_t albedo = 0;
  while ((*reader)->layers()[albedo].semantic != LayerSemantic::kAlbedo) ++albedo;
  const std::string shuffled = dir_ + "/atlas_shuffled.vtpf";
  Status s = rewrite_page_file(dir_ + "/bake.vtpf", shuffled, albedo, /*rotate=*/true);
  ASSERT_TRUE(s.ok()) << s.message();
  std::filesystem::copy_file(dir_ + "/bake.glb", dir_ + "/atlas_shuffled.glb",
                             std::filesystem::copy_options::overwrite_existing);
  // The same scene with no asset.version: the glTF importer warns and reads it as 2.0.
  nlohmann::json gltf = read_json(dir_ + "/scene.gltf");
  ASSERT_TRUE(gltf.is_object());
  gltf["asset"].erase("version");
  const std::string scene = dir_ + "/scene_noversion.gltf";
  write_text(scene, gltf.dump());

  const std::string out = dir_ + "/atlas_only";
  RunResult r = run("validate " + scene + " " + shuffled + " --atlas-only --out " + out);
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(contains(r.out, "vtbake validate: FAIL: layers albedo (pages as (level, x, y))"))
      << r.out;
  EXPECT_TRUE(contains(r.out, "vtbake validate: layer albedo: ")) << r.out;
  EXPECT_TRUE(contains(r.out, "warning: " + scene + ": asset.version is missing")) << r.out;
  nlohmann::json report = read_json(out + "/report.json");
  ASSERT_TRUE(report.is_object());
  EXPECT_EQ(report["passed"], false);
  ASSERT_EQ(report["warnings"].size(), 1u) << report["warnings"].dump();
  EXPECT_TRUE(contains(report["warnings"][0].get<std::string>(), "asset.version is missing"));
  const auto [w, h] = image_size(out + "/contact_sheet.png");
  EXPECT_GT(w, 0);
  EXPECT_GT(h, 0);

  // The bake itself passes the atlas check: exit 0, nothing on stderr but the warning.
  r = run("validate " + scene + " " + dir_ + "/bake.vtpf --atlas-only --quiet --out " + out);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_FALSE(contains(r.out, "FAIL")) << r.out;
}

// These fail before any scene, page file or Vulkan work, so they run everywhere.
TEST(ValidateCliArgs, BadCameraFilesAreBadInputNamingTheFile) {
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("vt_validate_args_" + std::to_string(::getpid())))
          .string();
  std::filesystem::create_directories(dir);
  const std::string cams = dir + "/cams.json";
  write_text(cams, R"({"cameras":[{"eye":[1,2,3],"target":[1,2,3]}]})");
  RunResult r = run("validate none.gltf none.vtpf --cameras " + cams);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.out, cams + ": camera 0: eye and target coincide")) << r.out;

  write_text(cams, R"({"cameras":[{"eye":[1,2,3]}]})");
  r = run("validate none.gltf none.vtpf --cameras " + cams);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.out, cams + ": camera 0: missing \"target\"")) << r.out;

  r = run("validate none.gltf none.vtpf --cameras " + dir + "/nope.json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.out, dir + "/nope.json: cannot open camera file")) << r.out;

  // --views and --cameras exclude each other.
  write_text(cams, kGroundCamera);
  r = run("validate none.gltf none.vtpf --views 2 --cameras " + cams);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.out, "excludes")) << r.out;

  // A scene that does not exist is bad input too, named.
  r = run("validate " + dir + "/none.gltf " + dir + "/none.vtpf");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.out, dir + "/none.vtpf")) << r.out;

  r = run("validate --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_TRUE(contains(r.out, "\"fov_y_deg\"")) << r.out;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace vt
