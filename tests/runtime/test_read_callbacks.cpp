#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "format/page_file.h"
#include "format/page_file_c.h"
#include "runtime/vt_runtime_c.h"
#include "runtime_test_util.h"

namespace vt {
namespace {

// An engine's storage in miniature: a page file held in memory, counting reads and releases.
struct MemoryStorage {
  std::vector<uint8_t> bytes;
  std::atomic<int> reads{0}, releases{0};
  bool fail = false;
};

int64_t read_memory(void* user, uint64_t offset, void* buf, size_t size) {
  auto* m = static_cast<MemoryStorage*>(user);
  ++m->reads;
  if (m->fail) return -1;
  if (offset >= m->bytes.size()) return 0;
  const size_t n = std::min<size_t>(size, m->bytes.size() - offset);
  std::memcpy(buf, m->bytes.data() + offset, n);
  return int64_t(n);
}

void release_memory(void* user) {
  ++static_cast<MemoryStorage*>(user)->releases;
}

// The bytes of runtime_test::write_marked_file's page file.
std::vector<uint8_t> marked_file_bytes() {
  std::ifstream in(runtime_test::write_marked_file(), std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

vt_read_callbacks callbacks_of(MemoryStorage& m) {
  return vt_read_callbacks{&m, m.bytes.size(), read_memory, release_memory};
}

TEST(ReadCallbacks, StreamerReadsTheEnginesStorage) {
  MemoryStorage m;
  m.bytes = marked_file_bytes();
  const vt_read_callbacks io = callbacks_of(m);
  vtrt_options o;
  vtrt_default_options(&o);
  o.slots_x = 5;
  o.slots_y = 4;
  vtrt_streamer* h = nullptr;
  ASSERT_EQ(vtrt_open_callbacks(&io, "pak:textures/terrain.vtpf", &o, &h), VT_OK)
      << vt_last_error();
  std::vector<uint32_t> fb;
  for (uint32_t y = 0; y < 3; ++y)
    for (uint32_t x = 0; x < 4; ++x) fb.push_back(VTRT_FEEDBACK(0, x, y));
  uint32_t level0 = 0;
  for (int f = 0; f < 20 && level0 < 12; ++f) {
    vtrt_frame_stats st;
    ASSERT_EQ(vtrt_update(h, fb.data(), fb.size(), &st), VT_OK) << vt_last_error();
    for (uint32_t i = 0; i < vtrt_upload_count(h); ++i) {
      vtrt_upload u;
      ASSERT_EQ(vtrt_get_upload(h, i, 0, &u), VT_OK);
      EXPECT_EQ(u.data[0], u.level);
      EXPECT_EQ(u.data[1], u.page_x);
      EXPECT_EQ(u.data[2], u.page_y);
      level0 += u.level == 0;
    }
    vtrt_wait_idle(h);
  }
  EXPECT_EQ(level0, 12u);
  EXPECT_GT(m.reads.load(), 12);
  EXPECT_EQ(m.releases.load(), 0);
  vtrt_close(h);
  EXPECT_EQ(m.releases.load(), 1);
}

TEST(ReadCallbacks, ErrorsNameTheStorageAndReleaseOnce) {
  MemoryStorage m;
  m.bytes = marked_file_bytes();
  m.bytes.resize(m.bytes.size() / 2);  // truncated
  vt_read_callbacks io = callbacks_of(m);
  vtpf_file* file = nullptr;
  EXPECT_EQ(vtpf_open_callbacks(&io, "pak:half.vtpf", 1, &file), VT_ERR_CORRUPT);
  EXPECT_EQ(file, nullptr);
  EXPECT_NE(std::string(vt_last_error()).find("pak:half.vtpf"), std::string::npos)
      << vt_last_error();
  EXPECT_EQ(m.releases.load(), 1);

  MemoryStorage failing;
  failing.bytes = marked_file_bytes();
  failing.fail = true;
  io = callbacks_of(failing);
  vtrt_streamer* h = nullptr;
  EXPECT_EQ(vtrt_open_callbacks(&io, "net:tile", nullptr, &h), VT_ERR_IO);
  EXPECT_NE(std::string(vt_last_error()).find("read callback failed"), std::string::npos)
      << vt_last_error();
  EXPECT_EQ(failing.releases.load(), 1);

  io.read = nullptr;
  EXPECT_EQ(vtrt_open_callbacks(&io, "x", nullptr, &h), VT_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(vtrt_open_callbacks(nullptr, "x", nullptr, &h), VT_ERR_INVALID_ARGUMENT);
}

TEST(ReadCallbacks, ReaderOverAByteSource) {
  struct Bytes final : ByteSource {
    std::vector<uint8_t> data;
    uint64_t size() const override { return data.size(); }
    Expected<size_t> read_some(uint64_t offset, std::span<uint8_t> out) const override {
      if (offset >= data.size()) return size_t(0);
      const size_t n = std::min<size_t>(out.size(), data.size() - offset);
      std::memcpy(out.data(), data.data() + offset, n);
      return n;
    }
  };
  auto bytes = std::make_shared<Bytes>();
  bytes->data = marked_file_bytes();
  auto reader = PageFileReader::open(bytes, "memory");
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  EXPECT_EQ((*reader)->path(), "memory");
  EXPECT_TRUE((*reader)->verify().ok());
  EXPECT_FALSE(PageFileReader::open(nullptr, "none").ok());
}

}  // namespace
}  // namespace vt
