#include <gtest/gtest.h>

#include <string>

#include "format/version.h"
#include "format/vt_version_c.h"

namespace vt {
namespace {

TEST(Version, BothApisGiveTheProjectVersion) {
  const LibraryVersion v = library_version();
  EXPECT_EQ(
      std::string(library_version_string()),
      std::to_string(v.major) + "." + std::to_string(v.minor) + "." + std::to_string(v.patch));
  EXPECT_STREQ(vt_version_string(), library_version_string());
  EXPECT_EQ(vt_version(), (v.major << 16) | (v.minor << 8) | v.patch);
  EXPECT_EQ(newest_page_file_version(), 1u);
  EXPECT_EQ(vtpf_newest_version(), newest_page_file_version());
}

}  // namespace
}  // namespace vt
