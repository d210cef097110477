#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <tuple>

#include "engine_hooks.h"
#include "format/page_file.h"
#include "runtime/feedback.h"
#include "runtime/vt_runtime_c.h"
#include "runtime_test_util.h"

namespace vt {
namespace {

TEST(RuntimeCApi, OpenStreamAndReadTable) {
  const std::string path = runtime_test::write_marked_file();
  vtrt_options o;
  vtrt_default_options(&o);
  o.slots_x = 5;  // 20 slots for 12 + 4 + 1 pages
  o.slots_y = 4;
  vtrt_streamer* h = nullptr;
  ASSERT_EQ(vtrt_open(path.c_str(), &o, &h), VT_OK) << vt_last_error();
  vtrt_geometry g;
  ASSERT_EQ(vtrt_get_geometry(h, &g), VT_OK);
  EXPECT_EQ(g.page_size, 16u);
  EXPECT_EQ(g.level_count, 3u);  // 4x3, 2x2, 1x1
  uint32_t format = 99;
  size_t bytes = 0;
  ASSERT_EQ(vtrt_get_upload_format(h, 0, &format, &bytes), VT_OK);
  EXPECT_EQ(vtrt_get_upload_format(h, 1, &format, &bytes), VT_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(format, uint32_t(RuntimeFormat::kRgba8));
  EXPECT_EQ(bytes, 16u * 16u * 4u);

  std::vector<uint32_t> fb;
  for (uint32_t y = 0; y < 3; ++y)
    for (uint32_t x = 0; x < 4; ++x) fb.push_back(feedback_pack(0, x, y));
  uint32_t uploads = 0;
  vtrt_frame_stats st{};
  for (int f = 0; f < 20; ++f) {
    ASSERT_EQ(vtrt_update(h, fb.data(), fb.size(), &st), VT_OK);
    for (uint32_t i = 0; i < vtrt_upload_count(h); ++i) {
      vtrt_upload u;
      ASSERT_EQ(vtrt_get_upload(h, i, 0, &u), VT_OK);
      ASSERT_EQ(u.size, bytes);
      EXPECT_EQ(u.data[0], u.level);
      EXPECT_EQ(u.data[1], u.page_x);
      EXPECT_EQ(u.data[2], u.page_y);
      ++uploads;
    }
    vtrt_wait_idle(h);
    if (st.needed == st.resident_hits && vtrt_idle(h)) break;
  }
  EXPECT_EQ(uploads, 12u + 4u + 1u);  // the root comes with the first update
  const uint8_t* data = nullptr;
  uint32_t w = 0, hgt = 0, dirty[4];
  ASSERT_EQ(vtrt_get_page_table_level(h, 0, &data, &w, &hgt, dirty), VT_OK);
  EXPECT_EQ(w, 4u);
  EXPECT_EQ(hgt, 3u);
  EXPECT_EQ(data[3] & 1, 1);
  vtrt_upload u;
  EXPECT_EQ(vtrt_get_upload(h, 9999, 0, &u), VT_ERR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(vt_last_error()).find("out of range"), std::string::npos);
  EXPECT_EQ(vtrt_update(h, nullptr, 3, &st), VT_ERR_INVALID_ARGUMENT);
  EXPECT_STREQ(vt_last_error(), "feedback is NULL");
  vtrt_close(h);

  EXPECT_EQ(vtrt_open("/nonexistent/x.vtpf", nullptr, &h), VT_ERR_NOT_FOUND);
  EXPECT_EQ(h, nullptr);
  EXPECT_NE(std::string(vt_last_error()).find("/nonexistent/x.vtpf"), std::string::npos)
      << vt_last_error();
  EXPECT_EQ(vtrt_get_geometry(nullptr, &g), VT_ERR_INVALID_ARGUMENT);
  EXPECT_STREQ(vt_last_error(), "streamer is NULL");
  vtrt_close(nullptr);
}

// Streams until a frame needs nothing new; returns the pages uploaded, as (level, x, y) read from
// the marked file's texels (which also proves each upload's bytes are its page's).
std::vector<PageId> stream_until_converged(vtrt_streamer* h, const std::vector<uint32_t>& fb,
                                           testing::TestJobQueue* jobs) {
  std::vector<PageId> pages;
  vtrt_frame_stats st{};
  for (int f = 0; f < 30; ++f) {
    EXPECT_EQ(vtrt_update(h, fb.data(), fb.size(), &st), VT_OK);
    for (uint32_t i = 0; i < vtrt_upload_count(h); ++i) {
      vtrt_upload u;
      EXPECT_EQ(vtrt_get_upload(h, i, 0, &u), VT_OK);
      EXPECT_EQ(PageId({u.data[0], u.data[1], u.data[2]}), PageId({u.level, u.page_x, u.page_y}));
      pages.push_back({u.level, u.page_x, u.page_y});
    }
    if (jobs) jobs->run_all();
    vtrt_wait_idle(h);
    if (st.needed == st.resident_hits && vtrt_idle(h)) break;
  }
  std::sort(pages.begin(), pages.end(), [](const PageId& a, const PageId& b) {
    return std::tie(a.level, a.y, a.x) < std::tie(b.level, b.y, b.x);
  });
  return pages;
}

TEST(RuntimeCApi, TwoTexturesShareOneFeedbackBufferWithEngineHooks) {
  const std::string path = runtime_test::write_marked_file();
  testing::TestJobQueue jobs;
  testing::CountingAllocator alloc;
  vtrt_allocator a{};
  const Allocator hook = alloc.hook();
  a.allocate = hook.allocate;
  a.release = hook.release;
  a.user = hook.user;
  vtrt_job_system js{};
  const JobSystem jh = jobs.hook();
  js.submit = jh.submit;
  js.user = jh.user;

  vtrt_open_info info{};
  info.struct_size = sizeof info;
  info.path = path.c_str();
  info.allocator = &a;
  info.jobs = &js;
  info.texture_id = 2;
  vtrt_streamer* tex2 = nullptr;
  ASSERT_EQ(vtrt_open_ex(&info, &tex2), VT_OK) << vt_last_error();
  vtrt_streamer* tex0 = nullptr;
  ASSERT_EQ(vtrt_open(path.c_str(), nullptr, &tex0), VT_OK) << vt_last_error();

  // Texture 0 wants page (0, 1, 1), texture 2 page (0, 3, 2), in one buffer.
  std::vector<uint32_t> fb(64, VTRT_FEEDBACK_NONE);
  for (int i = 0; i < 20; ++i) fb[i] = VTRT_FEEDBACK(0, 1, 1);
  for (int i = 30; i < 50; ++i) fb[i] = VTRT_FEEDBACK_TEX(2, 0, 3, 2);
  EXPECT_EQ(VTRT_FEEDBACK_TEX(2, 0, 3, 2), feedback_pack(0, 3, 2, 2));
  const std::vector<PageId> want0 = {{0, 1, 1}, {1, 0, 0}, {2, 0, 0}};
  const std::vector<PageId> want2 = {{0, 3, 2}, {1, 1, 1}, {2, 0, 0}};
  EXPECT_EQ(stream_until_converged(tex0, fb, nullptr), want0);
  EXPECT_EQ(stream_until_converged(tex2, fb, &jobs), want2);
  EXPECT_GE(jobs.submitted(), 2u);         // the root is loaded by open, the rest by jobs
  EXPECT_GE(alloc.allocations.load(), 3);  // the root and two pages, at least
  vtrt_close(tex2);
  vtrt_close(tex0);
  EXPECT_EQ(alloc.live_blocks.load(), 0);
  EXPECT_EQ(alloc.size_mismatches.load(), 0);
}

TEST(RuntimeCApi, OpenExRejectsWhatItCannotUse) {
  const std::string path = runtime_test::write_marked_file();
  vtrt_streamer* h = reinterpret_cast<vtrt_streamer*>(1);
  vtrt_open_info info{};
  info.path = path.c_str();
  EXPECT_EQ(vtrt_open_ex(&info, &h), VT_ERR_INVALID_ARGUMENT);  // struct_size 0
  EXPECT_EQ(h, nullptr);
  EXPECT_NE(std::string(vt_last_error()).find("struct_size"), std::string::npos);
  info.struct_size = sizeof info;
  vt_read_callbacks io{};
  info.io = &io;
  EXPECT_EQ(vtrt_open_ex(&info, &h), VT_ERR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(vt_last_error()).find("exactly one of path and io"), std::string::npos);
  info.path = nullptr;
  EXPECT_EQ(vtrt_open_ex(&info, &h), VT_ERR_INVALID_ARGUMENT);  // io->read is NULL
  EXPECT_STREQ(vt_last_error(), "io->read is NULL");
  info.io = nullptr;
  EXPECT_EQ(vtrt_open_ex(&info, &h), VT_ERR_INVALID_ARGUMENT);
  info.path = path.c_str();
  info.texture_id = 7;
  EXPECT_EQ(vtrt_open_ex(&info, &h), VT_ERR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(vt_last_error()).find("texture_id"), std::string::npos) << vt_last_error();
  info.texture_id = 0;
  vtrt_allocator half{};
  half.allocate = [](size_t, size_t, void*) -> void* { return nullptr; };
  info.allocator = &half;
  EXPECT_EQ(vtrt_open_ex(&info, &h), VT_ERR_INVALID_ARGUMENT);  // no release
  vtrt_job_system no_submit{};
  info.allocator = nullptr;
  info.jobs = &no_submit;
  EXPECT_EQ(vtrt_open_ex(&info, &h), VT_ERR_INVALID_ARGUMENT);
  EXPECT_STREQ(vt_last_error(), "jobs->submit is NULL");
  EXPECT_EQ(vtrt_open_ex(nullptr, &h), VT_ERR_INVALID_ARGUMENT);
}

}  // namespace
}  // namespace vt
