// Page file round trips: random pages written in random order from several threads read back
// bit-exact, the bytes do not depend on the thread count, reads are thread-safe, and the writer
// rejects bad calls and never leaves partial files.
#include <gtest/gtest.h>

#include <filesystem>
#include <thread>

#include "codec/dct.h"
#include "format/page_file.h"
#include "page_file_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;

PageFileDesc mixed_desc() {
  PageFileDesc desc;
  desc.geometry = {70, 45, 12, 2};  // 16x16 pages, 6x4 -> 3x2 -> 2x1 -> 1x1
  desc.layers = {layer("albedo", 4, TexelType::kU8, PageCodec::kRaw),
                 layer("height", 1, TexelType::kF32, PageCodec::kRawZstd),
                 layer("orm", 3, TexelType::kU8, PageCodec::kRawZstd),
                 layer("hdr", 2, TexelType::kF16, PageCodec::kRaw)};
  desc.layers[0].color_space = ColorSpace::kSrgb;
  desc.layers[1].semantic = LayerSemantic::kCustom;
  desc.layers[2].semantic = LayerSemantic::kOrm;
  desc.layers[2].address_mode = AddressMode::kWrap;
  desc.layers[3].semantic = LayerSemantic::kEmissive;
  desc.layers[3].codec_tables = {1, 2, 3};  // opaque tables travel with the layer
  desc.metadata_json = R"({"tool":"vtbake","seed":1})";
  return desc;
}

void expect_reads_back(const PageFileReader& reader, const GeneratedFile& f) {
  std::vector<uint8_t> texels;
  for (const ExpectedPage& p : f.pages) {
    auto e = reader.entry(p.id, p.layer);
    ASSERT_TRUE(e.ok()) << e.status().message();
    ASSERT_EQ(e->state, p.state);
    texels.assign(reader.decoded_page_bytes(p.layer), 0xCD);
    Status s = reader.read_texels(p.id, p.layer, texels);
    if (p.state == PageState::kAbsent) {
      EXPECT_EQ(s.code(), ErrorCode::kNotFound);
      EXPECT_EQ(reader.read_stored(p.id, p.layer).status().code(), ErrorCode::kNotFound);
      continue;
    }
    ASSERT_TRUE(s.ok()) << s.message();
    ASSERT_EQ(texels, p.texels);
    if (p.state == PageState::kStored) {
      EXPECT_EQ(e->size, p.stored.size());
      EXPECT_EQ(e->codec, f.desc.layers[p.layer].codec);
      auto stored = reader.read_stored(p.id, p.layer);
      ASSERT_TRUE(stored.ok()) << stored.status().message();
      ASSERT_EQ(*stored, p.stored);
    }
  }
}

TEST(PageFile, RoundTripIsBitExactAndIndependentOfThreads) {
  GeneratedFile f = generate(mixed_desc(), 1);
  const std::string one = temp_path("one.vtpf"), many = temp_path("many.vtpf");
  ASSERT_TRUE(write_file(f, one, 1, 0).ok());
  Status s = write_file(f, many, 6, 99);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(read_bytes(one), read_bytes(many));

  auto reader = PageFileReader::open(many);
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  const PageFileReader& r = **reader;
  EXPECT_EQ(r.version(), 1u);
  EXPECT_EQ(r.geometry().width, 70u);
  EXPECT_EQ(r.geometry().payload, 12u);
  EXPECT_EQ(r.metadata_json(), f.desc.metadata_json);
  EXPECT_EQ(r.file_size(), std::filesystem::file_size(many));
  ASSERT_EQ(r.layers().size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    const LayerSpec &a = r.layers()[i], &b = f.desc.layers[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.semantic, b.semantic);
    EXPECT_EQ(a.channels, b.channels);
    EXPECT_EQ(a.texel_type, b.texel_type);
    EXPECT_EQ(a.codec, b.codec);
    EXPECT_EQ(a.color_space, b.color_space);
    EXPECT_EQ(a.address_mode, b.address_mode);
    EXPECT_EQ(a.codec_tables, b.codec_tables);
  }
  EXPECT_EQ(r.decoded_page_bytes(1), 16u * 16 * 4);
  EXPECT_TRUE(r.verify().ok());
  expect_reads_back(r, f);
}

TEST(PageFile, DataIsInCanonicalOrder) {
  GeneratedFile f = generate(mixed_desc(), 2);
  const std::string path = temp_path("order.vtpf");
  ASSERT_TRUE(write_file(f, path, 3, 5).ok());
  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok());
  const PageGeometry& g = (*reader)->geometry();
  // Coarse levels first, Morton order inside a level, layers in order: offsets increase.
  uint64_t last = 0;
  for (uint32_t level = g.level_count(); level-- > 0;) {
    std::vector<std::pair<uint64_t, PageId>> pages;
    for (uint32_t y = 0; y < g.pages_y(level); ++y)
      for (uint32_t x = 0; x < g.pages_x(level); ++x)
        pages.push_back({morton_encode(x, y), PageId{level, x, y}});
    std::sort(pages.begin(), pages.end(), [](auto& a, auto& b) { return a.first < b.first; });
    for (auto& [code, id] : pages)
      for (uint32_t layer = 0; layer < 4; ++layer) {
        auto e = (*reader)->entry(id, layer);
        ASSERT_TRUE(e.ok());
        if (e->state != PageState::kStored) continue;
        EXPECT_GE(e->offset, last);
        last = e->offset + e->size;
      }
  }
  EXPECT_EQ(last + f.desc.metadata_json.size(), (*reader)->file_size());
}

TEST(PageFile, AlignedPagesStartOn4KiB) {
  PageFileDesc desc = mixed_desc();
  desc.align_pages_4k = true;
  GeneratedFile f = generate(desc, 3);
  const std::string path = temp_path("aligned.vtpf");
  ASSERT_TRUE(write_file(f, path, 2, 1).ok());
  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  int stored = 0;
  for (const ExpectedPage& p : f.pages) {
    auto e = (*reader)->entry(p.id, p.layer);
    ASSERT_TRUE(e.ok());
    if (e->state != PageState::kStored) continue;
    EXPECT_EQ(e->offset % 4096, 0u);
    ++stored;
  }
  EXPECT_GT(stored, 10);
  EXPECT_TRUE((*reader)->verify().ok());
  expect_reads_back(**reader, f);
}

TEST(PageFile, ConcurrentReads) {
  GeneratedFile f = generate(mixed_desc(), 4);
  const std::string path = temp_path("concurrent.vtpf");
  ASSERT_TRUE(write_file(f, path, 4, 2).ok());
  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok());
  std::vector<int> mismatches(4, 0);
  std::vector<std::thread> pool;
  for (int t = 0; t < 4; ++t)
    pool.emplace_back([&, t] {
      std::vector<uint8_t> texels;
      for (int round = 0; round < 3; ++round)
        for (size_t i = t; i < f.pages.size() * 2; i += 3) {
          const ExpectedPage& p = f.pages[i % f.pages.size()];
          if (p.state == PageState::kAbsent) continue;
          texels.resize((*reader)->decoded_page_bytes(p.layer));
          if (!(*reader)->read_texels(p.id, p.layer, texels).ok() || texels != p.texels)
            ++mismatches[t];
        }
    });
  for (auto& th : pool) th.join();
  for (int m : mismatches) EXPECT_EQ(m, 0);
}

TEST(PageFile, EmptyFileHasOnlyAbsentPages) {
  PageFileDesc desc;
  desc.geometry = {1, 1, 8, 2};
  desc.layers = {layer("", 4, TexelType::kU8, PageCodec::kRawZstd)};
  desc.metadata_json = "";
  const std::string path = temp_path("empty.vtpf");
  auto w = PageFileWriter::create(path, desc);
  ASSERT_TRUE(w.ok());
  ASSERT_TRUE((*w)->finish().ok());
  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  auto e = (*reader)->entry({0, 0, 0}, 0);
  ASSERT_TRUE(e.ok());
  EXPECT_EQ(e->state, PageState::kAbsent);
  EXPECT_TRUE((*reader)->verify().ok());
}

TEST(PageFileWriter, RejectsBadDescriptions) {
  const std::string path = temp_path("bad.vtpf");
  PageFileDesc desc = mixed_desc();
  desc.geometry.payload = 13;
  EXPECT_EQ(PageFileWriter::create(path, desc).status().code(), ErrorCode::kInvalidArgument);
  desc = mixed_desc();
  desc.layers.clear();
  EXPECT_FALSE(PageFileWriter::create(path, desc).ok());
  desc = mixed_desc();
  desc.layers[1].name = "albedo";
  EXPECT_FALSE(PageFileWriter::create(path, desc).ok());
  desc = mixed_desc();
  desc.layers[0].channels = 5;
  EXPECT_FALSE(PageFileWriter::create(path, desc).ok());
  desc = mixed_desc();
  desc.layers[1].codec = PageCodec::kDct;  // f32 texels cannot be DCT coded
  EXPECT_FALSE(PageFileWriter::create(path, desc).ok());
  desc = mixed_desc();
  desc.layers[0].codec = PageCodec::kBcZstd;  // runtime format rgba8 is not BC
  EXPECT_FALSE(PageFileWriter::create(path, desc).ok());
  desc = mixed_desc();
  desc.layers[0].name = std::string(256, 'a');
  EXPECT_FALSE(PageFileWriter::create(path, desc).ok());
  desc = mixed_desc();
  desc.layers[0].name = "d\xe9tail";  // Latin-1: names are UTF-8 (docs/FORMAT.md)
  EXPECT_FALSE(PageFileWriter::create(path, desc).ok());
  desc.layers[0].name = "d\xc3\xa9tail";
  EXPECT_TRUE(PageFileWriter::create(path, desc).ok());
  desc = mixed_desc();
  desc.layers[0].semantic = LayerSemantic::kLitAlbedo;  // the last semantic known
  desc.layers[0].name = "lit";
  EXPECT_TRUE(PageFileWriter::create(path, desc).ok());
  desc.layers[0].semantic = LayerSemantic(uint8_t(LayerSemantic::kLitAlbedo) + 1);
  EXPECT_FALSE(PageFileWriter::create(path, desc).ok());
  desc = mixed_desc();
  desc.layers.resize(17, desc.layers[0]);
  EXPECT_FALSE(PageFileWriter::create(path, desc).ok());
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_EQ(PageFileWriter::create("/nonexistent-dir/x.vtpf", mixed_desc()).status().code(),
            ErrorCode::kIo);
}

TEST(PageFileWriter, RejectsBadPages) {
  const std::string path = temp_path("badpages.vtpf");
  PageFileDesc desc = mixed_desc();
  auto w = PageFileWriter::create(path, desc);
  ASSERT_TRUE(w.ok());
  PageFileWriter& writer = **w;
  std::vector<uint8_t> raw(16 * 16 * 4, 7), texel(4, 1);
  EXPECT_TRUE(writer.add_page({0, 5, 3}, 0, raw).ok());
  Status dup = writer.add_page({0, 5, 3}, 0, raw);
  EXPECT_EQ(dup.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(dup.message().find("twice"), std::string::npos) << dup.message();
  EXPECT_FALSE(writer.add_constant_page({0, 5, 3}, 0, texel).ok());
  EXPECT_FALSE(writer.add_page({0, 6, 0}, 0, raw).ok());  // x outside level 0
  EXPECT_FALSE(writer.add_page({0, 0, 4}, 0, raw).ok());
  EXPECT_FALSE(writer.add_page({4, 0, 0}, 0, raw).ok());                       // no level 4
  EXPECT_FALSE(writer.add_page({3, 0, 0}, 4, raw).ok());                       // no layer 4
  EXPECT_FALSE(writer.add_page({0, 0, 0}, 0, std::vector<uint8_t>(10)).ok());  // raw size
  EXPECT_FALSE(writer.add_page({0, 0, 0}, 1, {}).ok());
  EXPECT_FALSE(writer.add_constant_page({0, 0, 0}, 1, std::vector<uint8_t>(3)).ok());
  EXPECT_TRUE(writer.add_constant_page({0, 0, 0}, 1, texel).ok());
  ASSERT_TRUE(writer.finish().ok());
  EXPECT_FALSE(writer.add_page({1, 0, 0}, 0, raw).ok());
  EXPECT_FALSE(writer.finish().ok());
  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok());
  EXPECT_EQ((*reader)->entry({0, 5, 3}, 0)->state, PageState::kStored);
  EXPECT_EQ((*reader)->entry({0, 0, 0}, 1)->state, PageState::kConstant);
  EXPECT_EQ((*reader)->entry({1, 0, 0}, 0)->state, PageState::kAbsent);
  EXPECT_EQ((*reader)->entry({0, 6, 0}, 0).status().code(), ErrorCode::kInvalidArgument);
  std::vector<uint8_t> small(3);
  EXPECT_EQ((*reader)->read_texels({0, 5, 3}, 0, small).code(), ErrorCode::kInvalidArgument);
}

TEST(PageFileWriter, AbandonedWriterLeavesNoFiles) {
  const std::string path = temp_path("abandoned.vtpf");
  const auto dir = std::filesystem::path(path).parent_path();
  std::vector<uint8_t> previous = {1, 2, 3};
  write_bytes(path, previous);
  {
    auto w = PageFileWriter::create(path, mixed_desc());
    ASSERT_TRUE(w.ok());
    std::vector<uint8_t> raw(16 * 16 * 4, 7);
    ASSERT_TRUE((*w)->add_page({0, 0, 0}, 0, raw).ok());
  }
  EXPECT_EQ(read_bytes(path), previous);
  size_t files = 0;
  for (auto& entry : std::filesystem::directory_iterator(dir)) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 1u);  // only the untouched original: no temporary or spill file
}

TEST(PageFileWriter, FinishReplacesExistingFile) {
  GeneratedFile f = generate(mixed_desc(), 6);
  const std::string path = temp_path("replace.vtpf");
  write_bytes(path, {1, 2, 3});
  ASSERT_TRUE(write_file(f, path, 2, 3).ok());
  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok());
  expect_reads_back(**reader, f);
  size_t files = 0;
  for (auto& entry :
       std::filesystem::directory_iterator(std::filesystem::path(path).parent_path())) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 1u);
}

}  // namespace
}  // namespace vt
