// Hostile page files: every truncation, every flipped header/index bit (with and without the
// checksums recomputed so that the structural checks themselves are exercised), flipped data
// bits, and hand-crafted bad files. Each must give an error or the page exactly as written.
#include <gtest/gtest.h>
#include <xxhash.h>

#include "format/page_file.h"
#include "page_file_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;

uint64_t get64(const std::vector<uint8_t>& b, size_t at) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | b[at + i];
  return v;
}
uint32_t get32(const std::vector<uint8_t>& b, size_t at) {
  return uint32_t(b[at]) | uint32_t(b[at + 1]) << 8 | uint32_t(b[at + 2]) << 16 |
         uint32_t(b[at + 3]) << 24;
}
void put64(std::vector<uint8_t>& b, size_t at, uint64_t v) {
  for (int i = 0; i < 8; ++i) b[at + i] = uint8_t(v >> (8 * i));
}
void put32(std::vector<uint8_t>& b, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = uint8_t(v >> (8 * i));
}

// Where the sections of the pristine small file lie (docs/FORMAT.md).
struct Layout {
  size_t header_size, index_offset, index_size, data_offset, data_size;
};
Layout layout_of(const std::vector<uint8_t>& b) {
  return {get32(b, 12), size_t(get64(b, 48)), size_t(get64(b, 56)), size_t(get64(b, 64)),
          size_t(get64(b, 72))};
}

// Recomputes the index and header checksums of `b` at the pristine file's positions.
void fix_checksums(std::vector<uint8_t>& b, const Layout& l) {
  put64(b, 104, XXH3_64bits(b.data() + l.index_offset, l.index_size));
  put64(b, l.header_size - 8, XXH3_64bits(b.data(), l.header_size - 8));
}

class Corruption : public ::testing::Test {
 protected:
  void SetUp() override {
    file_ = small_file();
    pristine_path_ = temp_path("small.vtpf");
    ASSERT_TRUE(write_file(file_, pristine_path_, 1, 0).ok());
    pristine_ = read_bytes(pristine_path_);
    layout_ = layout_of(pristine_);
    mangled_path_ = temp_path("mangled.vtpf");
    int states[3] = {};
    for (auto& p : file_.pages) ++states[int(p.state)];
    ASSERT_GT(states[0], 0);
    ASSERT_GT(states[1], 0);
    ASSERT_GT(states[2], 0);
  }

  // Opens `bytes` as a page file; if it opens, every page must read back as written or fail.
  // Returns true when something reported an error.
  bool check(const std::vector<uint8_t>& bytes, bool verify_checksums = true) {
    write_bytes(mangled_path_, bytes);
    auto reader = PageFileReader::open(mangled_path_, {verify_checksums});
    if (!reader.ok()) {
      const Status& s = reader.status();
      EXPECT_TRUE(s.code() == ErrorCode::kCorrupt || s.code() == ErrorCode::kUnsupported)
          << s.message();
      EXPECT_NE(s.message().find(mangled_path_), std::string::npos) << s.message();
      return true;
    }
    bool error = !(*reader)->verify().ok();
    std::vector<uint8_t> texels;
    for (const ExpectedPage& p : file_.pages) {
      texels.assign((*reader)->decoded_page_bytes(p.layer), 0);
      Status s = (*reader)->read_texels(p.id, p.layer, texels);
      auto e = (*reader)->entry(p.id, p.layer);
      if (s.code() == ErrorCode::kNotFound && p.state == PageState::kAbsent && e.ok() &&
          e->state == PageState::kAbsent)
        continue;
      if (!s.ok()) {
        error = true;
        continue;
      }
      // A page that reads must be the page written, unless checksums were not asked for.
      if (verify_checksums) {
        EXPECT_NE(p.state, PageState::kAbsent);
        EXPECT_TRUE(texels == p.texels)
            << "page " << p.id.level << "," << p.id.x << "," << p.id.y << " layer " << p.layer;
      }
    }
    return error;
  }

  GeneratedFile file_;
  std::string pristine_path_, mangled_path_;
  std::vector<uint8_t> pristine_;
  Layout layout_;
};

TEST_F(Corruption, PristineFileReads) {
  EXPECT_FALSE(check(pristine_));
}

TEST_F(Corruption, TruncatedAtEveryOffset) {
  for (size_t size = 0; size < pristine_.size(); ++size) {
    std::vector<uint8_t> b(pristine_.begin(), pristine_.begin() + size);
    ASSERT_TRUE(check(b)) << "truncated to " << size;
  }
  std::vector<uint8_t> longer = pristine_;
  longer.push_back(0);
  EXPECT_TRUE(check(longer));
}

TEST_F(Corruption, EveryHeaderAndIndexBitFlipped) {
  const size_t end = layout_.index_offset + layout_.index_size;
  for (size_t byte = 0; byte < end; ++byte)
    for (int bit = 0; bit < 8; ++bit) {
      std::vector<uint8_t> b = pristine_;
      b[byte] ^= uint8_t(1 << bit);
      ASSERT_TRUE(check(b)) << "byte " << byte << " bit " << bit;
    }
}

// With the checksums recomputed the flip reaches the structural checks: each must give an
// error, or a file whose pages still read exactly as written (e.g. a renamed layer).
TEST_F(Corruption, EveryHeaderAndIndexBitFlippedWithChecksumsFixed) {
  const size_t end = layout_.index_offset + layout_.index_size;
  int opened = 0;
  for (size_t byte = 0; byte < end; ++byte)
    for (int bit = 0; bit < 8; ++bit) {
      std::vector<uint8_t> b = pristine_;
      b[byte] ^= uint8_t(1 << bit);
      fix_checksums(b, layout_);
      write_bytes(mangled_path_, b);
      if (PageFileReader::open(mangled_path_).ok()) ++opened;
      check(b);
      if (HasFatalFailure() || HasNonfatalFailure()) FAIL() << "byte " << byte << " bit " << bit;
    }
  EXPECT_LT(opened, int(end * 8) / 4);  // most flips are caught by the structural checks
}

// Several bytes at once, set to arbitrary values (large offsets and counts, not just one bit
// away from the truth), checksums recomputed so the structural checks see them.
TEST_F(Corruption, RandomBytesWithChecksumsFixed) {
  std::mt19937 rng(17);
  const size_t end = layout_.index_offset + layout_.index_size;
  for (int round = 0; round < 2000; ++round) {
    std::vector<uint8_t> b = pristine_;
    const int count = 1 + int(rng() % 4);
    for (int i = 0; i < count; ++i) b[rng() % end] = uint8_t(rng());
    fix_checksums(b, layout_);
    check(b);
    if (HasFatalFailure() || HasNonfatalFailure()) FAIL() << "round " << round;
  }
}

TEST_F(Corruption, DataBitsFlipped) {
  // Sample data bits evenly: every stored page is covered by a checksum, so each flip is caught.
  const size_t begin = layout_.data_offset, end = begin + layout_.data_size;
  for (size_t byte = begin; byte < end; byte += 7) {
    std::vector<uint8_t> b = pristine_;
    b[byte] ^= uint8_t(1 << (byte % 8));
    ASSERT_TRUE(check(b)) << "byte " << byte;
    check(b, /*verify_checksums=*/false);  // decoders meet corrupt bytes: no crash allowed
  }
}

TEST_F(Corruption, CraftedFiles) {
  auto open_code = [&](const std::vector<uint8_t>& b) {
    write_bytes(mangled_path_, b);
    auto r = PageFileReader::open(mangled_path_);
    return r.ok() ? ErrorCode::kOk : r.status().code();
  };
  auto open_message = [&](const std::vector<uint8_t>& b) {
    write_bytes(mangled_path_, b);
    auto r = PageFileReader::open(mangled_path_);
    return r.ok() ? std::string() : r.status().message();
  };
  std::vector<uint8_t> b = pristine_;
  b[0] = 'X';
  EXPECT_NE(open_message(b).find("bad magic"), std::string::npos);

  b = pristine_;
  put32(b, 8, 2);
  fix_checksums(b, layout_);
  EXPECT_EQ(open_code(b), ErrorCode::kUnsupported);
  EXPECT_NE(open_message(b).find("version 2"), std::string::npos);

  b = pristine_;
  put32(b, 16, 0xFFFFFFFFu);  // absurd width
  fix_checksums(b, layout_);
  EXPECT_EQ(open_code(b), ErrorCode::kCorrupt);

  b = pristine_;
  put32(b, 32, 0x7FFFFFFFu);  // absurd level count
  fix_checksums(b, layout_);
  EXPECT_NE(open_message(b).find("level count"), std::string::npos);

  b = pristine_;
  put32(b, 36, 1000000);  // absurd layer count
  fix_checksums(b, layout_);
  EXPECT_NE(open_message(b).find("layer count"), std::string::npos);

  b = pristine_;
  put64(b, 56, ~0ull);  // index size past the end of the file
  fix_checksums(b, layout_);
  EXPECT_EQ(open_code(b), ErrorCode::kCorrupt);

  b = pristine_;
  put64(b, 72, ~0ull - 100);  // data size that would wrap around
  fix_checksums(b, layout_);
  EXPECT_EQ(open_code(b), ErrorCode::kCorrupt);

  // Find two stored pages to aim at each other and past the end of the file.
  std::vector<size_t> stored;
  for (size_t e = 0; e < layout_.index_size / 32; ++e)
    if (pristine_[layout_.index_offset + e * 32] == 2) stored.push_back(e);
  ASSERT_GE(stored.size(), 2u);
  const size_t e0 = layout_.index_offset + stored[0] * 32;
  const size_t e1 = layout_.index_offset + stored[1] * 32;

  b = pristine_;
  put64(b, e0 + 8, pristine_.size() - 4);
  fix_checksums(b, layout_);
  EXPECT_NE(open_message(b).find("outside the data area"), std::string::npos);

  b = pristine_;
  put64(b, e0 + 8, ~0ull - 2);
  fix_checksums(b, layout_);
  EXPECT_NE(open_message(b).find("outside the data area"), std::string::npos);

  b = pristine_;
  put64(b, e0 + 8, 0);  // points into the header
  fix_checksums(b, layout_);
  EXPECT_NE(open_message(b).find("outside the data area"), std::string::npos);

  b = pristine_;
  put64(b, e1 + 8, get64(pristine_, e0 + 8) + 1);  // overlaps the first page
  fix_checksums(b, layout_);
  EXPECT_NE(open_message(b).find("overlap"), std::string::npos);

  b = pristine_;
  put32(b, e1 + 4, 0xFFFFFFFFu);  // size far past the data area
  fix_checksums(b, layout_);
  EXPECT_EQ(open_code(b), ErrorCode::kCorrupt);

  b = pristine_;
  b[e0] = 7;  // unknown state
  fix_checksums(b, layout_);
  EXPECT_NE(open_message(b).find("unknown page state"), std::string::npos);

  b.assign(8, 0);
  EXPECT_NE(open_message(b).find("truncated"), std::string::npos);

  write_bytes(mangled_path_, {});
  EXPECT_EQ(PageFileReader::open(mangled_path_).status().code(), ErrorCode::kCorrupt);
  EXPECT_EQ(PageFileReader::open(mangled_path_ + ".missing").status().code(), ErrorCode::kNotFound);
  EXPECT_FALSE(PageFileReader::open(std::filesystem::path(mangled_path_).parent_path()).ok());
}

}  // namespace
}  // namespace vt
