// Atlas rasterisation: exact (no sample in two triangles, shared edges and vertices on texel
// centres included), conservative (every texel a triangle touches is covered) and chart-aware.
#include <gtest/gtest.h>

#include <random>

#include "tests/unwrap/grid_triangles.h"

#include "bake/transfer.h"

namespace vt {
namespace {

using Tris = std::vector<std::array<double, 6>>;

// A jittered grid of quads split into triangles, all sharing edges: one chart.
Tris jittered_grid(double x0, double y0, double cell, int n, double jitter, uint32_t seed,
                   bool snap_to_centres) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> d(-jitter, jitter);
  std::vector<std::array<double, 2>> v;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      double x = x0 + i * cell, y = y0 + j * cell;
      if (i > 0 && i < n && j > 0 && j < n) x += d(rng), y += d(rng);
      if (snap_to_centres) x = std::floor(x) + 0.5, y = std::floor(y) + 0.5;
      v.push_back({x, y});
    }
  }
  return test::grid_triangles(v, n);
}

bool inside_closed(const std::array<double, 6>& t, double px, double py, bool strict) {
  double s = 0;
  double e[3];
  for (int k = 0; k < 3; ++k) {
    int i = k, j = (k + 1) % 3;
    e[k] = (t[2 * j] - t[2 * i]) * (py - t[2 * i + 1]) -
           (t[2 * j + 1] - t[2 * i + 1]) * (px - t[2 * i]);
  }
  double area = (t[2] - t[0]) * (t[5] - t[1]) - (t[3] - t[1]) * (t[4] - t[0]);
  s = area > 0 ? 1 : -1;
  for (double v : e) {
    if (strict ? v * s <= 0 : v * s < 0) return false;
  }
  return true;
}

TEST(Raster, NoSampleClaimedTwiceAndEveryCentreInsideTheUnionCovered) {
  for (bool snap : {false, true}) {
    for (int ss : {1, 4, 16}) {
      Tris tris = jittered_grid(3.25, 2.75, 5.5, 8, 1.2, 7 + ss, snap);
      const uint32_t W = 56, H = 56;
      AtlasRaster r = rasterize_atlas(tris, std::vector<int32_t>(tris.size(), 0), W, H, ss);
      EXPECT_EQ(r.double_sampled, 0u) << "supersample " << ss << " snap " << snap;
      EXPECT_EQ(r.contested_texels, 0u);
      // The union is the grid's outline (the border vertices are not jittered).
      double lo_x = snap ? std::floor(3.25) + 0.5 : 3.25,
             lo_y = snap ? std::floor(2.75) + 0.5 : 2.75;
      double hi_x = snap ? std::floor(3.25 + 44) + 0.5 : 3.25 + 44,
             hi_y = snap ? std::floor(2.75 + 44) + 0.5 : 2.75 + 44;
      auto pattern = supersample_pattern(ss);
      for (uint32_t y = 0; y < H; ++y) {
        for (uint32_t x = 0; x < W; ++x) {
          size_t i = size_t(y) * W + x;
          // Samples strictly inside the outline must each be claimed by exactly one triangle.
          int expect = 0;
          for (auto& s : pattern) {
            double px = x + s[0], py = y + s[1];
            if (px > lo_x && px < hi_x && py > lo_y && py < hi_y) ++expect;
          }
          if (expect == int(pattern.size())) {
            EXPECT_EQ(r.inside[i], expect) << x << "," << y;
          }
          // Texels whose open square meets the outline are covered; others are not.
          bool touches = x + 1 > lo_x && x < hi_x && y + 1 > lo_y && y < hi_y;
          EXPECT_EQ(r.owner[i] >= 0, touches) << x << "," << y << " snap " << snap;
        }
      }
    }
  }
}

TEST(Raster, ConservativeCoverageMatchesBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> d(0.0, 30.0);
  Tris tris;
  std::vector<int32_t> chart;
  for (int t = 0; t < 40; ++t) {
    double cx = d(rng), cy = d(rng);
    std::uniform_real_distribution<double> s(-3.0, 3.0);
    tris.push_back({cx, cy, cx + s(rng), cy + s(rng), cx + s(rng), cy + s(rng)});
    chart.push_back(t);
  }
  const uint32_t W = 32, H = 32;
  AtlasRaster r = rasterize_atlas(tris, chart, W, H, 1);
  // Brute force: a texel is touched when a fine sample of its open square is inside a triangle.
  uint64_t missing = 0, extra = 0;
  for (uint32_t y = 0; y < H; ++y) {
    for (uint32_t x = 0; x < W; ++x) {
      bool touched = false;
      for (int j = 1; j < 32 && !touched; ++j)
        for (int i = 1; i < 32 && !touched; ++i)
          for (const auto& t : tris)
            if (inside_closed(t, x + i / 32.0, y + j / 32.0, false)) {
              touched = true;
              break;
            }
      bool covered = r.owner[size_t(y) * W + x] >= 0;
      if (touched && !covered) ++missing;
      // A covered texel the fine grid missed must at least have the triangle near it.
      if (covered && !touched) {
        const auto& t = tris[r.owner[size_t(y) * W + x]];
        double minx = std::min({t[0], t[2], t[4]}), maxx = std::max({t[0], t[2], t[4]});
        double miny = std::min({t[1], t[3], t[5]}), maxy = std::max({t[1], t[3], t[5]});
        if (maxx <= x || minx >= x + 1 || maxy <= y || miny >= y + 1) ++extra;
      }
    }
  }
  EXPECT_EQ(missing, 0u);
  EXPECT_EQ(extra, 0u);
  EXPECT_GT(r.contested_texels, 0u);  // random triangles of different charts do overlap
}

TEST(Raster, ChartsOneTexelApartAreNotContestedTouchingOnesAre) {
  Tris a = jittered_grid(2.0, 2.0, 4.0, 3, 0.0, 1, false);   // x in [2, 14]
  Tris b = jittered_grid(15.0, 2.0, 4.0, 3, 0.0, 1, false);  // x in [15, 27]: gap of a texel
  Tris c =
      jittered_grid(13.75, 2.0, 4.0, 3, 0.0, 1, false);  // x in [13.75, 25.75]: texel 13 shared
  auto run = [](Tris x, const Tris& y) {
    std::vector<int32_t> chart(x.size(), 0);
    x.insert(x.end(), y.begin(), y.end());
    chart.resize(x.size(), 1);
    return rasterize_atlas(x, chart, 32, 32, 1);
  };
  EXPECT_EQ(run(a, b).contested_texels, 0u);
  AtlasRaster touching = run(a, c);
  EXPECT_EQ(touching.contested_texels, 12u);  // column 13, rows 2..13
  EXPECT_EQ(touching.double_sampled, 0u);
}

TEST(Raster, DegenerateAndNonFiniteTrianglesCoverNothing) {
  Tris t = {{1, 1, 5, 5, 9, 9},
            {NAN, 1, 2, 2, 3, 1},
            {1, 1, INFINITY, 3, 2, 8},
            {2.5, 2.5, 2.5, 2.5, 2.5, 2.5}};
  AtlasRaster r = rasterize_atlas(t, {0, 1, 2, 3}, 16, 16, 4);
  for (int32_t o : r.owner) EXPECT_EQ(o, -1);
}

TEST(Raster, SupersamplePatterns) {
  for (int n : {1, 4, 16}) {
    auto p = supersample_pattern(n);
    ASSERT_EQ(p.size(), size_t(n));
    double mx = 0, my = 0;
    for (auto& s : p) {
      EXPECT_GT(s[0], 0);
      EXPECT_LT(s[0], 1);
      mx += s[0], my += s[1];
    }
    EXPECT_DOUBLE_EQ(mx / n, 0.5);
    EXPECT_DOUBLE_EQ(my / n, 0.5);
  }
}

}  // namespace
}  // namespace vt
