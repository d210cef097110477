#include <gtest/gtest.h>

#include "fake_source.h"
#include "runtime/page_cache.h"

namespace vt {
namespace {

using testing::small_geometry;

TEST(PageCache, LruEvictsOldestLeafNotUsedThisFrame) {
  const PageGeometry g = small_geometry(8, 6);
  PageCache cache(g, 4);
  std::vector<CacheEvent> ev;
  const PageId root{3, 0, 0}, a{2, 0, 0}, b{2, 1, 0}, c{2, 0, 1}, d{2, 1, 1};
  EXPECT_EQ(cache.map(root, std::nullopt, 1, ev), 0u);  // lowest free slot first
  EXPECT_EQ(cache.map(a, root, 1, ev), 1u);
  EXPECT_EQ(cache.map(b, root, 2, ev), 2u);
  EXPECT_EQ(cache.map(c, root, 3, ev), 3u);
  EXPECT_EQ(cache.resident_count(), 4u);
  // Full: d evicts a (oldest), not the pinned root.
  ev.clear();
  cache.touch(b, 4);
  auto s = cache.map(d, root, 4, ev);
  ASSERT_TRUE(s);
  EXPECT_EQ(*s, 1u);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].kind, CacheEvent::Kind::kUnmap);
  EXPECT_EQ(ev[0].page, a);
  EXPECT_EQ(ev[1].kind, CacheEvent::Kind::kMap);
  EXPECT_FALSE(cache.resident(a));
  // Next: c (frame 3) is older than b (touched at 4).
  ev.clear();
  s = cache.map(a, root, 5, ev);
  ASSERT_TRUE(s);
  EXPECT_EQ(ev[0].page, c);
  // Everything but the root used in frame 5 or 6: nothing can go in frame 6... after touching.
  cache.touch(b, 6);
  cache.touch(d, 6);
  cache.touch(a, 6);
  ev.clear();
  EXPECT_FALSE(cache.map(c, root, 6, ev));
  EXPECT_TRUE(ev.empty());
  EXPECT_FALSE(cache.unmap(root, ev));  // pinned
}

TEST(PageCache, ParentsAreNotEvictedAndChainRuleHolds) {
  const PageGeometry g = small_geometry(8, 6);
  PageCache cache(g, 3);
  std::vector<CacheEvent> ev;
  const PageId root{3, 0, 0}, p{2, 0, 0}, child{1, 0, 0}, other{2, 1, 0};
  ASSERT_TRUE(cache.map(root, std::nullopt, 1, ev));
  EXPECT_FALSE(cache.map(child, p, 1, ev));  // parent not resident
  ASSERT_TRUE(cache.map(p, root, 1, ev));
  ASSERT_TRUE(cache.map(child, p, 2, ev));
  EXPECT_FALSE(cache.evictable(p));
  EXPECT_FALSE(cache.unmap(p, ev));
  // p is the oldest but a parent: the child goes instead.
  ev.clear();
  ASSERT_TRUE(cache.map(other, root, 3, ev));
  EXPECT_EQ(ev[0].page, child);
  EXPECT_TRUE(cache.evictable(p));
  EXPECT_TRUE(cache.unmap(p, ev));
  EXPECT_EQ(cache.resident_pages().size(), 2u);
}

}  // namespace
}  // namespace vt
