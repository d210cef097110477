// Hostile inputs and outputs (issue 20): header fields that contradict each other with every
// checksum recomputed, sizes a tiny file claims, files changed under an open reader, FIFOs and
// directories as inputs, and output paths that are links, FIFOs, directories or devices.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

#include <chrono>

#include "codec/dct.h"
#include "format/atomic_output.h"
#include "format/page_file.h"
#include "format/page_file_inspect.h"
#include "format/page_file_layout.h"
#include "page_file_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;
using namespace vt::pagefile;

constexpr int kDctPage = 16;

// One DCT layer of 3 channels (YCoCg tables coding 3 channels), one 16x16 page per level.
std::string write_dct_file(const std::string& name) {
  PageFileDesc desc;
  desc.geometry = {24, 12, 12, 2};  // 16x16 pages: 2x1 -> 1x1
  LayerSpec spec = layer("albedo", 3, TexelType::kU8, PageCodec::kDct);
  DctSettings s;
  s.channels = 3;
  auto tables = dct_make_tables(s, kDctPage, kDctPage);
  EXPECT_TRUE(tables.ok());
  spec.codec_tables = dct_serialize_tables(**tables);
  desc.layers = {spec};
  const std::string path = temp_path(name);
  auto w = PageFileWriter::create(path, desc);
  EXPECT_TRUE(w.ok()) << w.status().message();
  std::vector<uint8_t> texels(size_t(kDctPage) * kDctPage * 3);
  for (size_t i = 0; i < texels.size(); ++i) texels[i] = uint8_t(i * 5);
  std::vector<uint8_t> coded;
  EXPECT_TRUE(dct_encode_page(**tables, texels.data(), kDctPage, kDctPage, coded).ok());
  for (const PageId& id : {PageId{0, 0, 0}, PageId{0, 1, 0}, PageId{1, 0, 0}})
    EXPECT_TRUE((*w)->add_page(id, 0, coded).ok());
  EXPECT_TRUE((*w)->finish().ok());
  return path;
}

// Sets the channel byte of layer 0's record and recomputes the header checksum, so that only
// the cross-check of the record against its own tables can catch it.
void patch_channels(std::vector<uint8_t>& b, uint8_t channels) {
  const uint32_t header_size = get_u32(b.data() + kOffHeaderSize);
  const uint32_t levels = get_u32(b.data() + kOffLevelCount);
  b[kFixedHeaderBytes + levels * kLevelRecordBytes + 1] = channels;
  put_u64(b.data() + header_size - 8, XXH3_64bits(b.data(), header_size - 8));
}

TEST(HostileFiles, DctLayerWhoseRecordContradictsItsTablesDoesNotOpen) {
  const std::string path = write_dct_file("dct.vtpf");
  const std::vector<uint8_t> pristine = read_bytes(path);
  ASSERT_TRUE(PageFileReader::open(path).ok());
  for (uint8_t channels : {1, 2, 4}) {
    std::vector<uint8_t> b = pristine;
    patch_channels(b, channels);
    write_bytes(path, b);
    auto reader = PageFileReader::open(path);
    ASSERT_FALSE(reader.ok()) << int(channels);
    EXPECT_EQ(reader.status().code(), ErrorCode::kCorrupt);
    EXPECT_EQ(
        reader.status().message(),
        path + ": layer 0: dct tables code 3 channels, the layer has " + std::to_string(channels));
  }
}

TEST(HostileFiles, DctDecoderWritesOnlyIntoTheBufferItIsGiven) {
  DctSettings s;
  s.channels = 3;
  auto tables = dct_make_tables(s, kDctPage, kDctPage);
  ASSERT_TRUE(tables.ok());
  std::vector<uint8_t> texels(size_t(kDctPage) * kDctPage * 3, 77), coded;
  ASSERT_TRUE(dct_encode_page(**tables, texels.data(), kDctPage, kDctPage, coded).ok());
  // A buffer sized for 2 channels while the tables decode 3: refused before any write.
  std::vector<uint8_t> small(size_t(kDctPage) * kDctPage * 2 + 16, 0xAB);
  const Status st = dct_decode_page(**tables, coded, kDctPage, kDctPage,
                                    std::span<uint8_t>(small.data(), small.size() - 16));
  EXPECT_EQ(st.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(st.message().find("the tables decode 3 channels"), std::string::npos) << st.message();
  for (uint8_t v : small) ASSERT_EQ(v, 0xAB);
  std::vector<uint8_t> exact(texels.size());
  EXPECT_TRUE(dct_decode_page(**tables, coded, kDctPage, kDctPage, std::span<uint8_t>(exact)).ok());
}

TEST(HostileFiles, ExtractRefusesALevelBeyondTheCeilingBeforeAllocating) {
  // 65536^2 texels of 4 bytes (16 GiB) at level 0, described by a file of a few KB.
  PageFileDesc desc;
  desc.geometry = {65536, 65536, 4088, 4};
  desc.layers = {layer("albedo", 4, TexelType::kU8, PageCodec::kRawZstd)};
  const std::string path = temp_path("huge.vtpf");
  {
    auto w = PageFileWriter::create(path, desc);
    ASSERT_TRUE(w.ok()) << w.status().message();
    ASSERT_TRUE((*w)->finish().ok());
  }
  EXPECT_LT(read_bytes(path).size(), 16384u);
  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  auto image = extract_level(**reader, 0, 0);
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(image.status().message(),
            path +
                ": level 0 of layer 0 is 65536x65536 texels of 4 bytes: 17179869184 bytes (16.0 "
                "GiB), more than the 4294967296 bytes (4.0 GiB) an extracted image may hold");
  // A level inside the ceiling extracts (all absent: zeros).
  auto small = extract_level(**reader, 5, 0);
  ASSERT_TRUE(small.ok()) << small.status().message();
  EXPECT_EQ(small->width, 2048u);
  EXPECT_EQ(extract_level(**reader, 3, 0, 1 << 20).status().code(), ErrorCode::kInvalidArgument);
}

TEST(HostileFiles, NonRegularInputsAreRefusedWithoutBlocking) {
  const std::string fifo = temp_path("pipe.vtpf");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto t0 = std::chrono::steady_clock::now();
  auto reader = PageFileReader::open(fifo);  // used to wait forever for a writer
  ASSERT_FALSE(reader.ok());
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
  EXPECT_EQ(reader.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(reader.status().message(), fifo + ": not a regular file (a FIFO)");
  const std::string dir = temp_path("dir.vtpf");
  ASSERT_EQ(::mkdir(dir.c_str(), 0700), 0);
  EXPECT_EQ(PageFileReader::open(dir).status().message(),
            dir + ": not a regular file (a directory)");

  EXPECT_EQ(check_input_file(fifo).message(), fifo + " is a FIFO, not a regular file to read");
  EXPECT_EQ(check_input_file(dir).code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(check_input_file(dir + "/missing").code(), ErrorCode::kNotFound);
  const std::string file = temp_path("plain.bin");
  write_bytes(file, {1, 2, 3});
  EXPECT_TRUE(check_input_file(file).ok());
}

TEST(HostileFiles, FileTruncatedOrRewrittenWhileOpenGivesErrorsNotSigbus) {
  const GeneratedFile f = small_file();
  const std::string path = temp_path("live.vtpf");
  ASSERT_TRUE(write_file(f, path, 1, 0).ok());
  const std::vector<uint8_t> pristine = read_bytes(path);
  auto reader = PageFileReader::open(path);
  ASSERT_TRUE(reader.ok());
  auto unchecked = PageFileReader::open(path, {false});
  ASSERT_TRUE(unchecked.ok());
  const uint64_t data_offset = le64(pristine, kOffDataOffset);

  // Truncated in place (as `cp new old` does first): every stored page now errors.
  ASSERT_EQ(::truncate(path.c_str(), off_t(data_offset)), 0);
  int stored = 0;
  for (const ExpectedPage& p : f.pages) {
    std::vector<uint8_t> out((*reader)->decoded_page_bytes(p.layer));
    const Status s = (*reader)->read_texels(p.id, p.layer, out);
    const Status u = (*unchecked)->read_texels(p.id, p.layer, out);
    if (p.state != PageState::kStored) {
      EXPECT_EQ(s.ok(), p.state == PageState::kConstant);
      continue;
    }
    ++stored;
    EXPECT_EQ(s.code(), ErrorCode::kCorrupt);
    EXPECT_NE(
        s.message().find(path + ": " + page_name(p.id, p.layer) + ": file changed while open"),
        std::string::npos)
        << s.message();
    EXPECT_EQ(u.code(), ErrorCode::kCorrupt);
    EXPECT_EQ((*reader)->verify_page(p.id, p.layer).code(), ErrorCode::kCorrupt);
    EXPECT_EQ((*reader)->read_stored(p.id, p.layer).status().code(), ErrorCode::kCorrupt);
  }
  EXPECT_GT(stored, 0);

  // Rewritten in place with other bytes of the same size: checksums catch it.
  std::vector<uint8_t> other = pristine;
  for (size_t i = data_offset; i < other.size(); ++i) other[i] ^= 0x5A;
  write_bytes(path, other);
  EXPECT_EQ((*reader)->verify().code(), ErrorCode::kCorrupt);
  write_bytes(path, pristine);
  EXPECT_TRUE((*reader)->verify().ok());
}

TEST(AtomicOutput, ResolvesLinksAndRefusesWhatIsNotAFile) {
  const std::string target = temp_path("real.vtpf");
  write_bytes(target, {1});
  const std::string link = temp_path("link.vtpf");
  ASSERT_EQ(::symlink(target.c_str(), link.c_str()), 0);
  EXPECT_EQ(*resolve_output_path(link), target);
  EXPECT_EQ(*resolve_output_path(target), target);
  const std::string fresh = temp_path("new.vtpf");
  EXPECT_EQ(*resolve_output_path(fresh), fresh);

  auto null = resolve_output_path("/dev/null");
  EXPECT_EQ(null.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(null.status().message(),
            "/dev/null is a character device: refusing to replace it with a file");
  const std::string dir = temp_path("out");
  ASSERT_EQ(::mkdir(dir.c_str(), 0700), 0);
  EXPECT_EQ(resolve_output_path(dir).status().code(), ErrorCode::kInvalidArgument);
  const std::string dev_link = temp_path("null-link");
  ASSERT_EQ(::symlink("/dev/null", dev_link.c_str()), 0);
  EXPECT_EQ(resolve_output_path(dev_link).status().message(),
            dev_link +
                " (a link to /dev/null) is a character device: refusing to replace it "
                "with a file");
  const std::string loop = temp_path("loop");
  ASSERT_EQ(::symlink(loop.c_str(), loop.c_str()), 0);
  EXPECT_EQ(resolve_output_path(loop).status().code(), ErrorCode::kInvalidArgument);
}

TEST(AtomicOutput, WriterReplacesALinksTargetAndRefusesAFifo) {
  GeneratedFile f = small_file();
  const std::string target = temp_path("target.vtpf");
  write_bytes(target, {1, 2, 3});
  const std::string link = temp_path("link.vtpf");
  ASSERT_EQ(::symlink(target.c_str(), link.c_str()), 0);
  ASSERT_TRUE(write_file(f, link, 1, 0).ok());
  struct stat st;
  ASSERT_EQ(::lstat(link.c_str(), &st), 0);
  EXPECT_TRUE(S_ISLNK(st.st_mode));
  EXPECT_TRUE(PageFileReader::open(target).ok());
  for (auto& e : std::filesystem::directory_iterator(std::filesystem::path(target).parent_path()))
    EXPECT_EQ(e.path().string(), target);  // no temporary left beside it

  const std::string fifo = temp_path("fifo.vtpf");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto w = PageFileWriter::create(fifo, f.desc);
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(w.status().message(), fifo + " is a FIFO: refusing to replace it with a file");
  ASSERT_EQ(::lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
}

TEST(AtomicOutput, OutputSetReplacesBothOrNeither) {
  const std::string a = temp_path("scene.vtpf"), b = temp_path("scene.glb");
  write_bytes(a, {'o', 'l', 'd', 'a'});
  write_bytes(b, {'o', 'l', 'd', 'b'});
  {
    OutputSet set;  // abandoned: nothing changes, nothing is left
    auto ta = set.stage(a), tb = set.stage(b);
    ASSERT_TRUE(ta.ok() && tb.ok());
    write_bytes(*ta, {'n'});
    write_bytes(*tb, {'n'});
  }
  EXPECT_EQ(read_bytes(a), std::vector<uint8_t>({'o', 'l', 'd', 'a'}));
  EXPECT_EQ(read_bytes(b), std::vector<uint8_t>({'o', 'l', 'd', 'b'}));
  EXPECT_EQ(std::distance(
                std::filesystem::directory_iterator(std::filesystem::path(a).parent_path()), {}),
            1);
  {
    // The second rename fails (a directory took its place): the first is put back.
    OutputSet set;
    auto ta = set.stage(a);
    const std::string c = temp_path("blocked.glb");
    auto tc = set.stage(c);
    ASSERT_TRUE(ta.ok() && tc.ok());
    write_bytes(*ta, {'n', 'e', 'w'});
    ASSERT_EQ(::mkdir(c.c_str(), 0700), 0);
    const Status s = set.commit();
    EXPECT_EQ(s.code(), ErrorCode::kIo);
    EXPECT_NE(s.message().find(c + ": rename into place failed"), std::string::npos);
    EXPECT_EQ(read_bytes(a), std::vector<uint8_t>({'o', 'l', 'd', 'a'}));
  }
  EXPECT_EQ(std::distance(
                std::filesystem::directory_iterator(std::filesystem::path(a).parent_path()), {}),
            1);
  OutputSet set;
  auto ta = set.stage(a), tb = set.stage(b);
  ASSERT_TRUE(ta.ok() && tb.ok());
  write_bytes(*ta, {'n', 'a'});
  write_bytes(*tb, {'n', 'b'});
  ASSERT_TRUE(set.commit().ok());
  EXPECT_EQ(read_bytes(a), std::vector<uint8_t>({'n', 'a'}));
  EXPECT_EQ(read_bytes(b), std::vector<uint8_t>({'n', 'b'}));
  struct stat st;
  ASSERT_EQ(::stat(a.c_str(), &st), 0);
  EXPECT_NE(st.st_mode & 0044, 0u);  // not left 0600 as mkstemp made it
  EXPECT_EQ(set.stage(a).status().code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace vt
