// The code identity that the transfer and unwrap caches are keyed by: the hash of the file that
// holds the baker, so a cache from another build of the same version is never read.
#include <gtest/gtest.h>

#define XXH_STATIC_LINKING_ONLY
#include <xxhash.h>

#include <fstream>
#include <iterator>
#include <vector>

#include "bake/content_key.h"

namespace vt {
namespace {

TEST(ContentKey, CodeIdentityIsTheHashOfTheProgramHoldingTheBaker) {
  // This test program links the baker statically: the file holding it is /proc/self/exe.
  std::ifstream in("/proc/self/exe", std::ios::binary);
  ASSERT_TRUE(in);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                std::istreambuf_iterator<char>());
  ASSERT_FALSE(bytes.empty());
  EXPECT_EQ(code_identity(), XXH3_64bits(bytes.data(), bytes.size()));
  EXPECT_EQ(code_identity(), code_identity());  // read once
}

}  // namespace
}  // namespace vt
