#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <tuple>

#include "fake_source.h"
#include "runtime/feedback.h"

namespace vt {
namespace {

using testing::FakeSource;
using testing::small_geometry;

TEST(Feedback, PackUnpackRoundTrip) {
  for (uint32_t level : {0u, 1u, 17u, 31u})
    for (uint32_t x : {0u, 1u, 2048u, 4095u})
      for (uint32_t y : {0u, 7u, 4095u}) {
        const uint32_t v = feedback_pack(level, x, y);
        EXPECT_EQ(v >> 29, 0u);
        EXPECT_NE(v, kFeedbackNone);
        EXPECT_EQ(feedback_unpack(v), (PageId{level, x, y}));
      }
  EXPECT_EQ(feedback_pack(3, 5, 9), 5u | (9u << 12) | (3u << 24));
  for (uint32_t t = 0; t < kFeedbackMaxTextures; ++t) {
    const uint32_t v = feedback_pack(31, 4095, 4095, t);
    EXPECT_NE(v, kFeedbackNone);
    EXPECT_EQ(feedback_texture(v), t);
    EXPECT_EQ(feedback_unpack(v), (PageId{31, 4095, 4095}));
  }
  EXPECT_EQ(feedback_texture(kFeedbackNone), 7u);  // the reserved id is the background's
}

// Straightforward std::map version of the resolver's contract.
std::vector<PageRequest> naive_resolve(const PageSource& src, std::span<const uint32_t> fb,
                                       uint32_t bias) {
  const PageGeometry& g = src.geometry();
  const uint32_t last = g.level_count() - 1;
  auto nearest = [&](PageId id) {
    while (id.level < last && !src.present(id)) id = {id.level + 1, id.x / 2, id.y / 2};
    if (id.level >= last) id = {last, 0, 0};
    return id;
  };
  std::map<uint32_t, uint32_t> values;
  for (uint32_t v : fb) values[v]++;
  std::map<std::tuple<uint32_t, uint32_t, uint32_t>, uint32_t> counts;
  for (auto [v, n] : values) {
    if (v == kFeedbackNone || (v >> 29) != 0) continue;
    PageId r = feedback_unpack(v);
    if (!g.contains(r)) continue;
    const uint32_t level = std::min(r.level + bias, last);
    const uint32_t s = level - r.level;
    PageId id = nearest({level, r.x >> s, r.y >> s});
    for (;;) {
      counts[{id.level, id.x, id.y}] += n;
      if (id.level >= last) break;
      id = nearest({id.level + 1, id.x / 2, id.y / 2});
    }
  }
  std::vector<PageRequest> out;
  for (auto& [k, c] : counts)
    out.push_back({PageId{std::get<0>(k), std::get<1>(k), std::get<2>(k)}, c});
  std::sort(out.begin(), out.end(), [](const PageRequest& a, const PageRequest& b) {
    if (a.id.level != b.id.level) return a.id.level > b.id.level;
    if (a.pixels != b.pixels) return a.pixels > b.pixels;
    if (a.id.y != b.id.y) return a.id.y < b.id.y;
    return a.id.x < b.id.x;
  });
  return out;
}

void expect_same(const std::vector<PageRequest>& a, const std::vector<PageRequest>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].id, b[i].id) << i;
    EXPECT_EQ(a[i].pixels, b[i].pixels) << i;
  }
}

TEST(FeedbackResolver, MatchesNaiveReferenceOnRandomBuffers) {
  // Pages with (x + y) % 3 == 0 at levels 0-1 are absent; they resolve to their parents.
  FakeSource src(small_geometry(13, 9), 1,
                 [](const PageId& id) { return id.level < 2 && (id.x + id.y) % 3 == 0; });
  FeedbackResolver resolver(src);
  std::mt19937 rng(7);
  std::vector<PageRequest> got;
  for (int iter = 0; iter < 40; ++iter) {
    std::vector<uint32_t> fb(2000 + rng() % 3000);
    const uint32_t levels = src.geometry().level_count();
    for (size_t i = 0; i < fb.size();) {
      // Runs of equal values, as a real buffer has, plus background and garbage.
      uint32_t v;
      const uint32_t kind = rng() % 10;
      if (kind == 0)
        v = kFeedbackNone;
      else if (kind == 1)
        v = rng();  // mostly invalid
      else {
        const uint32_t l = rng() % (levels + 1);  // one past the last level: invalid
        v = feedback_pack(l, rng() % 15, rng() % 11);
      }
      const size_t run = 1 + rng() % 40;
      for (size_t r = 0; r < run && i < fb.size(); ++r) fb[i++] = v;
    }
    const uint32_t bias = iter % 4;
    const ResolveStats st = resolver.resolve(fb, bias, got);
    expect_same(got, naive_resolve(src, fb, bias));
    uint64_t own = 0, other = 0;
    for (uint32_t v : fb) {
      const uint32_t t = feedback_texture(v);
      own += v != kFeedbackNone && (t == 0 || t == 7);  // 7: invalid, but counted as ours
      other += t != 0 && t != 7;
    }
    EXPECT_EQ(st.pixels, own);
    EXPECT_EQ(st.other_texture_pixels, other);
  }
}

// The run scan works four pixels at a time: every buffer length up to 19 and every place a run
// can end, including the tail past the last group of four and a change in the last pixel.
TEST(FeedbackResolver, ShortBuffersAndRunEndsAtEveryPosition) {
  FakeSource src(small_geometry(13, 9), 1);
  FeedbackResolver resolver(src);
  std::vector<PageRequest> got;
  const uint32_t a = feedback_pack(0, 1, 2), b = feedback_pack(0, 7, 3), c = feedback_pack(1, 2, 1);
  for (size_t n = 0; n < 20; ++n) {
    for (size_t cut = 0; cut <= n; ++cut) {
      // a up to `cut`, then b, with c in the last pixel and background at every fifth.
      std::vector<uint32_t> fb(n);
      for (size_t i = 0; i < n; ++i) fb[i] = i < cut ? a : b;
      if (n > 0) fb[n - 1] = c;
      for (size_t i = 4; i < n; i += 5) fb[i] = kFeedbackNone;
      const ResolveStats st = resolver.resolve(fb, 0, got);
      expect_same(got, naive_resolve(src, fb, 0));
      EXPECT_EQ(st.pixels, uint64_t(std::count_if(fb.begin(), fb.end(),
                                                  [](uint32_t v) { return v != kFeedbackNone; })));
    }
  }
}

TEST(FeedbackResolver, ChainsAndPriority) {
  FakeSource src(small_geometry(8, 6), 1);
  FeedbackResolver resolver(src);
  std::vector<uint32_t> fb(100, kFeedbackNone);
  for (int i = 0; i < 30; ++i) fb[i] = feedback_pack(0, 5, 3);
  for (int i = 30; i < 40; ++i) fb[i] = feedback_pack(0, 0, 0);
  std::vector<PageRequest> out;
  const ResolveStats st = resolver.resolve(fb, 0, out);
  EXPECT_EQ(st.pixels, 40u);
  EXPECT_EQ(st.invalid_pixels, 0u);
  EXPECT_EQ(st.unique_values, 2u);
  // Level 3 root (40 px), level 2: (1,0) 30 px and (0,0) 10 px, level 1: (2,1) 30, (0,0) 10,
  // level 0: (5,3) 30, (0,0) 10.
  const std::vector<PageRequest> want = {{{3, 0, 0}, 40}, {{2, 1, 0}, 30}, {{2, 0, 0}, 10},
                                         {{1, 2, 1}, 30}, {{1, 0, 0}, 10}, {{0, 5, 3}, 30},
                                         {{0, 0, 0}, 10}};
  expect_same(out, want);
}

TEST(FeedbackResolver, BiasAbsentAndInvalid) {
  // Level 0 page (5,3) absent: resolves to (1, 2, 1).
  FakeSource src(small_geometry(8, 6), 1, [](const PageId& id) { return id == PageId{0, 5, 3}; });
  FeedbackResolver resolver(src);
  std::vector<PageRequest> out;
  std::vector<uint32_t> fb = {feedback_pack(0, 5, 3), feedback_pack(0, 8, 0) /* x outside */,
                              0xE0000000u, kFeedbackNone};
  ResolveStats st = resolver.resolve(fb, 0, out);
  EXPECT_EQ(st.invalid_pixels, 2u);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out.back().id, (PageId{1, 2, 1}));
  // A bias beyond the last level clamps to the root.
  st = resolver.resolve(std::span(fb).first(1), 30, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, (PageId{3, 0, 0}));
  // Empty and all-background buffers give nothing.
  st = resolver.resolve({}, 0, out);
  EXPECT_TRUE(out.empty());
  std::vector<uint32_t> bg(1000, kFeedbackNone);
  st = resolver.resolve(bg, 0, out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(st.pixels, 0u);
}

TEST(FeedbackResolver, FullHdBufferManyPages) {
  // 4096 x 4096 pages at level 0 (the format's limit): a 1920x1080 buffer of 8x8-pixel tiles,
  // every tile a different page, exercises table growth; compared with the naive version.
  PageGeometry g;
  g.payload = 120;
  g.border = 4;
  g.width = 4096 * 120;
  g.height = 4096 * 120;
  FakeSource src(g, 1);
  FeedbackResolver resolver(src);
  std::vector<uint32_t> fb(1920 * 1080);
  for (uint32_t y = 0; y < 1080; ++y)
    for (uint32_t x = 0; x < 1920; ++x)
      fb[y * 1920 + x] = feedback_pack((x / 64) % 3, 4095 - x / 8, y / 8);
  std::vector<PageRequest> out;
  const ResolveStats st = resolver.resolve(fb, 0, out);
  EXPECT_EQ(st.pixels, 1920u * 1080u);
  EXPECT_EQ(st.unique_values, 240u * 135u);
  expect_same(out, naive_resolve(src, fb, 0));
}

TEST(FeedbackResolver, TexturesShareOneBufferEachResolverSeesItsOwn) {
  FakeSource src(small_geometry(8, 6), 1);
  std::vector<uint32_t> fb;
  for (int i = 0; i < 40; ++i) fb.push_back(feedback_pack(0, 1, 2, 0));
  for (int i = 0; i < 25; ++i) fb.push_back(feedback_pack(0, 6, 5, 3));
  fb.push_back(feedback_pack(1, 3, 2, 3));
  fb.push_back(0xE0000001u);  // texture 7 is reserved: invalid for everyone
  fb.push_back(kFeedbackNone);
  std::vector<PageRequest> out0, out3, out5;
  const ResolveStats s0 = FeedbackResolver(src, 0).resolve(fb, 0, out0);
  const ResolveStats s3 = FeedbackResolver(src, 3).resolve(fb, 0, out3);
  const ResolveStats s5 = FeedbackResolver(src, 5).resolve(fb, 0, out5);
  EXPECT_EQ(s0.pixels, 41u);  // its 40 and the invalid one
  EXPECT_EQ(s0.invalid_pixels, 1u);
  EXPECT_EQ(s0.other_texture_pixels, 26u);
  EXPECT_EQ(s3.pixels, 27u);
  EXPECT_EQ(s3.invalid_pixels, 1u);
  EXPECT_EQ(s3.other_texture_pixels, 40u);
  EXPECT_EQ(s5.pixels, 1u);
  EXPECT_EQ(s5.other_texture_pixels, 66u);
  EXPECT_TRUE(out5.empty());
  // Texture 0 wants (0,1,2) and its ancestors; texture 3 (0,6,5), (1,3,2) and theirs.
  const std::vector<PageRequest> want0 = {
      {{3, 0, 0}, 40}, {{2, 0, 0}, 40}, {{1, 0, 1}, 40}, {{0, 1, 2}, 40}};
  const std::vector<PageRequest> want3 = {
      {{3, 0, 0}, 26}, {{2, 1, 1}, 26}, {{1, 3, 2}, 26}, {{0, 6, 5}, 25}};
  expect_same(out0, want0);
  expect_same(out3, want3);
}

}  // namespace
}  // namespace vt
