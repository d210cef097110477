// Every command's --json object against docs/JSON.md (issue 17, "One report schema"): the
// envelope {schema, command, ok, exit} first and in order, then exactly the keys the document's
// "Keys per command" table lists for it (those marked * may be absent); a failure prints the
// envelope and an error object {code, message} and nothing else on stdout.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>

#include "tests/cli/cli_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;
namespace fs = std::filesystem;

struct DocumentedKeys {
  std::set<std::string> required, optional;
};

// The table rows "| `command` | `key` `key*` ... |" of docs/JSON.md's "Keys per command".
std::map<std::string, DocumentedKeys> documented_keys() {
  std::ifstream in(std::string(VTBAKE_SOURCE_DIR) + "/docs/JSON.md");
  std::map<std::string, DocumentedKeys> table;
  bool in_section = false;
  for (std::string line; std::getline(in, line);) {
    if (line.starts_with("## ")) in_section = line == "## Keys per command";
    if (!in_section || !line.starts_with("| `")) continue;
    const size_t name_end = line.find('`', 3);
    const std::string command = line.substr(3, name_end - 3);
    std::istringstream cells(line.substr(line.find('|', name_end) + 1));
    DocumentedKeys keys;
    for (std::string word; cells >> word;) {
      if (word == "|") continue;
      word = word.substr(1, word.find('`', 1) - 1);
      const bool optional = word.ends_with('*');
      if (optional) word.pop_back();
      (optional ? keys.optional : keys.required).insert(word);
    }
    table[command] = keys;
  }
  return table;
}

class JsonSchema : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fresh_test_dir("json_schema");
    documented_ = documented_keys();
  }
  static void TearDownTestSuite() { remove_test_dir(dir_); }

  // Runs `vtbake --json ARGS`, checks the exit status, one line of output, the envelope and the
  // documented keys of `row`; returns the object.
  static nlohmann::ordered_json check(const std::string& row, const std::string& args,
                                      int exit_code = 0) {
    const RunResult r = run_vtbake("--json " + args, false);
    EXPECT_EQ(r.exit_code, exit_code) << args << "\n" << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << args << "\n" << r.out;
    auto j = nlohmann::ordered_json::parse(r.out, nullptr, false);
    if (j.is_discarded() || !j.is_object()) {
      ADD_FAILURE() << args << ": not a JSON object: " << r.out;
      return {};
    }
    std::vector<std::string> order;
    for (const auto& [key, value] : j.items()) order.push_back(key);
    EXPECT_GE(order.size(), 4u);
    if (order.size() >= 4) {
      EXPECT_EQ(std::vector<std::string>(order.begin(), order.begin() + 4),
                (std::vector<std::string>{"schema", "command", "ok", "exit"}))
          << args;
    }
    EXPECT_EQ(j["schema"], 1);
    EXPECT_EQ(j["command"], row.substr(0, row.find(' ')));
    EXPECT_EQ(j["ok"], exit_code == 0);
    EXPECT_EQ(j["exit"], exit_code);
    const auto doc = documented_.find(row);
    if (doc == documented_.end()) {
      ADD_FAILURE() << "docs/JSON.md has no row for `" << row << "`";
      return j;
    }
    std::set<std::string> body(order.begin() + std::min<size_t>(4, order.size()), order.end());
    for (const std::string& key : doc->second.required)
      EXPECT_TRUE(body.count(key)) << row << ": documented key " << key << " missing";
    for (const std::string& key : body)
      EXPECT_TRUE(doc->second.required.count(key) || doc->second.optional.count(key))
          << row << ": key " << key << " is not in docs/JSON.md";
    return j;
  }

  // A failing run: the envelope and an error object, nothing else.
  static void check_error(const std::string& command, const std::string& args, int exit_code,
                          const std::string& code) {
    const RunResult r = run_vtbake("--json " + args, false);
    EXPECT_EQ(r.exit_code, exit_code) << args;
    auto j = nlohmann::json::parse(r.out, nullptr, false);
    ASSERT_TRUE(j.is_object()) << args << ": " << r.out;
    EXPECT_EQ(j.size(), 5u) << j;
    EXPECT_EQ(j["schema"], 1);
    EXPECT_EQ(j["command"], command);
    EXPECT_EQ(j["ok"], false);
    EXPECT_EQ(j["exit"], exit_code);
    EXPECT_EQ(j["error"]["code"], code) << j;
    EXPECT_FALSE(j["error"]["message"].get<std::string>().empty());
  }

  static inline std::string dir_;
  static inline std::map<std::string, DocumentedKeys> documented_;
};

TEST_F(JsonSchema, TheDocumentListsEveryCommand) {
  for (const char* row :
       {"bake", "bake --plan", "bake --shard", "build", "clean", "extract", "info", "merge",
        "merge --missing", "sample", "sample-scene", "unwrap", "validate", "verify", "version"})
    EXPECT_TRUE(documented_.count(row)) << row;
}

TEST_F(JsonSchema, PageFileCommands) {
  check("version", "version");
  auto sample = check("sample", "sample -o " + dir_ + "/img --width 200 --height 150");
  EXPECT_EQ(sample["outputs"].size(), 2u);
  auto build = check("build", "build " + dir_ + "/img/albedo.png -o " + dir_ + "/a.vtpf");
  EXPECT_EQ(build["output"], dir_ + "/a.vtpf");
  EXPECT_GE(build["seconds"]["total"].get<double>(), 0.0);
  auto info = check("info", "info " + dir_ + "/a.vtpf");
  EXPECT_EQ(info["input"], dir_ + "/a.vtpf");
  // One name, one meaning: the file's size and the page counts agree across commands.
  EXPECT_EQ(info["bytes"]["file"], build["bytes"]["file"]);
  EXPECT_EQ(info["bytes"]["stored"], build["bytes"]["stored"]);
  EXPECT_EQ(info["pages"], build["pages"]);
  auto verify = check("verify", "verify " + dir_ + "/a.vtpf");
  EXPECT_EQ(verify["pages"]["checked"], info["pages"]["stored"]);
  auto extract = check("extract", "extract " + dir_ + "/a.vtpf --level 1 -o " + dir_ + "/e.png");
  EXPECT_EQ(extract["bytes"]["file"].get<uint64_t>(), fs::file_size(dir_ + "/e.png"));
  EXPECT_EQ(extract["width"], 100);
  auto clean = check("clean", "clean " + dir_);
  EXPECT_EQ(clean["removed"], nlohmann::json::array());
}

TEST_F(JsonSchema, SceneAndFarmCommands) {
  auto scene = check("sample-scene", "sample-scene " + dir_ +
                                         "/scene --ground-cells 2 --sphere-segments 8 "
                                         "--texture-size 32");
  const std::string gltf = scene["output"];
  const std::string flags = " --size 2 --payload 56 --supersample 1";
  auto bake = check("bake", "bake " + gltf + " -o " + dir_ + "/s.vtpf" + flags);
  EXPECT_EQ(bake["input"], gltf);
  EXPECT_GE(bake["seconds"]["total"].get<double>(), 0.0);
  check("unwrap", "unwrap " + gltf + " -o " + dir_ + "/u.glb");
  check("bake --plan", "bake " + gltf + " -o " + dir_ + "/f.vtpf --work " + dir_ + "/work" + flags);
  check("merge --missing", "merge " + dir_ + "/work --missing 1");
  auto shard = check("bake --shard", "bake " + gltf + " -o " + dir_ + "/f.vtpf --work " + dir_ +
                                         "/work --shard 0/1" + flags);
  EXPECT_EQ(shard["input"], dir_ + "/work");
  auto merge = check("merge", "merge " + dir_ + "/work");
  // The merged file is the one-process bake's: the same counts under the same names.
  EXPECT_EQ(merge["pages"], bake["build"]["pages"]);
  EXPECT_EQ(merge["bytes"]["file"], bake["build"]["bytes"]["file"]);
}

TEST_F(JsonSchema, ValidateAtlasOnly) {
  ASSERT_EQ(write_sample_scene(dir_ + "/vscene"), "");
  const std::string gltf = dir_ + "/vscene/scene.gltf";
  ASSERT_EQ(run_vtbake("-q bake " + gltf + " -o " + dir_ + "/v.vtpf --size 2 --payload 56", false)
                .exit_code,
            0);
  auto v = check("validate",
                 "validate " + gltf + " " + dir_ + "/v.vtpf --atlas-only --out " + dir_ + "/v.out");
  EXPECT_EQ(v["output"], dir_ + "/v.out");
}

TEST_F(JsonSchema, ErrorsAreObjectsOnStdout) {
  const std::string missing = dir_ + "/missing.vtpf";
  check_error("info", "info " + missing, 2, "not_found");
  check_error("verify", "verify " + missing, 2, "not_found");
  check_error("extract", "extract " + missing + " --level 0 -o " + dir_ + "/x.png", 2, "not_found");
  check_error("bake", "bake " + dir_ + "/missing.gltf -o " + dir_ + "/x.vtpf", 2, "not_found");
  check_error("build", "build " + dir_ + "/missing.png -o " + dir_ + "/x.vtpf", 2, "not_found");
  // A message quoting a file name that is not UTF-8 (Latin-1) is still a JSON error object.
  check_error("build", "build '" + dir_ + "/caf\xe9.png' -o " + dir_ + "/x.vtpf", 2, "not_found");
  check_error("build",
              "build procedural:64x64 --layer 'd\xe9tail=procedural:64x64' -o " + dir_ + "/x.vtpf",
              2, "usage");
  check_error("clean", "clean " + dir_ + "/no-such-folder", 2, "not_found");
  // Errors found while parsing the command line are objects too.
  check_error("info", "info", 2, "usage");
  check_error("vtbake", "no-such-command", 2, "usage");
  // A write that fails is an i/o error with exit 1, and leaves no file behind.
  check_error("sample", "sample -o /proc/vtbake-cannot-write", 1, "io");
}

}  // namespace
}  // namespace vt
