// Statistics, threaded verification and level reassembly (the library side of `vtbake info`,
// `verify` and `extract`).
#include <gtest/gtest.h>

#include "format/page_file_inspect.h"
#include "page_file_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;

TEST(PageFileInspect, StatsCountEveryPage) {
  GeneratedFile f = small_file();
  const std::string path = temp_path("stats.vtpf");
  ASSERT_TRUE(write_file(f, path, 1, 0).ok());
  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok());
  PageFileStats stats = page_file_stats(**reader);
  ASSERT_EQ(stats.levels.size(), 3u);
  uint64_t stored_bytes = 0, raw = 0;
  for (uint32_t level = 0; level < 3; ++level) {
    uint64_t counts[3] = {}, bytes = 0;
    for (auto& p : f.pages) {
      if (p.id.level != level) continue;
      ++counts[int(p.state)];
      bytes += p.stored.size();
      if (p.state != PageState::kAbsent) raw += p.texels.size();
    }
    EXPECT_EQ(stats.levels[level].absent_pages, counts[0]);
    EXPECT_EQ(stats.levels[level].constant_pages, counts[1]);
    EXPECT_EQ(stats.levels[level].stored_pages, counts[2]);
    EXPECT_EQ(stats.levels[level].bytes, bytes);
    stored_bytes += bytes;
  }
  EXPECT_EQ(stats.stored_bytes, stored_bytes);
  EXPECT_EQ(stats.raw_bytes, raw);
  EXPECT_DOUBLE_EQ(stats.compression_ratio, double(raw) / double(stored_bytes));
}

TEST(PageFileInspect, VerifyFindsEveryBadPage) {
  GeneratedFile f = small_file();
  const std::string path = temp_path("verify.vtpf");
  ASSERT_TRUE(write_file(f, path, 1, 0).ok());
  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok());
  VerifyReport ok = verify_pages(**reader, 3);
  EXPECT_TRUE(ok.bad_pages.empty());
  uint64_t stored = 0;
  for (auto& p : f.pages) stored += p.state == PageState::kStored;
  EXPECT_EQ(ok.pages_checked, stored);

  // Damage two stored pages: both are reported, in index order, at 1 and 3 threads.
  std::vector<uint8_t> bytes = read_bytes(path);
  std::vector<PageEntry> damaged;
  for (auto& p : f.pages) {
    if (p.state != PageState::kStored || damaged.size() == 2) continue;
    auto e = (*reader)->entry(p.id, p.layer);
    bytes[e->offset + e->size / 2] ^= 1;
    damaged.push_back(*e);
  }
  const std::string bad = temp_path("verify_bad.vtpf");
  write_bytes(bad, bytes);
  for (bool checksums : {true, false}) {
    auto r = PageFileReader::open(bad, {checksums});
    ASSERT_TRUE(r.ok());
    for (int threads : {1, 3}) {
      VerifyReport report = verify_pages(**r, threads);
      ASSERT_EQ(report.bad_pages.size(), 2u);
      EXPECT_EQ(report.bad_pages[0].status.code(), ErrorCode::kCorrupt);
      EXPECT_NE(report.bad_pages[0].status.message().find(bad), std::string::npos);
    }
    // verify() and verify_page check the bytes whatever the reader's options.
    const VerifyReport report = verify_pages(**r, 1);
    const BadPage& first = report.bad_pages[0];
    EXPECT_EQ((*r)->verify().message(), first.status.message());
    EXPECT_NE(first.status.message().find(page_name(first.id, first.layer) + ": checksum"),
              std::string::npos)
        << first.status.message();
    EXPECT_EQ((*r)->verify_page(first.id, first.layer).code(), ErrorCode::kCorrupt);
  }
  EXPECT_TRUE((*reader)->verify().ok());
  for (auto& p : f.pages) EXPECT_TRUE((*reader)->verify_page(p.id, p.layer).ok());
  EXPECT_EQ((*reader)->verify_page({0, 99, 0}, 0).code(), ErrorCode::kInvalidArgument);
}

TEST(PageFileInspect, ExtractReassemblesEveryLevelExactly) {
  PageFileDesc desc;
  desc.geometry = {37, 22, 8, 2};  // ragged edges: the last page column and row are partial
  desc.layers = {layer("albedo", 3, TexelType::kU8, PageCodec::kRawZstd),
                 layer("height", 1, TexelType::kF32, PageCodec::kRaw)};
  const PageGeometry& g = desc.geometry;
  auto albedo = random_levels(g, 3, 1), height = random_levels(g, 4, 2);
  const std::string path = temp_path("extract.vtpf");
  {
    auto w = PageFileWriter::create(path, desc);
    ASSERT_TRUE(w.ok());
    for (uint32_t l = 0; l < g.level_count(); ++l)
      for (uint32_t y = 0; y < g.pages_y(l); ++y)
        for (uint32_t x = 0; x < g.pages_x(l); ++x) {
          auto a = cut_page(albedo[l], g.level_width(l), g.level_height(l), 3, g, {l, x, y});
          std::vector<uint8_t> z;
          ASSERT_TRUE(zstd_compress(a, 1, z).ok());
          ASSERT_TRUE((*w)->add_page({l, x, y}, 0, z).ok());
          auto h = cut_page(height[l], g.level_width(l), g.level_height(l), 4, g, {l, x, y});
          ASSERT_TRUE((*w)->add_page({l, x, y}, 1, h).ok());
        }
    ASSERT_TRUE((*w)->finish().ok());
  }
  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok());
  for (uint32_t l = 0; l < g.level_count(); ++l) {
    auto a = extract_level(**reader, l, 0);
    ASSERT_TRUE(a.ok()) << a.status().message();
    EXPECT_EQ(a->width, g.level_width(l));
    EXPECT_EQ(a->height, g.level_height(l));
    EXPECT_EQ(a->channels, 3u);
    EXPECT_EQ(a->texels, albedo[l]) << "level " << l;
    auto h = extract_level(**reader, l, 1);
    ASSERT_TRUE(h.ok());
    EXPECT_EQ(h->texel_type, TexelType::kF32);
    EXPECT_EQ(h->texels, height[l]) << "level " << l;
  }
  EXPECT_EQ(extract_level(**reader, g.level_count(), 0).status().code(),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(extract_level(**reader, 0, 2).status().code(), ErrorCode::kInvalidArgument);
}

TEST(PageFileInspect, ExtractFillsAbsentPagesFromNearestAncestor) {
  PageFileDesc desc;
  desc.geometry = {32, 32, 8, 2};  // 4x4 -> 2x2 -> 1x1
  desc.layers = {layer("albedo", 1, TexelType::kU8, PageCodec::kRaw)};
  const PageGeometry& g = desc.geometry;
  auto levels = random_levels(g, 1, 5);
  const std::string path = temp_path("ancestor.vtpf");
  {
    auto w = PageFileWriter::create(path, desc);
    ASSERT_TRUE(w.ok());
    // Level 0: only page (0, 0). Level 1: all but page (1, 1). Level 2: stored.
    auto add = [&](PageId id) {
      auto p =
          cut_page(levels[id.level], g.level_width(id.level), g.level_height(id.level), 1, g, id);
      ASSERT_TRUE((*w)->add_page(id, 0, p).ok());
    };
    add({0, 0, 0});
    add({1, 0, 0});
    add({1, 1, 0});
    add({1, 0, 1});
    add({2, 0, 0});
    ASSERT_TRUE((*w)->finish().ok());
  }
  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok());
  auto img = extract_level(**reader, 0, 0);
  ASSERT_TRUE(img.ok()) << img.status().message();
  EXPECT_EQ(img->filled_from_ancestor, 15u);
  EXPECT_EQ(img->filled_with_zero, 0u);
  for (uint32_t ty = 0; ty < 32; ++ty)
    for (uint32_t tx = 0; tx < 32; ++tx) {
      const uint32_t px = tx / 8, py = ty / 8;
      uint8_t expected;
      if (px == 0 && py == 0)
        expected = levels[0][ty * 32 + tx];
      else if (px / 2 == 1 && py / 2 == 1)
        expected = levels[2][(ty / 4) * 8 + tx / 4];  // level 1 page (1, 1) absent too
      else
        expected = levels[1][(ty / 2) * 16 + tx / 2];
      ASSERT_EQ(img->texels[ty * 32 + tx], expected) << tx << "," << ty;
    }
}

}  // namespace
}  // namespace vt
