// The build's plan (trained tables up front, plan hash), its tasks (dependencies, content keys)
// and the level store the tasks write.
#include <gtest/gtest.h>

#include <zstd.h>

#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <thread>

#include "bake/build_plan.h"
#include "bake/build_tasks.h"
#include "bake/level_source.h"
#include "bake/level_store.h"
#include "codec/dct.h"
#include "samples/procedural.h"
#include "tests/bake/bake_test_util.h"

namespace vt {
namespace {

std::shared_ptr<ImageSource> procedural(uint32_t w, uint32_t h, uint32_t seed = 11) {
  return std::make_shared<ProceduralImageSource>(ProceduralPattern::kAlbedo, w, h, 3, seed);
}

std::vector<float> procedural_texels(uint32_t w, uint32_t h) {
  std::vector<float> t(size_t(w) * h * 3);
  EXPECT_TRUE(procedural(w, h)->read_rows(0, h, t.data()).ok());
  return t;
}

std::shared_ptr<ImageSource> memory_image(uint32_t w, uint32_t h, std::vector<float> texels) {
  ImageInfo info;
  info.width = w, info.height = h, info.channels = 3, info.color_space = "sRGB";
  return std::make_shared<MemoryImageSource>(info, std::move(texels));
}

BuildOptions raw_options(std::shared_ptr<ImageSource> source) {
  BuildOptions o;
  o.layers.push_back(test::layer_input(LayerSemantic::kAlbedo, std::move(source)));
  o.payload = 8;
  o.codec.codec = CodecKind::kRaw;
  return o;
}

TEST(BuildPlan, HashNamesSettingsAndContentButNotThreadsOrMemory) {
  BuildOptions o = raw_options(procedural(100, 60));
  auto a = plan_build(o);
  o.threads = 3;
  o.memory_limit = 1;
  auto same = plan_build(o);
  o.filter = MipFilter::kBox;
  auto other_filter = plan_build(o);
  o = raw_options(procedural(100, 60, 12));  // other texels, same size
  auto other_content = plan_build(o);
  ASSERT_TRUE(a.ok() && same.ok() && other_filter.ok() && other_content.ok());
  EXPECT_EQ(a->hash, same->hash);
  EXPECT_NE(a->hash, other_filter->hash);
  EXPECT_NE(a->hash, other_content->hash);
}

// More level-0 pages than a training set holds: the tables come from pages spread evenly over
// 16 page rows spread evenly down the level, not from its first rows.
TEST(BuildPlan, TablesAreTrainedOnASpreadSampleOfALargeLevel) {
  const uint32_t w = 8 * 24, h = 8 * 40;  // 24 x 40 = 960 pages of 8x8 payload
  BuildOptions o = raw_options(procedural(w, h));
  auto raw = test::build_in_memory(o);
  ASSERT_TRUE(raw);
  o.codec.codec = CodecKind::kDct;
  auto plan = plan_build(o);
  ASSERT_TRUE(plan.ok());

  const PageGeometry& g = plan->desc.geometry;
  const uint32_t S = g.page_size();
  ASSERT_EQ(g.pages_y(0), 40u);
  std::vector<std::vector<uint8_t>> sample;
  for (uint32_t k = 0; k < 16; ++k) {
    const uint32_t y = (2 * k + 1) * 40 / 32;  // rows 1, 3, 6, 8, ... 38
    for (uint32_t j = 0; j < 16; ++j) {
      const uint32_t x = (2 * j + 1) * 24 / 32;
      const auto& page = raw->sink.pages.at({0, 0, y, x});
      if (page.state != PageState::kStored) continue;  // constant pages teach nothing
      std::vector<uint8_t> texels(size_t(S) * S * 3);
      ASSERT_EQ(ZSTD_decompress(texels.data(), texels.size(), page.bytes.data(), page.bytes.size()),
                texels.size());
      sample.push_back(std::move(texels));
    }
  }
  ASSERT_GT(sample.size(), 200u);
  std::vector<std::span<const uint8_t>> spans(sample.begin(), sample.end());
  DctSettings s;
  s.quality = o.codec.dct_quality;
  s.channels = 3;
  s.layout = DctPlaneLayout::kYCoCg420;
  auto expected = dct_make_tables(s, int(S), int(S), spans);
  ASSERT_TRUE(expected.ok());
  EXPECT_EQ(plan->desc.layers[0].codec_tables, dct_serialize_tables(**expected));
}

TEST(BuildTasks, BandsDependOnExactlyTheRowsTheyRead) {
  for (AddressMode mode : {AddressMode::kClamp, AddressMode::kWrap}) {
    BuildOptions o = raw_options(procedural(77, 131));
    o.address = mode;
    o.filter = MipFilter::kLanczos3;
    auto plan = plan_build(o);
    ASSERT_TRUE(plan.ok());
    const PageGeometry& g = plan->desc.geometry;
    const std::vector<BuildTask> tasks = make_build_tasks(*plan);
    size_t bands = 0;
    for (uint32_t l = 0; l < g.level_count(); ++l) bands += g.pages_y(l);
    ASSERT_EQ(tasks.size(), bands);  // no whole-level work without coverage or alpha
    const uint32_t P = g.payload, half = P / 2, m = plan->margin;
    for (size_t i = 0; i < tasks.size(); ++i) {
      const BuildTask& t = tasks[i];
      ASSERT_EQ(t.kind, BuildTask::Kind::kBand);
      if (t.level == 0) {
        EXPECT_TRUE(t.deps.empty());
        continue;
      }
      std::set<uint32_t> rows_read, rows_written;
      for (int64_t y = int64_t(t.row) * P - m; y < int64_t(t.row) * P + P + m; ++y)
        rows_read.insert(uint32_t(address_texel(y, g.level_height(t.level), mode)));
      for (uint32_t d : t.deps) {
        ASSERT_LT(d, i);
        const BuildTask& dep = tasks[d];
        EXPECT_EQ(dep.level + 1, t.level);
        bool useful = false;
        for (uint32_t y = dep.row * half;
             y < std::min(g.level_height(t.level), dep.row * half + half); ++y) {
          rows_written.insert(y);
          useful |= rows_read.count(y) > 0;
        }
        EXPECT_TRUE(useful) << "task " << i << " depends on task " << d << " for nothing";
      }
      for (uint32_t y : rows_read) EXPECT_TRUE(rows_written.count(y)) << "row " << y;
    }
  }
}

TEST(BuildTasks, CoverageLevelsWaitForTheWholeLevelBefore) {
  const uint32_t w = 64, h = 40;
  auto coverage = std::make_shared<std::vector<uint8_t>>(size_t(w) * h, 0);
  for (uint32_t y = 5; y < 30; ++y)
    for (uint32_t x = 3; x < 50; ++x) (*coverage)[size_t(y) * w + x] = 1;
  BuildOptions o = raw_options(memory_image(w, h, procedural_texels(w, h)));
  o.layers[0].coverage = CoverageMask::from_bytes(w, h, coverage->data());
  auto plan = plan_build(o);
  ASSERT_TRUE(plan.ok());
  const std::vector<BuildTask> tasks = make_build_tasks(*plan);
  const PageGeometry& g = plan->desc.geometry;
  for (uint32_t l = 1; l < g.level_count(); ++l) {
    auto it = std::find_if(tasks.begin(), tasks.end(), [&](const BuildTask& t) {
      return t.kind == BuildTask::Kind::kLevel && t.level == l;
    });
    ASSERT_NE(it, tasks.end()) << "level " << l;
    EXPECT_EQ(it->deps.size(), g.pages_y(l - 1));
    const uint32_t whole = uint32_t(it - tasks.begin());
    for (const BuildTask& t : tasks) {
      if (t.kind == BuildTask::Kind::kBand && t.level == l) {
        EXPECT_EQ(t.deps, std::vector<uint32_t>{whole});
      }
    }
  }
}

// A band's key is its input: change one texel near the bottom and only the bands that read it,
// and those fed by them, change key.
TEST(BuildTasks, KeysChangeOnlyWithTheirInputRows) {
  const uint32_t w = 64, h = 80;
  std::vector<float> texels = procedural_texels(w, h);
  auto a = test::build_in_memory(raw_options(memory_image(w, h, texels)));
  BuildOptions threaded = raw_options(memory_image(w, h, texels));
  threaded.threads = 4;
  auto a4 = test::build_in_memory(threaded);
  auto again = test::build_in_memory(raw_options(memory_image(w, h, texels)));
  texels[(size_t(h - 2) * w + 10) * 3] += 0.25f;
  BuildOptions changed = raw_options(memory_image(w, h, texels));
  auto b = test::build_in_memory(changed);
  ASSERT_TRUE(a && a4 && again && b);
  EXPECT_EQ(a->summary.task_keys, again->summary.task_keys);
  EXPECT_EQ(a->summary.task_keys, a4->summary.task_keys);
  auto plan = plan_build(changed);
  ASSERT_TRUE(plan.ok());
  const std::vector<BuildTask> tasks = make_build_tasks(*plan);
  ASSERT_EQ(tasks.size(), a->summary.task_keys.size());
  const uint32_t rows0 = plan->desc.geometry.pages_y(0);
  for (size_t i = 0; i < tasks.size(); ++i) {
    if (tasks[i].level != 0) continue;
    if (tasks[i].row + 2 < rows0) {
      EXPECT_EQ(a->summary.task_keys[i], b->summary.task_keys[i]) << "row " << tasks[i].row;
    } else if (tasks[i].row + 1 == rows0) {
      EXPECT_NE(a->summary.task_keys[i], b->summary.task_keys[i]);
    }
  }
  EXPECT_NE(a->summary.plan_hash, b->summary.plan_hash);
}

// Scene bakes hand their buffers over: the build converts them in place and writes the same
// pages as from a copy.
TEST(LevelSource, ConsumedSourceIsConvertedInPlaceWithTheSameResult) {
  const uint32_t w = 48, h = 40;
  auto coverage = std::make_shared<std::vector<uint8_t>>(size_t(w) * h, 1);
  for (uint32_t x = 0; x < w; ++x) (*coverage)[x] = 0;
  BuildOptions copy = raw_options(memory_image(w, h, procedural_texels(w, h)));
  copy.layers[0].coverage = CoverageMask::from_bytes(w, h, coverage->data());
  BuildOptions consume = raw_options(memory_image(w, h, procedural_texels(w, h)));
  consume.layers[0].coverage = copy.layers[0].coverage;
  consume.layers[0].consume_source = true;
  auto source = std::static_pointer_cast<MemoryImageSource>(consume.layers[0].source);
  auto a = test::build_in_memory(copy);
  auto b = test::build_in_memory(consume);
  ASSERT_TRUE(a && b);
  EXPECT_TRUE(source->texels().empty());  // taken, not copied
  EXPECT_EQ(a->sink.pages.size(), b->sink.pages.size());
  for (const auto& [key, page] : a->sink.pages) EXPECT_EQ(page.bytes, b->sink.pages.at(key).bytes);
}

// A scene bake's scratch-file layer is converted in its own file (no second copy): the plan
// hash, the pages and the source's content hash are those of a build from a copy.
TEST(LevelSource, ScratchSourceIsConvertedInItsOwnFileWithTheSameResult) {
  const uint32_t w = 48, h = 40;
  const std::vector<float> texels = procedural_texels(w, h);
  std::vector<uint8_t> coverage(size_t(w) * h, 1);
  for (uint32_t x = 0; x < w; ++x) coverage[x] = 0;
  const std::string dir = std::filesystem::temp_directory_path().string();
  auto store = LevelStore::create(w, h, 3, false, dir);
  ASSERT_TRUE(store.ok());
  ASSERT_TRUE((*store)->write_rows(0, h, texels.data()).ok());
  std::shared_ptr<LevelStore> shared = std::move(*store);
  auto stored = std::make_shared<StoredImageSource>(memory_image(w, h, {})->info(), shared);
  const uint64_t source_hash = *stored->content_hash();
  ASSERT_NE(stored->scratch_store(), nullptr);

  BuildOptions copy = raw_options(memory_image(w, h, texels));
  copy.layers[0].coverage = CoverageMask::from_bytes(w, h, coverage.data());
  BuildOptions own = raw_options(stored);
  own.layers[0].coverage = copy.layers[0].coverage;
  own.layers[0].consume_source = true;
  own.memory_limit = copy.memory_limit = 16 << 10;  // level 0 in a scratch file
  auto a = plan_build(copy), b = plan_build(own);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_FALSE(b->layers[0].level0->in_memory());
  EXPECT_EQ(a->hash, b->hash);
  EXPECT_EQ(*stored->content_hash(), source_hash);  // as read, before the conversion
  EXPECT_EQ(stored->scratch_store(), nullptr);      // taken once
  std::vector<float> rows(texels.size());
  EXPECT_FALSE(stored->read_rows(0, h, rows.data()).ok());
  ASSERT_TRUE(shared->read(0, h, rows.data()).ok());
  EXPECT_NE(rows, texels);  // the store now holds the working form (linear, dilated)
  test::MemorySink sa, sb;
  ASSERT_TRUE(build_pages(*a, sa).ok());
  ASSERT_TRUE(build_pages(*b, sb).ok());
  EXPECT_EQ(sa.pages.size(), sb.pages.size());
  for (const auto& [key, page] : sa.pages) EXPECT_EQ(page.bytes, sb.pages.at(key).bytes);
}

TEST(LevelStore, MemoryAndScratchHoldTheSameRows) {
  const uint32_t w = 37, h = 23, ch = 3;
  std::vector<float> rows(size_t(w) * h * ch);
  for (size_t i = 0; i < rows.size(); ++i) rows[i] = float(i) * 0.5f;
  for (int kind = 0; kind < 3; ++kind) {  // in memory, raw scratch, compressed scratch
    const bool in_memory = kind == 0;
    auto store = LevelStore::create(w, h, ch, in_memory,
                                    std::filesystem::temp_directory_path().string(), kind == 2);
    ASSERT_TRUE(store.ok());
    EXPECT_EQ((*store)->in_memory(), in_memory);
    ASSERT_TRUE((*store)->write_rows(0, 10, rows.data()).ok());
    ASSERT_TRUE((*store)->write_rows(10, h - 10, rows.data() + size_t(10) * w * ch).ok());
    std::vector<float> back(size_t(5) * w * ch);
    ASSERT_TRUE((*store)->read(7, 12, back.data()).ok());
    EXPECT_TRUE(std::equal(back.begin(), back.end(), rows.begin() + size_t(7) * w * ch));
    EXPECT_FALSE((*store)->read(20, h + 1, back.data()).ok());
    EXPECT_FALSE((*store)->write_rows(h - 1, 2, rows.data()).ok());
    // Scratch levels dilate too (in bands: level_dilation.h).
    EXPECT_TRUE((*store)->set_coverage_and_dilate(std::vector<uint8_t>(size_t(w) * h, 1)).ok());
  }
}

// An opaque albedo store loses its alpha in place, in memory and in its scratch file (which
// shrinks to the 3-channel size), with rows that cross the copy's bands.
TEST(LevelStore, KeepChannelsDropsTheLastChannelsInPlace) {
  const uint32_t w = 300, h = 9000, ch = 4;  // ~4.3 MiB a scratch band: two bands and a bit
  std::vector<float> rows(size_t(w) * h * ch);
  for (size_t i = 0; i < rows.size(); ++i) rows[i] = float(i % 1000003);
  std::vector<float> want(size_t(w) * h * 3);
  for (size_t t = 0; t < size_t(w) * h; ++t)
    for (uint32_t c = 0; c < 3; ++c) want[3 * t + c] = rows[ch * t + c];
  for (int kind = 0; kind < 3; ++kind) {  // in memory, raw scratch, compressed scratch
    const bool in_memory = kind == 0;
    auto store = LevelStore::create(w, h, ch, in_memory,
                                    std::filesystem::temp_directory_path().string(), kind == 2);
    ASSERT_TRUE(store.ok());
    ASSERT_TRUE((*store)->write_rows(0, h, rows.data()).ok());
    ASSERT_TRUE((*store)->keep_channels(3).ok());
    EXPECT_EQ((*store)->channels(), 3u);
    EXPECT_EQ((*store)->bytes(), uint64_t(w) * h * 3 * sizeof(float));
    std::vector<float> back(want.size());
    ASSERT_TRUE((*store)->read(0, h, back.data()).ok());
    EXPECT_TRUE(back == want) << "kind " << kind;
    if (kind == 1) {
      EXPECT_EQ((*store)->disk_bytes(), (*store)->bytes());  // the file shrank
    }
    EXPECT_FALSE((*store)->read(h, h + 1, back.data()).ok());
  }
}

// Blocks the process's open scratch levels take on disk (unnamed O_TMPFILE files, "DIR/#INODE
// (deleted)", or unlinked .vtbake-level-* files where the file system has no O_TMPFILE).
uint64_t scratch_level_blocks_bytes() {
  uint64_t total = 0;
  for (const auto& fd : std::filesystem::directory_iterator("/proc/self/fd")) {
    std::error_code ec;
    const std::string target = std::filesystem::read_symlink(fd.path(), ec).string();
    struct stat st;
    const bool unnamed = target.find("/#") != std::string::npos && target.ends_with(" (deleted)");
    if (!ec && (unnamed || target.find("/.vtbake-level-") != std::string::npos) &&
        stat(fd.path().c_str(), &st) == 0)
      total += uint64_t(st.st_blocks) * 512;
  }
  return total;
}

// A scratch store compresses its rows in chunks (65 rows of 1,000 RGBA texels here): rows never
// written read as zeros, writes of a few rows keep the rest of their chunks, concurrent reads of
// parts of chunks see the same rows, and the disk it holds follows what it holds (a rewrite to
// constant rows frees the blocks of the noisy ones).
TEST(LevelStore, ScratchRowsAreCompressedChunksThatPartialWritesPatch) {
  const uint32_t w = 1000, h = 300, ch = 4;
  const size_t row = size_t(w) * ch;
  auto made =
      LevelStore::create(w, h, ch, false, std::filesystem::temp_directory_path().string(), true);
  ASSERT_TRUE(made.ok());
  LevelStore& store = **made;
  std::vector<float> want(row * h, 0.0f), back(row * h);
  ASSERT_TRUE(store.read(0, h, back.data()).ok());
  EXPECT_TRUE(back == want);
  EXPECT_EQ(store.disk_bytes(), 0u);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> noise(0.0f, 1.0f);
  const std::pair<uint32_t, uint32_t> pieces[] = {{60, 7}, {0, 3},   {130, 100}, {299, 1},
                                                  {3, 57}, {67, 63}, {230, 69}};
  for (auto [y0, rows] : pieces) {
    for (size_t i = y0 * row; i < (y0 + rows) * row; ++i) want[i] = noise(rng);
    ASSERT_TRUE(store.write_rows(y0, rows, want.data() + y0 * row).ok());
  }
  ASSERT_TRUE(store.read(0, h, back.data()).ok());
  EXPECT_TRUE(back == want);
  const uint64_t noisy = store.disk_bytes();
  EXPECT_GT(noisy, store.bytes() / 4);  // random floats barely compress
  EXPECT_GE(scratch_level_blocks_bytes(), noisy);
  std::vector<std::thread> readers;
  std::atomic<int> wrong{0};
  for (int t = 0; t < 4; ++t)
    readers.emplace_back([&, t] {
      std::mt19937 r(t);
      std::vector<float> part(row * h);
      for (int i = 0; i < 200; ++i) {
        const uint32_t y0 = r() % h, y1 = y0 + 1 + r() % std::min<uint32_t>(h - y0, 9);
        if (!store.read(y0, y1, part.data()).ok() ||
            !std::equal(part.begin(), part.begin() + (y1 - y0) * row, want.begin() + y0 * row))
          ++wrong;
      }
    });
  for (auto& t : readers) t.join();
  EXPECT_EQ(wrong.load(), 0);
  std::fill(want.begin(), want.end(), 0.25f);
  for (uint32_t y = 0; y < h; y += 50) ASSERT_TRUE(store.write_rows(y, 50, want.data()).ok());
  ASSERT_TRUE(store.read(0, h, back.data()).ok());
  EXPECT_TRUE(back == want);
  // Whole chunks go straight to disk (partly written ones wait in the store's two decoded chunks).
  ASSERT_TRUE(store.write_rows(0, h, want.data()).ok());
  ASSERT_TRUE(store.read(0, h, back.data()).ok());
  EXPECT_TRUE(back == want);
  EXPECT_LT(store.disk_bytes(), noisy / 20);
  EXPECT_LT(scratch_level_blocks_bytes(), noisy / 10);  // the old frames' tails punched
}

// Open descriptors of this process on the file at `path` (a scratch file linked there).
int descriptors_of(const std::string& path) {
  struct stat want, st;
  if (stat(path.c_str(), &want) != 0) return -1;
  int n = 0;
  for (const auto& fd : std::filesystem::directory_iterator("/proc/self/fd"))
    n += stat(fd.path().c_str(), &st) == 0 && st.st_ino == want.st_ino && st.st_dev == want.st_dev;
  return n;
}

// A level saved for the farm's shards (LevelStore::save) reads back as the same rows through
// open_saved, from memory, raw scratch and compressed scratch, linked or copied: a compressed
// level keeps its chunks (fewer bytes than raw on disk), rows never written read as zeros, a
// part written last (still in the decoded chunks) is in the file, the store is read only after,
// and a file of another shape, cut short or with a damaged footer is refused, naming it.
TEST(LevelStore, SavedLevelsReadBackAsTheSameRows) {
  const std::string dir = std::filesystem::temp_directory_path().string() + "/vt_saved_levels";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const uint32_t w = 3000, h = 97, ch = 3;  // compressed: 4 chunks of 29 rows
  const size_t row = size_t(w) * ch;
  for (int kind = 0; kind < 3; ++kind)
    for (bool link : {true, false}) {
      SCOPED_TRACE("kind " + std::to_string(kind) + (link ? " linked" : " copied"));
      auto made = LevelStore::create(w, h, ch, kind == 0, dir, kind == 2);
      ASSERT_TRUE(made.ok());
      LevelStore& store = **made;
      std::vector<float> want(row * h, 0.0f);
      for (uint32_t y = 0; y < 60; ++y)  // rows 60-96 never written except 70-72
        for (size_t i = 0; i < row; ++i) want[y * row + i] = float((y * 7 + i) % 13) * 0.125f;
      ASSERT_TRUE(store.write_rows(0, 60, want.data()).ok());
      for (size_t i = 70 * row; i < 73 * row; ++i) want[i] = 0.5f;
      ASSERT_TRUE(store.write_rows(70, 3, want.data() + 70 * row).ok());
      const std::string path = dir + "/level" + std::to_string(kind) + (link ? "l" : "c");
      { std::ofstream(path) << "staged"; }  // an empty staging file is replaced
      const Status saved = store.save(path, link);
      ASSERT_TRUE(saved.ok()) << saved.message();
      const bool compressed = store.compressed();
      EXPECT_EQ(compressed, kind == 2);
      EXPECT_EQ(descriptors_of(path), kind != 0 && link ? 1 : 0);
      if (kind != 0) {
        EXPECT_FALSE(store.write_rows(0, 1, want.data()).ok());
      }
      struct stat st;
      ASSERT_EQ(stat(path.c_str(), &st), 0);
      if (kind == 2) {
        EXPECT_LT(uint64_t(st.st_blocks) * 512, store.bytes() / 2);
      }
      made->reset();  // the store's file is gone; the saved one stays
      auto back = LevelStore::open_saved(path, w, h, ch, compressed);
      ASSERT_TRUE(back.ok()) << back.status().message();
      std::vector<float> rows(row * h, -1.0f);
      ASSERT_TRUE((*back)->read(0, h, rows.data()).ok());
      EXPECT_TRUE(rows == want);
      ASSERT_TRUE((*back)->read(65, 71, rows.data()).ok());
      EXPECT_TRUE(std::equal(rows.begin(), rows.begin() + 6 * row, want.begin() + 65 * row));
      EXPECT_FALSE((*back)->write_rows(0, 1, want.data()).ok());

      auto other = LevelStore::open_saved(path, w, h + 1, ch, compressed);
      ASSERT_FALSE(other.ok());
      EXPECT_EQ(other.status().code(), ErrorCode::kCorrupt);
      EXPECT_NE(other.status().message().find(path), std::string::npos);
      if (kind == 2) {
        std::filesystem::resize_file(path, std::filesystem::file_size(path) - 1);
        EXPECT_EQ(LevelStore::open_saved(path, w, h, ch, true).status().code(),
                  ErrorCode::kCorrupt);
      }
    }
  std::filesystem::remove_all(dir);
}

TEST(LevelStore, DilationFillsUncoveredTexelsFromCoveredOnes) {
  const uint32_t w = 16, h = 8;
  std::vector<float> texels(size_t(w) * h, 0.0f);
  std::vector<uint8_t> coverage(size_t(w) * h, 0);
  for (uint32_t y = 2; y < 4; ++y)
    for (uint32_t x = 2; x < 6; ++x) texels[y * w + x] = 0.75f, coverage[y * w + x] = 1;
  auto store = LevelStore::adopt(w, h, 1, texels);
  ASSERT_TRUE(store->set_coverage_and_dilate(coverage).ok());
  ASSERT_NE(store->coverage(), nullptr);
  for (size_t i = 0; i < texels.size(); ++i) EXPECT_FLOAT_EQ(store->data()[i], 0.75f) << i;
}

}  // namespace
}  // namespace vt
