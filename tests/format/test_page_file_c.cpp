// The C API reads what the C++ writer wrote and reports errors as codes and messages.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "format/page_file_c.h"
#include "page_file_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;

TEST(PageFileC, ReadsBackEveryPage) {
  GeneratedFile f = small_file();
  const std::string path = temp_path("c.vtpf");
  ASSERT_TRUE(write_file(f, path, 2, 1).ok());
  vtpf_file* file = nullptr;
  ASSERT_EQ(vtpf_open(path.c_str(), 1, &file), VT_OK) << vt_last_error();
  ASSERT_NE(file, nullptr);
  vtpf_geometry g;
  ASSERT_EQ(vtpf_get_geometry(file, &g), VT_OK);
  EXPECT_EQ(g.width, 20u);
  EXPECT_EQ(g.height, 12u);
  EXPECT_EQ(g.payload, 8u);
  EXPECT_EQ(g.border, 2u);
  EXPECT_EQ(g.page_size, 12u);
  EXPECT_EQ(g.level_count, 3u);
  EXPECT_EQ(g.layer_count, 2u);
  EXPECT_EQ(g.version, 1u);
  EXPECT_EQ(vtpf_pages_x(file, 0), 3u);
  EXPECT_EQ(vtpf_pages_y(file, 0), 2u);
  EXPECT_EQ(vtpf_pages_x(file, 3), 0u);
  vtpf_layer_info info;
  ASSERT_EQ(vtpf_get_layer(file, 1, &info), VT_OK);
  EXPECT_STREQ(info.name, "height");
  EXPECT_EQ(info.channels, 2);
  EXPECT_EQ(info.codec, uint8_t(PageCodec::kRawZstd));
  EXPECT_EQ(info.decoded_page_bytes, 12u * 12 * 2);
  EXPECT_EQ(vtpf_get_layer(file, 2, &info), VT_ERR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(vt_last_error()).find("no layer 2"), std::string::npos);
  size_t meta_size = 0;
  const char* meta = vtpf_metadata(file, &meta_size);
  EXPECT_EQ(std::string(meta, meta_size), f.desc.metadata_json);

  std::vector<uint8_t> buf(4096);
  for (const ExpectedPage& p : f.pages) {
    vtpf_page_entry e;
    ASSERT_EQ(vtpf_get_entry(file, p.id.level, p.id.x, p.id.y, p.layer, &e), VT_OK);
    ASSERT_EQ(e.state, uint8_t(p.state));
    int rc = vtpf_read_texels(file, p.id.level, p.id.x, p.id.y, p.layer, buf.data(), buf.size());
    if (p.state == PageState::kAbsent) {
      EXPECT_EQ(rc, VT_ERR_NOT_FOUND);
      continue;
    }
    ASSERT_EQ(rc, VT_OK) << vt_last_error();
    EXPECT_EQ(0, std::memcmp(buf.data(), p.texels.data(), p.texels.size()));
    if (p.state != PageState::kStored) continue;
    size_t size = 0;
    EXPECT_EQ(vtpf_read_stored(file, p.id.level, p.id.x, p.id.y, p.layer, buf.data(), 1, &size),
              VT_ERR_INVALID_ARGUMENT);
    EXPECT_EQ(size, p.stored.size());
    ASSERT_EQ(
        vtpf_read_stored(file, p.id.level, p.id.x, p.id.y, p.layer, buf.data(), buf.size(), &size),
        VT_OK);
    ASSERT_EQ(size, p.stored.size());
    EXPECT_EQ(0, std::memcmp(buf.data(), p.stored.data(), size));
  }
  EXPECT_EQ(vtpf_read_texels(file, 0, 0, 0, 0, buf.data(), 10), VT_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(vtpf_get_entry(file, 0, 3, 0, 0, nullptr), VT_ERR_INVALID_ARGUMENT);
  vtpf_page_entry e;
  EXPECT_EQ(vtpf_get_entry(file, 0, 3, 0, 0, &e), VT_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(vtpf_verify(file), VT_OK);
  vtpf_close(file);
}

TEST(PageFileC, ErrorsNameTheFile) {
  GeneratedFile f = small_file();
  const std::string path = temp_path("c_bad.vtpf");
  ASSERT_TRUE(write_file(f, path, 1, 0).ok());
  std::vector<uint8_t> bytes = read_bytes(path);
  bytes[0] ^= 1;
  write_bytes(path, bytes);
  vtpf_file* file = reinterpret_cast<vtpf_file*>(1);
  EXPECT_EQ(vtpf_open(path.c_str(), 1, &file), VT_ERR_CORRUPT);
  EXPECT_EQ(file, nullptr);
  const std::string message = vt_last_error();
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find("magic"), std::string::npos) << message;
  EXPECT_EQ(vtpf_open(nullptr, 1, &file), VT_ERR_INVALID_ARGUMENT);
  EXPECT_STREQ(vt_last_error(), "path is NULL");
  EXPECT_EQ(vtpf_open(path.c_str(), 1, nullptr), VT_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(vtpf_open((path + ".missing").c_str(), 1, &file), VT_ERR_NOT_FOUND);
  EXPECT_EQ(vtpf_verify(nullptr), VT_ERR_INVALID_ARGUMENT);
  EXPECT_STREQ(vt_last_error(), "file is NULL");
  vtpf_close(nullptr);

  // A corrupt data byte: the file opens, verify and the page read fail.
  bytes[0] ^= 1;
  const uint64_t data_offset = le64(bytes, 64);
  bytes[data_offset + 1] ^= 0x10;
  write_bytes(path, bytes);
  ASSERT_EQ(vtpf_open(path.c_str(), 1, &file), VT_OK) << vt_last_error();
  EXPECT_EQ(vtpf_verify(file), VT_ERR_CORRUPT);
  EXPECT_NE(std::string(vt_last_error()).find("checksum"), std::string::npos);
  vtpf_close(file);
}

}  // namespace
}  // namespace vt
