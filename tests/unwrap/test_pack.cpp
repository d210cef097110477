// Chart packing: charts never share a texel, `padding` empty texels separate any two charts
// (measured with the atlas rasteriser on the placed triangles), and the result is
// deterministic.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "bake/unwrap/atlas_raster.h"
#include "bake/unwrap/unwrap_internal.h"

namespace vt::unwrap::detail {
namespace {

// A random fan of triangles around a centre, boxed as unwrap's fit_box does: origin at the box
// corner less a 1/16 texel margin, width and height whole texels.
PackChart random_chart(std::mt19937& rng) {
  std::uniform_real_distribution<double> radius(0.3, 9.0), jitter(0.5, 1.0);
  std::uniform_int_distribution<int> sides(3, 9);
  PackChart c;
  int n = sides(rng);
  double r = radius(rng), stretch = jitter(rng) * 2;
  c.points.push_back({0, 0});
  for (int k = 0; k < n; ++k) {
    double a = 2 * M_PI * k / n;
    c.points.push_back({r * stretch * std::cos(a) * jitter(rng), r * std::sin(a) * jitter(rng)});
  }
  for (int k = 0; k < n; ++k) c.tris.push_back({0, uint32_t(1 + k), uint32_t(1 + (k + 1) % n)});
  const auto [lo, hi] = bounds_of(c.points);
  const double m = 2 * kFootprintMargin;
  c.width = std::max(1.0, std::ceil(hi.x - lo.x + 2 * m));
  c.height = std::max(1.0, std::ceil(hi.y - lo.y + 2 * m));
  for (Vec2d& p : c.points)
    p = {p.x - lo.x + (c.width - (hi.x - lo.x)) / 2, p.y - lo.y + (c.height - (hi.y - lo.y)) / 2};
  return c;
}

// A w x h texel rectangle inset by a quarter texel: its half turn (and, square, its quarter
// turns) have the same profile as the unturned chart, which the packer searches once.
PackChart box_chart(int w, int h) {
  PackChart c;
  const double e = 0.25;
  c.points = {{e, e}, {w - e, e}, {w - e, h - e}, {e, h - e}};
  c.tris = {{0, 1, 2}, {0, 2, 3}};
  c.width = w, c.height = h;
  return c;
}

TEST(Bounds, HoldEveryPointAndAreInvertedWhenEmpty) {
  const auto [lo, hi] = bounds_of(std::vector<Vec2d>{{1, -2}, {-3, 4}, {0.5, 0}});
  EXPECT_EQ(lo.x, -3);
  EXPECT_EQ(lo.y, -2);
  EXPECT_EQ(hi.x, 1);
  EXPECT_EQ(hi.y, 4);
  const auto b = bounds_of(std::vector<Vec3d>{{1, 2, 3}, {-1, 5, -7}});
  EXPECT_EQ(b.lo.z, -7);
  EXPECT_EQ(b.hi.z, 3);
  EXPECT_EQ(b.lo.x, -1);
  EXPECT_EQ(b.hi.y, 5);
  const auto none = bounds_of(std::vector<Vec2d>{});
  EXPECT_GT(none.lo.x, none.hi.x);
}

// Owner chart of every texel the placed charts touch with `margin`; counts texels two charts
// touch and texels with another chart's texel within `padding` (Chebyshev).
struct Layout {
  int64_t shared = 0, too_close = 0, outside = 0;
};
Layout measure(const std::vector<PackChart>& charts, const PackResult& r, int width, int padding,
               double margin) {
  const int height = r.height + 1;
  std::vector<int32_t> owner(size_t(width) * height, -1);
  Layout out;
  for (size_t c = 0; c < charts.size(); ++c) {
    for (const auto& t : charts[c].tris) {
      Vec2d a = place_point(charts[c], r.placements[c], charts[c].points[t[0]]);
      Vec2d b = place_point(charts[c], r.placements[c], charts[c].points[t[1]]);
      Vec2d d = place_point(charts[c], r.placements[c], charts[c].points[t[2]]);
      RasterTriangle tri({a.x, a.y, b.x, b.y, d.x, d.y});
      TexelRect all = tri.bounds(margin);
      if (all.x0 < 0 || all.y0 < 0 || all.x1 >= width) ++out.outside;
      for_each_touched_texel(tri, margin, {0, 0, width - 1, height - 1}, [&](int64_t x, int64_t y) {
        int32_t& o = owner[size_t(y) * width + x];
        if (o >= 0 && o != int32_t(c)) ++out.shared;
        o = int32_t(c);
      });
    }
  }
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      int32_t o = owner[size_t(y) * width + x];
      if (o < 0) continue;
      for (int dy = -padding; dy <= padding; ++dy)
        for (int dx = -padding; dx <= padding; ++dx) {
          int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
          int32_t p = owner[size_t(ny) * width + nx];
          if (p >= 0 && p != o) ++out.too_close;
        }
    }
  return out;
}

TEST(Pack, ChartsNeverShareATexelAndKeepThePadding) {
  for (int padding : {0, 1, 4}) {
    std::mt19937 rng(5 + padding);
    std::vector<PackChart> charts;
    for (int i = 0; i < 150; ++i) charts.push_back(random_chart(rng));
    const int width = 240;
    PackResult r = pack_charts(charts, width, padding, 1);
    ASSERT_FALSE(r.overflow);
    EXPECT_GT(r.height, 0);
    // The placed triangles, exactly and with the footprint margin that absorbs float rounding.
    for (double margin : {0.0, kFootprintMargin}) {
      Layout l = measure(charts, r, width, padding, margin);
      EXPECT_EQ(l.outside, 0) << "padding " << padding;
      EXPECT_EQ(l.shared, 0) << "padding " << padding << " margin " << margin;
      EXPECT_EQ(l.too_close, 0) << "padding " << padding << " margin " << margin;
    }
  }
}

TEST(Pack, DeterministicWhateverTheThreads) {
  std::mt19937 rng(9);
  std::vector<PackChart> charts;
  for (int i = 0; i < 300; ++i) charts.push_back(random_chart(rng));
  PackResult a = pack_charts(charts, 360, 2, 1), b = pack_charts(charts, 360, 2, 4);
  ASSERT_EQ(a.placements.size(), b.placements.size());
  EXPECT_EQ(a.height, b.height);
  for (size_t c = 0; c < a.placements.size(); ++c) {
    EXPECT_EQ(a.placements[c].rotation, b.placements[c].rotation);
    EXPECT_EQ(a.placements[c].x, b.placements[c].x);
    EXPECT_EQ(a.placements[c].y, b.placements[c].y);
  }
}

// The packer's rule written out plainly, cell by cell and column by column (as the packer did
// before its search by runs): the cells every triangle touches, each rotation's lowest and
// highest cell per column, and at every x the drop height and wasted space; lowest top, then
// least waste, then the first position wins.
PackResult reference_pack(const std::vector<PackChart>& charts, int width, int padding) {
  constexpr int kNone = std::numeric_limits<int>::max();
  struct Rotated {
    int w = 0, h = 0;
    std::vector<int> top, low;  // top per column (0 = empty); low per dilated column
  };
  std::vector<std::array<Rotated, 4>> rotated(charts.size());
  for (size_t c = 0; c < charts.size(); ++c) {
    const int gx = std::max(1, int(std::ceil(charts[c].width)));
    const int gy = std::max(1, int(std::ceil(charts[c].height)));
    std::vector<char> cell(size_t(gx) * gy, 0);
    for (const auto& t : charts[c].tris) {
      const Vec2d &a = charts[c].points[t[0]], &b = charts[c].points[t[1]],
                  &d = charts[c].points[t[2]];
      for_each_touched_texel(RasterTriangle({a.x, a.y, b.x, b.y, d.x, d.y}), kFootprintMargin,
                             {0, 0, gx - 1, gy - 1},
                             [&](int64_t i, int64_t j) { cell[size_t(j * gx + i)] = 1; });
    }
    for (int r = 0; r < 4; ++r) {
      Rotated& ro = rotated[c][size_t(r)];
      ro.w = r % 2 ? gy : gx, ro.h = r % 2 ? gx : gy;
      std::vector<int> bottom(size_t(ro.w), kNone);
      ro.top.assign(size_t(ro.w), 0);
      for (int j = 0; j < gy; ++j)
        for (int i = 0; i < gx; ++i) {
          if (!cell[size_t(j * gx + i)]) continue;
          const int x = r == 0 ? i : r == 1 ? gy - 1 - j : r == 2 ? gx - 1 - i : j;
          const int y = r == 0 ? j : r == 1 ? i : r == 2 ? gy - 1 - j : gx - 1 - i;
          bottom[size_t(x)] = std::min(bottom[size_t(x)], y);
          ro.top[size_t(x)] = std::max(ro.top[size_t(x)], y + 1);
        }
      ro.low.assign(size_t(ro.w + 2 * padding), kNone);
      for (int x = 0; x < ro.w; ++x)
        for (int d = 0; d <= 2 * padding && bottom[size_t(x)] != kNone; ++d)
          ro.low[size_t(x + d)] = std::min(ro.low[size_t(x + d)], bottom[size_t(x)] - padding);
    }
  }
  std::vector<size_t> order(charts.size());
  std::iota(order.begin(), order.end(), size_t{0});
  auto grid = [&](size_t c) {
    return std::pair<int, int>(std::max(1, int(std::ceil(charts[c].width))),
                               std::max(1, int(std::ceil(charts[c].height))));
  };
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const auto [ax, ay] = grid(a);
    const auto [bx, by] = grid(b);
    if (std::min(ax, ay) != std::min(bx, by)) return std::min(ax, ay) > std::min(bx, by);
    return int64_t(ax) * ay > int64_t(bx) * by;
  });
  PackResult result;
  result.placements.resize(charts.size());
  result.width = width;
  std::vector<int> sky(size_t(width), 0);
  for (size_t c : order) {
    int64_t best_top = std::numeric_limits<int64_t>::max(), best_waste = 0;
    Placement best;
    for (int r = 0; r < 4; ++r) {
      const Rotated& ro = rotated[c][size_t(r)];
      for (int x = 0; x + ro.w <= width; ++x) {
        int64_t y = 0;
        for (int d = 0; d < int(ro.low.size()); ++d) {
          const int ax = x + d - padding;
          if (ax >= 0 && ax < width && ro.low[size_t(d)] != kNone)
            y = std::max<int64_t>(y, sky[size_t(ax)] - ro.low[size_t(d)]);
        }
        int64_t waste = 0;
        for (int d = 0; d < ro.w; ++d)
          if (ro.top[size_t(d)] > 0)
            waste += y + ro.low[size_t(d + padding)] + padding - sky[size_t(x + d)];
        const int64_t top = y + ro.h;
        if (top < best_top || (top == best_top && waste < best_waste))
          best_top = top, best_waste = waste, best = {r, x, int(y)};
      }
    }
    if (best_top == std::numeric_limits<int64_t>::max()) {
      result.overflow = true;
      best = {0, 0, result.height + padding};
    }
    const Rotated& ro = rotated[c][size_t(best.rotation)];
    for (int d = 0; d < ro.w && best.x + d < width; ++d)
      if (ro.top[size_t(d)] > 0)
        sky[size_t(best.x + d)] = std::max(sky[size_t(best.x + d)], best.y + ro.top[size_t(d)]);
    result.height = std::max(result.height, best.y + ro.h);
    result.placements[c] = best;
  }
  return result;
}

TEST(Pack, PlacementsAreThoseOfTheCellByCellScan) {
  for (int padding : {0, 1, 3, 8}) {
    std::mt19937 rng(21 + padding);
    std::uniform_int_distribution<int> side(1, 7);
    std::vector<PackChart> charts;
    for (int i = 0; i < 120; ++i) {
      charts.push_back(random_chart(rng));
      if (i % 3 == 0) charts.push_back(box_chart(side(rng), side(rng)));
    }
    for (int width : {40, 97, 256}) {
      const PackResult got = pack_charts(charts, width, padding, 2);
      const PackResult want = reference_pack(charts, width, padding);
      EXPECT_EQ(got.height, want.height) << "padding " << padding << " width " << width;
      EXPECT_EQ(got.overflow, want.overflow);
      for (size_t c = 0; c < charts.size(); ++c) {
        EXPECT_EQ(got.placements[c].rotation, want.placements[c].rotation) << c;
        EXPECT_EQ(got.placements[c].x, want.placements[c].x) << c;
        EXPECT_EQ(got.placements[c].y, want.placements[c].y) << c;
      }
    }
  }
}

TEST(Pack, GivesUpOnceTheHeightPassesTheLimitAndOnlyThen) {
  std::mt19937 rng(33);
  std::vector<PackChart> charts;
  for (int i = 0; i < 200; ++i) charts.push_back(random_chart(rng));
  const PackResult all = pack_charts(charts, 120, 2, 1);
  // A limit the whole packing stays under changes nothing.
  const PackResult under = pack_charts(charts, 120, 2, 1, all.height);
  EXPECT_EQ(under.height, all.height);
  for (size_t c = 0; c < charts.size(); ++c) {
    EXPECT_EQ(under.placements[c].x, all.placements[c].x) << c;
    EXPECT_EQ(under.placements[c].y, all.placements[c].y) << c;
  }
  // A lower one stops as soon as the top passes it: over the limit, under the whole height.
  const int limit = all.height / 2;
  const PackResult stopped = pack_charts(charts, 120, 2, 1, limit);
  EXPECT_GT(stopped.height, limit);
  EXPECT_LT(stopped.height, all.height);
}

TEST(Pack, LongChartsTurnToFitAndTooLargeOnesOverflow) {
  // A 30 x 4 texel strip in a 10 texel wide atlas fits only turned a quarter.
  PackChart strip;
  strip.points = {{0.5, 0.5}, {29.5, 0.5}, {29.5, 3.5}, {0.5, 3.5}};
  strip.tris = {{0, 1, 2}, {0, 2, 3}};
  strip.width = 30, strip.height = 4;
  PackResult r = pack_charts({strip}, 10, 1, 1);
  EXPECT_FALSE(r.overflow);
  EXPECT_EQ(r.placements[0].rotation % 2, 1);
  EXPECT_EQ(r.height, 30 + 1);  // the padding is kept from the atlas's bottom edge too
  // Wider than the atlas in every rotation.
  PackResult o = pack_charts({strip}, 3, 1, 1);
  EXPECT_TRUE(o.overflow);
}

}  // namespace
}  // namespace vt::unwrap::detail
