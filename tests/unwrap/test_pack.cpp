// Chart packing: charts never share a texel, `padding` empty texels separate any two charts
// (measured with the atlas rasteriser on the placed triangles), and the result is
// deterministic.
#include <gtest/gtest.h>

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
