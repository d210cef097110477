#include <gtest/gtest.h>

#include <string>

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

}  // namespace
}  // namespace vt
