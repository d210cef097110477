// End-to-end: `vtbake bake` over many scenes (issue 17): positionals and --list, one output per
// scene under --out-dir (parent folders created), every input checked before any work,
// --keep-going, a summary table, one JSON line per scene with --json.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "tests/cli/cli_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;
namespace fs = std::filesystem;

class BatchCli : public ::testing::Test {
 protected:
  // One sample scene as two glTF files (a.gltf, b.gltf share scene.bin and the textures).
  static void SetUpTestSuite() {
    dir_ = fresh_test_dir("batch_cli");
    setup_error_ = write_sample_scene(dir_ + "/scenes");
    if (!setup_error_.empty()) return;
    fs::copy_file(dir_ + "/scenes/scene.gltf", dir_ + "/scenes/a.gltf");
    fs::copy_file(dir_ + "/scenes/scene.gltf", dir_ + "/scenes/b.gltf");
    std::ofstream(dir_ + "/scenes/broken.gltf") << "{ not gltf";
  }
  static void TearDownTestSuite() { remove_test_dir(dir_); }
  void SetUp() override { ASSERT_TRUE(setup_error_.empty()) << setup_error_; }
  static std::string scene(const std::string& name) { return dir_ + "/scenes/" + name; }
  static std::string flags() { return " --size 2 --payload 56 --supersample 1"; }
  static std::string dir_, setup_error_;
};
std::string BatchCli::dir_, BatchCli::setup_error_;

TEST_F(BatchCli, BakesEveryScene) {
  const std::string out = dir_ + "/out/deeper/folder";
  RunResult r = run_vtbake(
      "-q bake " + scene("a.gltf") + " " + scene("b.gltf") + " --out-dir " + out + flags(), false);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("2 of 2 scenes baked"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("a.gltf"), std::string::npos);
  for (const char* name : {"a", "b"}) {
    EXPECT_TRUE(fs::exists(out + "/" + name + ".vtpf")) << name;
    EXPECT_TRUE(fs::exists(out + "/" + name + ".glb")) << name;
  }
  // The same scene gives the same bytes as a one-scene bake (at the same depth: the metadata
  // records the scene relative to the output).
  const std::string single = dir_ + "/single/at/depth";
  fs::create_directories(single);
  ASSERT_EQ(run_vtbake("-q bake " + scene("a.gltf") + " -o " + single + "/a.vtpf" + flags(), true)
                .exit_code,
            0);
  EXPECT_TRUE(read_file(single + "/a.vtpf") == read_file(out + "/a.vtpf"));
}

TEST_F(BatchCli, ListJsonLinesAndKeepGoing) {
  const std::string list = dir_ + "/scenes/list.txt";
  std::ofstream(list) << "# nightly\na.gltf\n\nbroken.gltf\n  b.gltf\n";
  // Without --keep-going the broken scene stops the batch after it (exit 1).
  RunResult stop =
      run_vtbake("-q --json bake --list " + list + " --out-dir " + dir_ + "/stop" + flags(), false);
  EXPECT_EQ(stop.exit_code, 1) << stop.out;
  EXPECT_FALSE(fs::exists(dir_ + "/stop/b.vtpf"));
  // With it every other scene is baked; one JSON line per scene, in order.
  RunResult r = run_vtbake(
      "-q --json bake --list " + list + " --keep-going --out-dir " + dir_ + "/go" + flags(), false);
  EXPECT_EQ(r.exit_code, 1) << r.out;
  std::istringstream lines(r.out);
  std::vector<nlohmann::json> js;
  for (std::string line; std::getline(lines, line);) {
    auto j = nlohmann::json::parse(line, nullptr, false);
    ASSERT_FALSE(j.is_discarded()) << line;
    js.push_back(j);
  }
  ASSERT_EQ(js.size(), 3u) << r.out;
  EXPECT_EQ(js[0]["ok"], true);
  EXPECT_EQ(js[0]["schema"], 1);
  EXPECT_TRUE(js[0]["input"].get<std::string>().ends_with("/a.gltf")) << js[0]["input"];
  EXPECT_EQ(js[0]["output"], dir_ + "/go/a.vtpf");
  EXPECT_TRUE(js[0].contains("build"));
  EXPECT_EQ(js[1]["ok"], false);
  EXPECT_EQ(js[1]["exit"], 2);
  EXPECT_EQ(js[1]["error"]["code"], "corrupt");
  EXPECT_NE(js[1]["error"]["message"].get<std::string>().find("broken.gltf"), std::string::npos);
  EXPECT_EQ(js[2]["ok"], true);
  EXPECT_TRUE(fs::exists(dir_ + "/go/b.vtpf"));
}

TEST_F(BatchCli, InputsAreCheckedBeforeAnyWork) {
  // A missing scene, or two scenes on one output, fail before anything is baked (exit 2).
  RunResult missing = run_vtbake("-q bake " + scene("a.gltf") + " " + scene("nope.gltf") +
                                     " --out-dir " + dir_ + "/checked" + flags(),
                                 true);
  EXPECT_EQ(missing.exit_code, 2) << missing.out;
  EXPECT_NE(missing.out.find("nope.gltf"), std::string::npos) << missing.out;
  EXPECT_FALSE(fs::exists(dir_ + "/checked/a.vtpf"));
  fs::create_directories(dir_ + "/other");
  fs::copy_file(scene("a.gltf"), dir_ + "/other/a.gltf");
  RunResult twice = run_vtbake("-q bake " + scene("a.gltf") + " " + dir_ + "/other/a.gltf" +
                                   " --out-dir " + dir_ + "/checked" + flags(),
                               true);
  EXPECT_EQ(twice.exit_code, 2) << twice.out;
  EXPECT_NE(twice.out.find("would write"), std::string::npos) << twice.out;
  EXPECT_FALSE(fs::exists(dir_ + "/checked/a.vtpf"));
  // Several scenes need --out-dir.
  EXPECT_EQ(
      run_vtbake("-q bake " + scene("a.gltf") + " " + scene("b.gltf") + flags(), true).exit_code,
      2);
}

TEST_F(BatchCli, KeepFoldersKeepsScenesOfOneNameApart) {
  // A game's models/*/head.md3: one stem in many folders.
  ASSERT_EQ(write_sample_scene(dir_ + "/scenes/sub"), "");
  const std::string list = dir_ + "/scenes/folders.txt";
  std::ofstream(list) << "scene.gltf\nsub/scene.gltf\n";
  RunResult stems =
      run_vtbake("-q bake --list " + list + " --out-dir " + dir_ + "/kf0" + flags(), true);
  EXPECT_EQ(stems.exit_code, 2) << stems.out;
  EXPECT_NE(stems.out.find("(--keep-folders keeps them apart)"), std::string::npos) << stems.out;
  RunResult r = run_vtbake(
      "-q bake --list " + list + " --keep-folders --out-dir " + dir_ + "/kf" + flags(), true);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  for (const char* out : {"/kf/scene.vtpf", "/kf/sub/scene.vtpf", "/kf/sub/scene.glb"})
    EXPECT_TRUE(fs::exists(dir_ + out)) << out;
  // A list made with `find "$PWD"` names them absolutely: the part below the list's folder.
  const std::string scenes = fs::absolute(dir_ + "/scenes").lexically_normal().string();
  const std::string absolute_list = dir_ + "/scenes/absolute.txt";
  std::ofstream(absolute_list) << scenes << "/scene.gltf\n" << scenes << "/sub/./scene.gltf\n";
  r = run_vtbake(
      "-q bake --list " + absolute_list + " --keep-folders --out-dir " + dir_ + "/kf3" + flags(),
      true);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  for (const char* out : {"/kf3/scene.vtpf", "/kf3/sub/scene.vtpf"})
    EXPECT_TRUE(fs::exists(dir_ + out)) << out;
  // A path that leaves the list's folder has no place under DIR, given relative or absolute:
  // refused before any work.
  const std::string beside = fs::absolute(dir_ + "/other/a.gltf").lexically_normal().string();
  for (const std::string& outside : {std::string("../scenes/a.gltf"), beside}) {
    std::ofstream(list) << "scene.gltf\n" << outside << "\n";
    r = run_vtbake(
        "-q bake --list " + list + " --keep-folders --out-dir " + dir_ + "/kf2" + flags(), true);
    EXPECT_EQ(r.exit_code, 2) << outside << r.out;
    EXPECT_NE(r.out.find("--keep-folders needs a path below"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir_ + "/kf2/scene.vtpf"));
  }
  // Without a batch it means nothing: bad usage.
  EXPECT_EQ(
      run_vtbake("-q bake " + scene("a.gltf") + " -o " + dir_ + "/x.vtpf --keep-folders" + flags(),
                 true)
          .exit_code,
      2);
}

}  // namespace
}  // namespace vt
