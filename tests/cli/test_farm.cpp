// End-to-end: a scene bake sharded over a build farm (issue 17, bake/shard.h). `bake --plan
// --work` then `bake --shard I/N` (or `--tasks`) then `merge` gives the bytes of a one-process
// bake (page file and unwrapped scene); a killed or failed shard leaves nothing the merge takes;
// running a shard again is safe; the merge refuses a part of another plan or a damaged one.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "tests/cli/cli_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;
namespace fs = std::filesystem;

class FarmCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fresh_test_dir("farm_cli");
    setup_error_ = write_sample_scene(dir_ + "/scene",
                                      "--ground-cells 4 --sphere-segments 12 --texture-size 64");
    if (!setup_error_.empty()) return;
    fs::create_directories(dir_ + "/local");
    for (const char* name : {"four", "tasks", "one", "kill", "a", "b", "alpha", "alpha_local",
                             "opaque", "opaque_local", "last", "scratch", "scratch_local"})
      fs::create_directories(dir_ + "/" + name);
    RunResult b =
        run_vtbake("-q bake " + scene() + " -o " + dir_ + "/local/out.vtpf " + flags(), true);
    if (b.exit_code != 0) setup_error_ = "bake failed: " + b.out;
  }
  static void TearDownTestSuite() { remove_test_dir(dir_); }
  void SetUp() override { ASSERT_TRUE(setup_error_.empty()) << setup_error_; }

  static std::string scene() { return dir_ + "/scene/scene.gltf"; }
  static std::string flags() { return "--size 4 --supersample 1"; }
  // `vtbake bake SCENE -o NAME/out.vtpf FLAGS --work NAME/work ARGS`
  static RunResult bake(const std::string& name, const std::string& args,
                        const std::string& extra_flags = "") {
    return run_vtbake("-q bake " + scene() + " -o " + dir_ + "/" + name + "/out.vtpf " + flags() +
                          " " + extra_flags + " --work " + work(name) + " " + args,
                      true);
  }
  static std::string work(const std::string& name) { return dir_ + "/" + name + "/work"; }
  static RunResult merge(const std::string& name, const std::string& args = "") {
    return run_vtbake("-q merge " + work(name) + " -o " + dir_ + "/" + name + "/out.vtpf " + args,
                      true);
  }
  static void expect_same_as_local(const std::string& name) {
    const std::string local = read_file(dir_ + "/local/out.vtpf");
    ASSERT_FALSE(local.empty());
    EXPECT_TRUE(read_file(dir_ + "/" + name + "/out.vtpf") == local)
        << name << ": the merged page file differs from the one-process bake";
    EXPECT_TRUE(read_file(dir_ + "/" + name + "/out.glb") == read_file(dir_ + "/local/out.glb"))
        << name << ": the unwrapped scene differs";
  }

  static std::string dir_, setup_error_;
};
std::string FarmCli::dir_, FarmCli::setup_error_;

TEST_F(FarmCli, ShardedBakeMergesToTheOneProcessBytes) {
  RunResult p = bake("four", "--plan " + work("four") + "/plan.json");
  ASSERT_EQ(p.exit_code, 0) << p.out;
  auto plan = nlohmann::json::parse(read_file(work("four") + "/plan.json"));
  ASSERT_TRUE(plan["tasks"].is_array());
  size_t band = 0;
  for (const auto& t : plan["tasks"]) {
    EXPECT_EQ(t["key"].get<std::string>().size(), 16u);
    EXPECT_TRUE(t.contains("deps") && t.contains("cost"));
    band += t["kind"] == "band";
  }
  EXPECT_GE(band, 8u);
  // Before every shard is there the merge fails, naming what is missing, and writes nothing.
  for (int i = 0; i < 3; ++i) {
    RunResult s = bake("four", "--shard " + std::to_string(i) + "/4");
    ASSERT_EQ(s.exit_code, 0) << s.out;
  }
  RunResult early = merge("four");
  EXPECT_NE(early.exit_code, 0);
  EXPECT_NE(early.out.find("no shard part"), std::string::npos) << early.out;
  EXPECT_FALSE(fs::exists(dir_ + "/four/out.vtpf"));
  EXPECT_EQ(run_vtbake("merge " + work("four") + " --missing 4", true).out, "3\n");
  ASSERT_EQ(bake("four", "--shard 3/4").exit_code, 0);
  EXPECT_EQ(run_vtbake("merge " + work("four") + " --missing 4", true).out, "");
  RunResult m = merge("four");
  ASSERT_EQ(m.exit_code, 0) << m.out;
  expect_same_as_local("four");

  // Running a shard again replaces its part with the same pages (only the task times it records
  // differ); the merge stays byte-identical.
  const std::string part = work("four") + "/parts/shard-1-of-4.part";
  const std::string before = read_file(part);
  ASSERT_EQ(bake("four", "--shard 1/4").exit_code, 0);
  EXPECT_EQ(read_file(part).size(), before.size());
  ASSERT_EQ(merge("four").exit_code, 0);
  expect_same_as_local("four");
}

TEST_F(FarmCli, TaskListsAndAnyShardCountGiveTheSameBytes) {
  ASSERT_EQ(bake("tasks", "--plan " + work("tasks") + "/plan.json").exit_code, 0);
  auto plan = nlohmann::json::parse(read_file(work("tasks") + "/plan.json"));
  std::string even, odd;
  int n = 0;
  for (const auto& t : plan["tasks"]) {
    if (t["kind"] != "band") continue;
    std::string& list = n++ % 2 ? odd : even;
    list += (list.empty() ? "" : ",") + std::to_string(t["id"].get<int>());
  }
  ASSERT_EQ(bake("tasks", "--tasks " + even).exit_code, 0);
  ASSERT_EQ(bake("tasks", "--tasks " + odd).exit_code, 0);
  ASSERT_EQ(merge("tasks").exit_code, 0);
  expect_same_as_local("tasks");
  // --plan without --work: the task graph alone, the same tasks and keys.
  const std::string dry = dir_ + "/tasks/dry.json";
  ASSERT_EQ(run_vtbake("-q bake " + scene() + " -o " + dir_ + "/tasks/out.vtpf " + flags() +
                           " --plan " + dry,
                       true)
                .exit_code,
            0);
  auto keys = [](const nlohmann::json& tasks) {
    std::vector<std::string> k;
    for (const auto& t : tasks) k.push_back(t["key"].get<std::string>());
    return k;
  };
  EXPECT_EQ(keys(nlohmann::json::parse(read_file(dry))["tasks"]), keys(plan["tasks"]));
  EXPECT_FALSE(fs::exists(dir_ + "/tasks/dry"));
  // One shard of one: the same again.
  ASSERT_EQ(bake("one", "--plan " + work("one") + "/plan.json").exit_code, 0);
  ASSERT_EQ(bake("one", "--shard 0/1").exit_code, 0);
  ASSERT_EQ(merge("one").exit_code, 0);
  expect_same_as_local("one");
}

TEST_F(FarmCli, KilledOrFailedShardsLeaveNothingTheMergeTakes) {
  ASSERT_EQ(bake("kill", "--plan " + work("kill") + "/plan.json").exit_code, 0);
  ASSERT_EQ(bake("kill", "--shard 0/2").exit_code, 0);
  // A shard with other settings than the plan's fails before writing anything.
  RunResult wrong = bake("kill", "--shard 1/2", "--codec dct:30");
  EXPECT_NE(wrong.exit_code, 0);
  EXPECT_NE(wrong.out.find("settings the plan was made with"), std::string::npos) << wrong.out;
  const std::string part = work("kill") + "/parts/shard-1-of-2.part";
  EXPECT_FALSE(fs::exists(part));
  // A shard killed while it works (its part staged, not complete) leaves only the staging file.
  const std::string command = std::string(VTBAKE_BINARY) + " -q --threads 1 bake " + scene() +
                              " -o " + dir_ + "/kill/out.vtpf " + flags() + " --work " +
                              work("kill") + " --shard 1/2";
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::execl("/bin/sh", "sh", "-c", ("exec " + command + " >/dev/null 2>&1").c_str(), nullptr);
    ::_exit(127);
  }
  bool staged = false;
  for (int i = 0; i < 2000 && !staged; ++i) {
    for (const auto& e : fs::directory_iterator(work("kill") + "/parts"))
      staged |= e.path().filename().string().rfind("shard-1-of-2.part.tmp-", 0) == 0;
    if (!staged) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  EXPECT_TRUE(staged) << "the shard's part was never staged";
  EXPECT_FALSE(fs::exists(part));
  EXPECT_EQ(run_vtbake("merge " + work("kill") + " --missing 2", true).out, "1\n");
  EXPECT_NE(merge("kill").exit_code, 0);
  // A damaged part (cut short) is refused, naming it.
  ASSERT_EQ(bake("kill", "--shard 1/2").exit_code, 0);
  const std::string whole = read_file(part);
  { std::ofstream(part, std::ios::binary).write(whole.data(), std::streamsize(whole.size() / 2)); }
  EXPECT_EQ(run_vtbake("merge " + work("kill") + " --missing 2", true).out, "1\n");
  RunResult cut = merge("kill");
  EXPECT_NE(cut.exit_code, 0);
  EXPECT_NE(cut.out.find("shard-1-of-2.part"), std::string::npos) << cut.out;
  EXPECT_FALSE(fs::exists(dir_ + "/kill/out.vtpf"));
  // Running it again mends the folder.
  ASSERT_EQ(bake("kill", "--shard 1/2").exit_code, 0);
  ASSERT_EQ(merge("kill").exit_code, 0);
  expect_same_as_local("kill");
}

TEST_F(FarmCli, MergeRefusesPartsOfAnotherPlan) {
  ASSERT_EQ(bake("a", "--plan " + work("a") + "/plan.json").exit_code, 0);
  ASSERT_EQ(bake("b", "--plan " + work("b") + "/plan.json", "--codec dct:30").exit_code, 0);
  ASSERT_EQ(bake("a", "--shard 0/2").exit_code, 0);
  ASSERT_EQ(bake("b", "--shard 1/2", "--codec dct:30").exit_code, 0);
  fs::copy_file(work("b") + "/parts/shard-1-of-2.part", work("a") + "/parts/shard-1-of-2.part");
  RunResult m = merge("a");
  EXPECT_NE(m.exit_code, 0);
  EXPECT_NE(m.out.find("another plan"), std::string::npos) << m.out;
  EXPECT_FALSE(fs::exists(dir_ + "/a/out.vtpf"));
  EXPECT_EQ(run_vtbake("merge " + work("a") + " --missing 2", true).out, "1\n");
}

TEST_F(FarmCli, PlanRefusesPathsThatAreNotUtf8) {
  // The plan records its paths as JSON text and the shards open them again: a Latin-1 folder
  // name is refused before any work (it was an internal error of the JSON writer at the end).
  const std::string latin1 = dir_ + "/caf\xe9";
  RunResult r = run_vtbake("-q bake " + scene() + " -o '" + latin1 + "/out.vtpf' " + flags() +
                               " --work '" + latin1 + "/work' --plan '" + latin1 + "/plan.json'",
                           true);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("must be UTF-8"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(latin1 + "/work"));
}

// The plan writes every coarser level as its pyramid pass makes it (dilated, with the alpha
// scale of coverage-preserving alpha), and the shards read them instead of redoing the pyramid:
// the merge stays byte-identical with a per-level alpha scale, and a damaged level file fails the
// shard, naming it, before anything is written.
TEST_F(FarmCli, ShardsReadThePlansLevelsAndAlphaScales) {
  const std::string alpha = "--alpha-coverage 0.5";
  RunResult local = run_vtbake(
      "-q bake " + scene() + " -o " + dir_ + "/alpha_local/out.vtpf " + flags() + " " + alpha,
      true);
  ASSERT_EQ(local.exit_code, 0) << local.out;
  ASSERT_EQ(bake("alpha", "--plan " + work("alpha") + "/plan.json", alpha).exit_code, 0);
  auto plan = nlohmann::json::parse(read_file(work("alpha") + "/plan.json"));
  const uint32_t levels = plan["geometry"]["levels"].get<uint32_t>();
  bool scaled = false;
  for (const auto& l : plan["layers"]) {
    ASSERT_EQ(l["levels"].size(), levels - 1) << l["name"];
    for (const auto& level : l["levels"]) {
      EXPECT_TRUE(fs::exists(work("alpha") + "/" + level["file"].get<std::string>()));
      scaled |= level["alpha_scale"].get<float>() != 1.0f;
    }
  }
  EXPECT_TRUE(scaled) << "no level's alpha was rescaled: the test does not reach that path";
  ASSERT_EQ(bake("alpha", "--shard 0/2", alpha).exit_code, 0);
  ASSERT_EQ(bake("alpha", "--shard 1/2", alpha).exit_code, 0);
  ASSERT_EQ(merge("alpha").exit_code, 0);
  EXPECT_TRUE(read_file(dir_ + "/alpha/out.vtpf") == read_file(dir_ + "/alpha_local/out.vtpf"))
      << "the merged page file differs from the one-process bake";

  const std::string level1 = plan["layers"][0]["levels"][0]["file"].get<std::string>();
  const std::string whole = read_file(work("alpha") + "/" + level1);
  {
    std::ofstream(work("alpha") + "/" + level1, std::ios::binary)
        .write(whole.data(), std::streamsize(whole.size() / 2));
  }
  const std::string part = work("alpha") + "/parts/shard-0-of-2.part";
  fs::remove(part);
  RunResult cut = bake("alpha", "--shard 0/2", alpha);
  EXPECT_NE(cut.exit_code, 0);
  EXPECT_NE(cut.out.find(level1), std::string::npos) << cut.out;
  EXPECT_FALSE(fs::exists(part));
}

// The plan records each layer's content hash and opaque-alpha decision, so that a shard need not
// read the whole of level 0 for them: with an opaque scene (the transfer stores albedo as RGB)
// and with the sample's masked material (RGBA kept), the merge equals the one-process bake.
TEST_F(FarmCli, ShardsTakeHashesAndAlphaDecisionsFromThePlan) {
  std::string gltf = read_file(scene());
  const std::string masked = "\"alphaMode\": \"MASK\"";
  ASSERT_NE(gltf.find(masked), std::string::npos) << "the sample scene has no masked material";
  gltf.replace(gltf.find(masked), masked.size(), "\"alphaMode\": \"OPAQUE\"");
  const std::string opaque = dir_ + "/scene/opaque.gltf";
  { std::ofstream(opaque, std::ios::binary) << gltf; }
  auto bake_opaque = [&](const std::string& name, const std::string& args) {
    return run_vtbake(
        "-q bake " + opaque + " -o " + dir_ + "/" + name + "/out.vtpf " + flags() + " " + args,
        true);
  };
  ASSERT_EQ(bake_opaque("opaque_local", "").exit_code, 0);
  const std::string w = work("opaque");
  ASSERT_EQ(bake_opaque("opaque", "--work " + w + " --plan " + w + "/plan.json").exit_code, 0);
  for (const char* part : {"0/2", "1/2"})
    ASSERT_EQ(bake_opaque("opaque", "--work " + w + " --shard " + part).exit_code, 0);
  ASSERT_EQ(merge("opaque").exit_code, 0);
  EXPECT_TRUE(read_file(dir_ + "/opaque/out.vtpf") == read_file(dir_ + "/opaque_local/out.vtpf"))
      << "the merged page file differs from the one-process bake";

  for (const std::string& name : {std::string("opaque"), std::string("four")}) {
    if (name == "four" && !fs::exists(work(name) + "/plan.json")) {
      ASSERT_EQ(bake(name, "--plan " + work(name) + "/plan.json").exit_code, 0);
    }
    auto plan = nlohmann::json::parse(read_file(work(name) + "/plan.json"));
    const auto& albedo = plan["layers"][0];
    ASSERT_EQ(albedo["name"], "albedo");
    EXPECT_EQ(albedo["content_hash"].get<std::string>().size(), 16u);
    EXPECT_FALSE(albedo["alpha_dropped"].get<bool>()) << name;  // the transfer decided already
    EXPECT_EQ(albedo["channels"].get<int>(), name == "opaque" ? 3 : 4) << name;
  }
}

// `--merge-last`: the shard that completes the set merges (a farm needs no merge job), once:
// a shard that finds a part missing merges nothing, the last one writes the one-process bytes
// and records it in DIR/merged.json, a shard run again after that finds the record and leaves
// the output alone, and the record no longer counts once the output is gone or the folder is
// planned again. The plan writes level 0 only in working form (the shards read nothing else).
TEST_F(FarmCli, TheLastShardMergesOnce) {
  ASSERT_EQ(bake("last", "--plan " + work("last") + "/plan.json").exit_code, 0);
  auto plan = nlohmann::json::parse(read_file(work("last") + "/plan.json"));
  for (const auto& l : plan["layers"]) {
    EXPECT_EQ(l["file"], "") << l["name"];
    EXPECT_FALSE(l["work_file"].get<std::string>().empty()) << l["name"];
    EXPECT_FALSE(fs::exists(work("last") + "/level0/" + l["name"].get<std::string>() + ".f32"));
  }
  const std::string out = dir_ + "/last/out.vtpf";
  auto shard = [&](const std::string& which) {
    RunResult r = run_vtbake("--json bake " + scene() + " -o " + out + " " + flags() + " --work " +
                                 work("last") + " --shard " + which + " --merge-last",
                             false);
    EXPECT_EQ(r.exit_code, 0) << r.out;
    auto j = nlohmann::json::parse(r.out, nullptr, false);
    EXPECT_TRUE(j.is_object() && j.contains("merged")) << r.out;
    return j.is_object() ? j["merged"] : nlohmann::json();
  };
  EXPECT_TRUE(shard("0/2").is_null());
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(work("last") + "/merged.json"));
  EXPECT_EQ(shard("1/2"), out);
  expect_same_as_local("last");
  auto record = nlohmann::json::parse(read_file(work("last") + "/merged.json"));
  EXPECT_EQ(record["plan_hash"], plan["plan_hash"]);
  EXPECT_EQ(record["bytes"].get<uint64_t>(), fs::file_size(out));
  // Run again: the record says merged, the output is not rewritten.
  const auto written = fs::last_write_time(out);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_TRUE(shard("0/2").is_null());
  EXPECT_EQ(fs::last_write_time(out), written);
  // The output gone: the next shard to finish merges again.
  fs::remove(out);
  EXPECT_EQ(shard("0/2"), out);
  expect_same_as_local("last");
  // Replaced by another file of the same size: not the merge the record names, merged again.
  const std::string merged_bytes = read_file(out);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::ofstream(out, std::ios::binary | std::ios::trunc) << std::string(merged_bytes.size(), 'x');
  ASSERT_EQ(fs::file_size(out), merged_bytes.size());
  EXPECT_EQ(shard("1/2"), out);
  expect_same_as_local("last");
  // A new plan of the folder drops the record (and the parts of another plan, if any).
  ASSERT_EQ(bake("last", "--plan " + work("last") + "/plan.json").exit_code, 0);
  EXPECT_FALSE(fs::exists(work("last") + "/merged.json"));
  // --merge-last takes --shard, not --tasks.
  EXPECT_NE(bake("last", "--tasks 0 --merge-last").exit_code, 0);
}

// A plan whose level 0 is held in compressed scratch files (a memory limit under it) gives the
// shards those files themselves, linked into the work folder with no copy and still compressed;
// the shards read them and the merge equals the one-process bake. A damaged one fails the
// shard, naming it.
TEST_F(FarmCli, ShardsReadThePlansCompressedScratchLevels) {
  const std::string size = " --size 12 --supersample 1 ";
  auto bake12 = [&](const std::string& name, const std::string& args) {
    return run_vtbake("-q bake " + scene() + " -o " + dir_ + "/" + name + "/out.vtpf" + size + args,
                      true);
  };
  ASSERT_EQ(bake12("scratch_local", "").exit_code, 0);
  const std::string scratch = " --memory-limit 150M --compress-scratch --work " + work("scratch");
  RunResult p = bake12("scratch", scratch + " --plan " + work("scratch") + "/plan.json");
  ASSERT_EQ(p.exit_code, 0) << p.out;
  auto plan = nlohmann::json::parse(read_file(work("scratch") + "/plan.json"));
  for (const auto& l : plan["layers"]) {
    ASSERT_EQ(l["work_format"], "zstd-chunks") << l["name"];
    const std::string file = work("scratch") + "/" + l["work_file"].get<std::string>();
    const uint64_t raw = l["width"].get<uint64_t>() * l["height"].get<uint64_t>() *
                         l["work_channels"].get<uint64_t>() * sizeof(float);
    struct stat st;
    ASSERT_EQ(stat(file.c_str(), &st), 0) << file;
    EXPECT_LT(uint64_t(st.st_blocks) * 512, raw * 3 / 4) << file;
  }
  for (const char* shard : {"0/2", "1/2"}) {
    RunResult r = bake12("scratch", scratch + " --shard " + shard);
    ASSERT_EQ(r.exit_code, 0) << r.out;
  }
  ASSERT_EQ(merge("scratch").exit_code, 0);
  EXPECT_TRUE(read_file(dir_ + "/scratch/out.vtpf") == read_file(dir_ + "/scratch_local/out.vtpf"))
      << "the merged page file differs from the one-process bake";

  const std::string level0 =
      work("scratch") + "/" + plan["layers"][1]["work_file"].get<std::string>();
  fs::resize_file(level0, fs::file_size(level0) - 4);
  fs::remove(work("scratch") + "/parts/shard-0-of-2.part");
  RunResult cut = bake12("scratch", scratch + " --shard 0/2");
  EXPECT_NE(cut.exit_code, 0);
  EXPECT_NE(cut.out.find(level0), std::string::npos) << cut.out;
  EXPECT_FALSE(fs::exists(work("scratch") + "/parts/shard-0-of-2.part"));
}

}  // namespace
}  // namespace vt
