#include <gtest/gtest.h>

#include <map>
#include <random>

#include "fake_source.h"
#include "runtime/page_cache.h"
#include "runtime/page_table.h"

namespace vt {
namespace {

using testing::small_geometry;

// Reference: the entry of v is the nearest resident page at or above it.
PageTableEntry expected_entry(const PageGeometry& g, const std::map<uint64_t, uint32_t>& resident,
                              PageId v, uint32_t slots_x) {
  const uint32_t last = g.level_count() - 1;
  for (;;) {
    auto it = resident.find((uint64_t(v.level) << 40) | (uint64_t(v.y) << 20) | v.x);
    if (it != resident.end())
      return {uint8_t(it->second % slots_x), uint8_t(it->second / slots_x), uint8_t(v.level),
              kPageTableValid};
    if (v.level >= last) return {};
    v = {v.level + 1, v.x / 2, v.y / 2};
  }
}

TEST(PageTable, RandomMapUnmapMatchesReference) {
  const PageGeometry g = small_geometry(11, 7);  // non-power-of-two grid
  const uint32_t last = g.level_count() - 1;
  const uint32_t slots_x = 5, slots = 20;
  PageTable table(g);
  PageCache cache(g, slots);
  std::map<uint64_t, uint32_t> resident;
  std::vector<CacheEvent> events;
  std::mt19937 rng(3);
  auto parent_of = [&](PageId p) -> std::optional<PageId> {
    if (p.level >= last) return std::nullopt;
    return PageId{p.level + 1, p.x / 2, p.y / 2};
  };
  auto apply = [&] {
    for (const CacheEvent& e : events) {
      const uint64_t k = (uint64_t(e.page.level) << 40) | (uint64_t(e.page.y) << 20) | e.page.x;
      if (e.kind == CacheEvent::Kind::kMap) {
        table.map(e.page, e.slot % slots_x, e.slot / slots_x);
        resident[k] = e.slot;
      } else {
        table.unmap(e.page);
        resident.erase(k);
      }
    }
    events.clear();
  };
  ASSERT_TRUE(cache.map({last, 0, 0}, std::nullopt, 0, events));
  apply();
  for (uint64_t frame = 1; frame < 600; ++frame) {
    for (int op = 0; op < 8; ++op) {
      const uint32_t l = rng() % g.level_count();
      const PageId p{l, uint32_t(rng() % g.pages_x(l)), uint32_t(rng() % g.pages_y(l))};
      if (rng() % 3 == 0) {
        cache.unmap(p, events);
      } else if (!cache.resident(p)) {
        auto parent = parent_of(p);
        if (parent && cache.resident(*parent)) cache.map(p, parent, frame, events);
      } else {
        cache.touch(p, frame);
      }
      apply();
    }
    ASSERT_LE(cache.resident_count(), slots);
    for (uint32_t l = 0; l <= last; ++l)
      for (uint32_t y = 0; y < g.pages_y(l); ++y)
        for (uint32_t x = 0; x < g.pages_x(l); ++x) {
          const PageId v{l, x, y};
          ASSERT_EQ(table.entry(v), expected_entry(g, resident, v, slots_x))
              << "frame " << frame << " page " << l << "," << x << "," << y;
          const PageTableEntry e = table.entry(v);
          ASSERT_TRUE(e.valid());
          ASSERT_GE(e.level, l);
        }
  }
}

TEST(PageTable, DirtyRectanglesAndLayout) {
  const PageGeometry g = small_geometry(8, 6);
  PageTable table(g);
  EXPECT_EQ(table.level_count(), 4u);
  EXPECT_EQ(table.level_data(0).size(), 8u * 6u * 4u);
  table.map({3, 0, 0}, 1, 2);
  for (uint32_t l = 0; l < 4; ++l) {
    const TableRect r = table.dirty(l);
    EXPECT_EQ(r.x0, 0u);
    EXPECT_EQ(r.x1, table.width(l));
    EXPECT_EQ(r.y1, table.height(l));
  }
  // Byte layout: R = slot x, G = slot y, B = level, A = flags.
  EXPECT_EQ(table.level_data(0)[0], 1);
  EXPECT_EQ(table.level_data(0)[1], 2);
  EXPECT_EQ(table.level_data(0)[2], 3);
  EXPECT_EQ(table.level_data(0)[3], kPageTableValid);
  table.clear_dirty();
  table.map({1, 2, 1}, 7, 0);
  EXPECT_TRUE(table.dirty(3).empty());
  EXPECT_TRUE(table.dirty(2).empty());
  const TableRect r1 = table.dirty(1), r0 = table.dirty(0);
  EXPECT_EQ(r1.x0, 2u);
  EXPECT_EQ(r1.x1, 3u);
  EXPECT_EQ(r0.x0, 4u);
  EXPECT_EQ(r0.x1, 6u);
  EXPECT_EQ(r0.y0, 2u);
  EXPECT_EQ(r0.y1, 4u);
  // A level-0 page under it: one texel changes.
  table.clear_dirty();
  table.map({0, 5, 3}, 9, 9);
  EXPECT_TRUE(table.dirty(1).empty());
  EXPECT_EQ(table.dirty(0).x1 - table.dirty(0).x0, 1u);
  EXPECT_EQ(table.entry({0, 4, 2}).level, 1);
  table.unmap({0, 5, 3});
  EXPECT_EQ(table.entry({0, 5, 3}), (PageTableEntry{7, 0, 1, kPageTableValid}));
}

TEST(PageTable, ScaleBiasMatchesTexelFormula) {
  PageGeometry g;
  g.payload = 120;
  g.border = 4;
  g.width = 1000;  // not a multiple of the payload
  g.height = 700;
  const uint32_t sx = 8, sy = 4;
  const PageTableEntry e{3, 2, 2, kPageTableValid};
  const PageId vpage{0, 7, 5};  // resident ancestor at level 2: (1, 1)
  const ScaleBias sb = page_table_scale_bias(g, vpage, e, sx, sy);
  const double ps = g.page_size();
  for (double u : {0.9, 0.93, 0.95}) {
    const double v = 0.88;
    const double tx = u * g.level_width(2), ty = v * g.level_height(2);
    const double px = e.slot_x * ps + g.border + (tx - 1 * 120.0);
    const double py = e.slot_y * ps + g.border + (ty - 1 * 120.0);
    EXPECT_NEAR(u * sb.scale_u + sb.bias_u, px / (sx * ps), 1e-6);
    EXPECT_NEAR(v * sb.scale_v + sb.bias_v, py / (sy * ps), 1e-6);
  }
  EXPECT_EQ(page_table_scale_bias(g, vpage, PageTableEntry{}, sx, sy).scale_u, 0.0f);
}

}  // namespace
}  // namespace vt
