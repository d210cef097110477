// End-to-end: content keys and update mode (issue 16). The same inputs reached by other path
// spellings give the same bytes; `--update` copies the pages whose key is unchanged and gives
// the bytes of a clean build with --tables-from the previous file; an unchanged update leaves
// the output untouched; a settings change rebuilds everything and says so.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <OpenImageIO/imageio.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/cli/cli_test_util.h"
#include "tests/format/page_file_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;

std::string dir_of(const std::string& path) {
  return path.substr(0, path.rfind('/'));
}

// A w x h RGB PNG of a smooth pattern; texels inside `patch` (x0, y0, x1, y1) get another one.
void write_png(const std::string& path, int w, int h, int seed, std::array<int, 4> patch = {}) {
  std::vector<uint8_t> texels(size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool in = x >= patch[0] && x < patch[2] && y >= patch[1] && y < patch[3];
      for (int c = 0; c < 3; ++c) {
        const int v = in ? (x * 7 + y * 3 + c * 50) : (x * (c + 1) + y * (3 - c) + seed * 40);
        texels[(size_t(y) * w + x) * 3 + c] = uint8_t((v ^ (x * y / 64)) & 255);
      }
    }
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out);
  ASSERT_TRUE(out->open(path, OIIO::ImageSpec(w, h, 3, OIIO::TypeDesc::UINT8)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, texels.data()));
  ASSERT_TRUE(out->close());
}

nlohmann::json run_json(const std::string& args) {
  RunResult r = run_vtbake("--json " + args, false);
  EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.out;
  auto j = nlohmann::json::parse(r.out, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << r.out;
  return j;
}

struct FileStamp {
  ino_t inode = 0;
  int64_t mtime_ns = 0;
  bool operator==(const FileStamp&) const = default;
};
FileStamp stamp(const std::string& path) {
  struct stat st {};
  EXPECT_EQ(::stat(path.c_str(), &st), 0) << path;
  return {st.st_ino, int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec};
}

// Two images (albedo 480 x 360 = 4 x 3 pages, an orm layer) for `vtbake build`.
struct ImageSet {
  std::string dir, albedo, orm;
  explicit ImageSet(const std::string& name) {
    albedo = temp_path(name + "_albedo.png");
    dir = dir_of(albedo);
    orm = dir + "/" + name + "_orm.png";
    write_png(albedo, 480, 360, 1);
    write_png(orm, 480, 360, 2);
  }
  std::string args(const std::string& out) const {
    return "build " + albedo + " --layer orm=" + orm + " -o " + out;
  }
};

TEST(CliUpdate, PathSpellingsOfOneImageGiveTheSameBuild) {
  const std::string png = temp_path("tex.png");
  const std::string dir = dir_of(png);
  write_png(png, 300, 200, 3);
  std::filesystem::create_directories(dir + "/sub");
  const std::string cwd = std::filesystem::current_path().string();
  std::filesystem::current_path(dir);
  const std::vector<std::string> spellings = {"tex.png", png, "./sub/../tex.png"};
  for (size_t i = 0; i < spellings.size(); ++i) {
    RunResult r = run_vtbake(
        "-q build " + spellings[i] + " -o " + dir + "/o" + std::to_string(i) + ".vtpf", true);
    EXPECT_EQ(r.exit_code, 0) << r.out;
  }
  std::filesystem::current_path(cwd);
  const auto first = read_bytes(dir + "/o0.vtpf");
  ASSERT_FALSE(first.empty());
  EXPECT_EQ(first, read_bytes(dir + "/o1.vtpf"));
  EXPECT_EQ(first, read_bytes(dir + "/o2.vtpf"));
}

TEST(CliUpdate, BuildUpdateAfterAChangeEqualsACleanBuildWithPinnedTables) {
  ImageSet set("upd");
  const std::string out = set.dir + "/out.vtpf", before = set.dir + "/before.vtpf";
  auto clean0 = run_json("-q " + set.args(out));
  std::filesystem::copy_file(out, before);
  EXPECT_EQ(clean0["update"], nullptr);
  // A patch inside the first page's payload: that page and its parents change.
  write_png(set.albedo, 480, 360, 1, {20, 20, 60, 60});
  auto update = run_json("-q " + set.args(out) + " --update");
  ASSERT_TRUE(update["update"].is_object()) << update.dump();
  const auto& u = update["update"];
  EXPECT_EQ(u["full_rebuild"], nullptr) << u.dump();
  EXPECT_FALSE(u["unchanged"].get<bool>());
  // 2 layers x (12 + 4 + 1) pages: level 0, 1 and 2 pages of the albedo's corner re-encoded.
  EXPECT_EQ(u["pages_reencoded"].get<int>(), 3) << u.dump();
  EXPECT_EQ(u["pages_reused"].get<int>(), 2 * 17 - 3) << u.dump();
  EXPECT_EQ(u["pages_dropped"].get<int>(), 0);
  // The pinned tables' fit is measured on the training sample's new pages alone: the changed
  // level-0 page (its key as the build computes it; the other 11 are the previous file's).
  EXPECT_EQ(u["tables_fit_pages"].get<int>(), 1) << u.dump();
  EXPECT_GT(u["tables_fit"].get<double>(), 0.0) << u.dump();

  const std::string clean = set.dir + "/clean.vtpf";
  auto pinned = run_json("-q " + set.args(clean) + " --tables-from " + before);
  EXPECT_TRUE(pinned["update"]["tables_pinned"].get<bool>());
  EXPECT_EQ(read_bytes(out), read_bytes(clean));
  // The same at one and two threads.
  const std::string one = set.dir + "/one.vtpf", two = set.dir + "/two.vtpf";
  std::filesystem::copy_file(before, one);
  std::filesystem::copy_file(before, two);
  run_json("--threads 1 -q " + set.args(one) + " --update");
  run_json("--threads 2 -q " + set.args(two) + " --update");
  EXPECT_EQ(read_bytes(out), read_bytes(one));
  EXPECT_EQ(read_bytes(out), read_bytes(two));
}

TEST(CliUpdate, UnchangedBuildUpdateLeavesTheFileUntouched) {
  ImageSet set("same");
  const std::string out = set.dir + "/out.vtpf";
  run_json("-q " + set.args(out));
  const auto bytes = read_bytes(out);
  const FileStamp before = stamp(out);
  auto j = run_json("-q " + set.args(out) + " --update");
  EXPECT_TRUE(j["update"]["unchanged"].get<bool>()) << j.dump();
  EXPECT_EQ(j["update"]["pages_reencoded"].get<int>(), 0);
  EXPECT_EQ(j["update"]["pages_reused"].get<int>(), 2 * 17);
  EXPECT_TRUE(stamp(out) == before);
  EXPECT_EQ(read_bytes(out), bytes);
  RunResult text = run_vtbake(set.args(out) + " --update", true);
  EXPECT_NE(text.out.find("update: 34 pages reused, 0 re-encoded, 0 dropped; unchanged, output "
                          "untouched"),
            std::string::npos)
      << text.out;
}

TEST(CliUpdate, SettingsChangeForcesAFullRebuildAndSaysSo) {
  ImageSet set("settings");
  const std::string out = set.dir + "/out.vtpf";
  run_json("-q " + set.args(out));
  auto j = run_json("-q " + set.args(out) + " --update --codec dct:50");
  EXPECT_EQ(j["update"]["full_rebuild"], "settings changed") << j.dump();
  EXPECT_EQ(j["update"]["pages_reused"].get<int>(), 0);
  EXPECT_EQ(j["update"]["pages_reencoded"].get<int>(), 2 * 17);
  // A clean build with the new settings gives the same bytes.
  const std::string clean = set.dir + "/clean.vtpf";
  run_json("-q " + set.args(clean) + " --codec dct:50");
  EXPECT_EQ(read_bytes(out), read_bytes(clean));

  auto missing = run_json("-q " + set.args(set.dir + "/new.vtpf") + " --update");
  EXPECT_EQ(missing["update"]["full_rebuild"], "no previous file");
  auto retrain = run_json("-q " + set.args(out) + " --codec dct:50 --update --retrain-tables");
  EXPECT_EQ(retrain["update"]["full_rebuild"], "tables retrained (--retrain-tables)");
}

// Two quads side by side, each with its own material and texture; returns the .obj path.
std::string two_textured_quads() {
  const std::string obj = temp_path("quads.obj");
  const std::string dir = dir_of(obj);
  std::filesystem::create_directories(dir + "/textures");
  std::ofstream(obj) << "mtllib quads.mtl\n"
                        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                        "v 3 0 0\nv 4 0 0\nv 4 1 0\nv 3 1 0\n"
                        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                        "usemtl A\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n"
                        "usemtl B\nf 5/1 6/2 7/3\nf 5/1 7/3 8/4\n";
  std::ofstream(dir + "/quads.mtl") << "newmtl A\nKd 1 1 1\nmap_Kd textures/a.png\n"
                                       "newmtl B\nKd 1 1 1\nmap_Kd textures/b.png\n";
  write_png(dir + "/textures/a.png", 64, 64, 4);
  write_png(dir + "/textures/b.png", 64, 64, 5);
  return obj;
}

TEST(CliUpdate, SceneBakeBySpellingsAndUpdateEqualsCleanBakeWithPinnedTables) {
  const std::string obj = two_textured_quads();
  const std::string dir = dir_of(obj);
  const std::string flags = " --size 3";
  run_json("-q bake " + obj + " -o " + dir + "/s1.vtpf" + flags);
  run_json("-q bake " + dir + "/textures/.././quads.obj -o " + dir + "/s2.vtpf" + flags);
  EXPECT_EQ(read_bytes(dir + "/s1.vtpf"), read_bytes(dir + "/s2.vtpf"));
  EXPECT_EQ(read_bytes(dir + "/s1.glb"), read_bytes(dir + "/s2.glb"));

  // Unchanged: nothing rewritten.
  const FileStamp pages = stamp(dir + "/s1.vtpf"), scene = stamp(dir + "/s1.glb");
  auto same = run_json("-q bake " + obj + " -o " + dir + "/s1.vtpf --update" + flags);
  EXPECT_TRUE(same["build"]["update"]["unchanged"].get<bool>()) << same["build"].dump();
  EXPECT_TRUE(stamp(dir + "/s1.vtpf") == pages);
  EXPECT_TRUE(stamp(dir + "/s1.glb") == scene);

  // One texture changes: an update equals a clean bake with the previous file's tables.
  std::filesystem::copy_file(dir + "/s1.vtpf", dir + "/before.vtpf");
  write_png(dir + "/textures/b.png", 64, 64, 5, {10, 10, 30, 30});
  auto update = run_json("-q bake " + obj + " -o " + dir + "/s1.vtpf --update" + flags);
  const auto& u = update["build"]["update"];
  EXPECT_EQ(u["full_rebuild"], nullptr) << u.dump();
  EXPECT_GT(u["pages_reused"].get<int>(), 0) << u.dump();
  EXPECT_GT(u["pages_reencoded"].get<int>(), 0) << u.dump();
  run_json("-q bake " + obj + " -o " + dir + "/clean.vtpf --tables-from " + dir + "/before.vtpf" +
           flags);
  EXPECT_EQ(read_bytes(dir + "/s1.vtpf"), read_bytes(dir + "/clean.vtpf"));
  EXPECT_EQ(read_bytes(dir + "/s1.glb"), read_bytes(dir + "/clean.glb"));
}

// The band cache beside the output (OUT.cache/transfer.bin): an update after a texture change
// reads the bands that do not see the texture from it and gives the bytes of a clean bake; a
// damaged cache is never trusted (its bad bands, or all of it, are transferred again: the same
// bytes); a settings change rebuilds everything, the cache included, and says so.
TEST(CliUpdate, SceneBakeUpdateReadsUnchangedBandsFromTheCacheAndNeverTrustsADamagedOne) {
  const std::string obj = two_textured_quads();
  const std::string dir = dir_of(obj);
  const std::string flags = " --size 3", out = dir + "/u.vtpf";
  const std::string cache = out + ".cache/transfer.bin";
  // A plain bake writes no band cache (only the unwrap's); a first --update, with no output to
  // update yet, is a clean bake that does.
  auto plain = run_json("-q bake " + obj + " -o " + out + flags);
  EXPECT_EQ(plain["transfer"]["bands_cached"], 0);
  EXPECT_FALSE(std::filesystem::exists(cache));
  EXPECT_TRUE(std::filesystem::exists(out + ".cache/unwrap.bin"));
  run_json("-q bake " + obj + " -o " + dir + "/named.vtpf --cache " + dir + "/named" + flags);
  EXPECT_TRUE(std::filesystem::exists(dir + "/named/transfer.bin"));  // a cache asked for by name
  const std::vector<uint8_t> plain_bytes = read_bytes(out);
  std::filesystem::remove(out);
  auto clean = run_json("-q bake " + obj + " -o " + out + " --update" + flags);
  EXPECT_EQ(clean["transfer"]["bands_cached"], 0);
  ASSERT_TRUE(std::filesystem::exists(cache));
  EXPECT_EQ(read_bytes(out), plain_bytes);
  std::filesystem::copy_file(out, dir + "/before.vtpf");
  std::filesystem::copy_file(cache, dir + "/before.bin");
  write_png(dir + "/textures/b.png", 64, 64, 5, {10, 10, 30, 30});
  run_json("-q bake " + obj + " -o " + dir + "/clean.vtpf --tables-from " + dir + "/before.vtpf" +
           flags + " --cache -");
  EXPECT_FALSE(std::filesystem::exists(dir + "/clean.vtpf.cache"));
  const std::vector<uint8_t> expected = read_bytes(dir + "/clean.vtpf");

  // Some bands see only quad A: read from the cache; those that see B are transferred.
  auto update = run_json("-q bake " + obj + " -o " + out + " --update" + flags);
  const int bands = update["transfer"]["bands"].get<int>();
  const int cached = update["transfer"]["bands_cached"].get<int>();
  EXPECT_GT(cached, 0) << update["transfer"].dump();
  EXPECT_LT(cached, bands) << update["transfer"].dump();
  EXPECT_EQ(update["build"]["update"]["full_rebuild"], nullptr);
  EXPECT_EQ(read_bytes(out), expected);
  // The update's cache keeps the bands it read: a second change of B reuses them again.
  write_png(dir + "/textures/b.png", 64, 64, 6, {10, 10, 30, 30});
  auto second = run_json("-q bake " + obj + " -o " + out + " --update" + flags);
  EXPECT_EQ(second["transfer"]["bands_cached"].get<int>(), cached);
  write_png(dir + "/textures/b.png", 64, 64, 5, {10, 10, 30, 30});

  // Every frame of the previous cache damaged (a byte flipped past the header in each of them):
  // no band passes its checksum, all are transferred again, the bytes are the same.
  auto damage = [&](auto&& change) {
    std::filesystem::copy_file(dir + "/before.vtpf", out,
                               std::filesystem::copy_options::overwrite_existing);
    std::vector<uint8_t> bytes = read_bytes(dir + "/before.bin");
    change(bytes);
    std::ofstream(cache, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    auto again = run_json("-q bake " + obj + " -o " + out + " --update" + flags);
    EXPECT_EQ(read_bytes(out), expected);
    return again["transfer"]["bands_cached"].get<int>();
  };
  EXPECT_EQ(damage([](std::vector<uint8_t>&) {}), cached);  // undamaged: the same reuse
  EXPECT_EQ(damage([&](std::vector<uint8_t>& b) {
              // Every 7th byte between the header and the index (the trailer's first field).
              uint64_t index_offset = 0;
              std::memcpy(&index_offset, b.data() + b.size() - 24, sizeof index_offset);
              ASSERT_LE(index_offset, b.size());
              for (size_t i = 24; i < index_offset; i += 7) b[i] ^= 0x5a;
            }),
            0);
  EXPECT_EQ(damage([](std::vector<uint8_t>& b) { b.resize(b.size() / 2); }), 0);  // truncated
  EXPECT_EQ(damage([](std::vector<uint8_t>& b) { b.assign(100, 7); }), 0);        // garbage

  // Another setting: a full rebuild that says why, and no band of the old cache is used.
  auto other = run_json("-q bake " + obj + " -o " + out + " --update --supersample 4" + flags);
  EXPECT_EQ(other["build"]["update"]["full_rebuild"], "settings changed");
  EXPECT_EQ(other["transfer"]["bands_cached"], 0);
  run_json("-q bake " + obj + " -o " + dir + "/clean4.vtpf --supersample 4" + flags);
  EXPECT_EQ(read_bytes(out), read_bytes(dir + "/clean4.vtpf"));
}

// The unwrap cache beside the output (OUT.cache/unwrap.bin): an update after a texture change
// takes the previous unwrap (the geometry did not change) and gives the bytes of a clean bake;
// a damaged, truncated or foreign cache is never trusted (the scene is unwrapped again: the same
// bytes, and a good cache is written for the next update); a change the unwrap reads (another
// texture size, moved geometry) unwraps again.
TEST(CliUpdate, SceneBakeUpdateReusesTheUnwrapWhileTheGeometryStaysAndNeverTrustsADamagedOne) {
  const std::string obj = two_textured_quads();
  const std::string dir = dir_of(obj);
  const std::string flags = " --size 3", out = dir + "/w.vtpf";
  const std::string cache = out + ".cache/unwrap.bin";
  auto clean = run_json("-q bake " + obj + " -o " + out + flags);
  EXPECT_FALSE(clean["atlas"]["reused"].get<bool>());  // a bake without --update reads no cache
  ASSERT_TRUE(std::filesystem::exists(cache));
  std::filesystem::copy_file(out, dir + "/before.vtpf");
  const std::vector<uint8_t> good = read_bytes(cache);
  write_png(dir + "/textures/b.png", 64, 64, 5, {10, 10, 30, 30});
  run_json("-q bake " + obj + " -o " + dir + "/clean.vtpf --tables-from " + dir + "/before.vtpf" +
           flags + " --cache -");
  const std::vector<uint8_t> expected = read_bytes(dir + "/clean.vtpf");
  const std::vector<uint8_t> expected_scene = read_bytes(dir + "/clean.glb");

  // The cache as given (unchanged, or damaged), the previous output back in place, an update.
  auto update_with = [&](auto&& change) {
    std::filesystem::copy_file(dir + "/before.vtpf", out,
                               std::filesystem::copy_options::overwrite_existing);
    std::vector<uint8_t> bytes = good;
    change(bytes);
    std::ofstream(cache, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    auto u = run_json("-q bake " + obj + " -o " + out + " --update" + flags);
    EXPECT_EQ(u["build"]["update"]["full_rebuild"], nullptr) << u["build"]["update"].dump();
    EXPECT_EQ(read_bytes(out), expected);
    EXPECT_EQ(read_bytes(dir + "/w.glb"), expected_scene);
    return u["atlas"]["reused"].get<bool>();
  };
  EXPECT_TRUE(update_with([](std::vector<uint8_t>&) {}));
  EXPECT_EQ(read_bytes(cache), good);  // reused: left as it was
  ASSERT_GT(good.size(), 100u);
  // A byte of the compressed result flipped, the header's key changed, truncated, garbage, the
  // checksum of the packed result changed (header: magic, version, key at 16, sizes, checksum
  // at 40).
  EXPECT_FALSE(update_with([](std::vector<uint8_t>& b) { b[b.size() - 5] ^= 0x5a; }));
  // Unwrapped again and stored again: the next update takes it.
  const std::vector<uint8_t> rewritten = read_bytes(cache);
  EXPECT_TRUE(update_with([&](std::vector<uint8_t>& b) { b = rewritten; }));
  EXPECT_FALSE(update_with([](std::vector<uint8_t>& b) { b[16] ^= 1; }));
  EXPECT_FALSE(update_with([](std::vector<uint8_t>& b) { b.resize(b.size() / 2); }));
  EXPECT_FALSE(update_with([](std::vector<uint8_t>& b) { b.assign(100, 7); }));
  EXPECT_FALSE(update_with([](std::vector<uint8_t>& b) { b[40] ^= 1; }));
  EXPECT_TRUE(update_with([](std::vector<uint8_t>&) {}));

  // What the unwrap reads changes: unwrapped again, as a clean bake unwraps it.
  write_png(dir + "/textures/b.png", 32, 32, 5);  // another size: the sources' density may move
  auto resized = run_json("-q bake " + obj + " -o " + out + " --update" + flags);
  EXPECT_FALSE(resized["atlas"]["reused"].get<bool>());
  std::ofstream(obj, std::ios::app) << "v 5 0 0\nv 6 0 0\nv 6 2 0\nf 9/1 10/2 11/3\n";
  auto moved = run_json("-q bake " + obj + " -o " + out + " --update" + flags);
  EXPECT_FALSE(moved["atlas"]["reused"].get<bool>());
  run_json("-q bake " + obj + " -o " + dir + "/clean2.vtpf" + flags + " --cache -");
  EXPECT_EQ(read_bytes(dir + "/w.glb"), read_bytes(dir + "/clean2.glb"));
}

}  // namespace
}  // namespace vt
