// The atlas rasteriser: the fill rule gives every sample one owner across shared edges (ties on
// texel centres and lattice points included), the conservative test finds every texel whose
// grown open square meets the triangle and nothing far from it, and empty triangles own nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "bake/unwrap/atlas_raster.h"
#include "tests/unwrap/grid_triangles.h"

namespace vt::unwrap {
namespace {

using Corners = std::array<double, 6>;

// An n x n lattice of quads with spacing `cell`, triangulated by grid_triangles. With `jitter` the
// interior vertices move by up to a quarter cell in eighths of a texel, so the mesh stays valid and
// ties on texel centres stay exact.
std::vector<Corners> lattice(double x0, double y0, double cell, int n, bool jitter, uint32_t seed) {
  std::mt19937 rng(seed);
  const int steps = jitter ? int(cell * 8 / 4) : 0;
  std::uniform_int_distribution<int> d(-steps, steps);
  std::vector<std::array<double, 2>> v;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      double x = x0 + i * cell, y = y0 + j * cell;
      if (i > 0 && i < n && j > 0 && j < n) x += d(rng) / 8.0, y += d(rng) / 8.0;
      v.push_back({x, y});
    }
  return test::grid_triangles(v, n);
}

std::vector<int64_t> touched(const RasterTriangle& t, double margin, const TexelRect& clip) {
  std::vector<int64_t> out;
  for_each_touched_texel(t, margin, clip,
                         [&](int64_t x, int64_t y) { out.push_back(y * 1000 + x); });
  return out;
}

TEST(AtlasRaster, EveryCentreOnSharedEdgesIsOwnedExactlyOnce) {
  for (double cell : {0.5, 1.0, 1.5, 2.0}) {
    for (uint32_t seed = 0; seed < 4; ++seed) {
      // The outline is [2, 2 + 8 cell]^2; vertices and edges run through texel centres.
      auto tris = lattice(2.0, 2.0, cell, 8, seed > 0, seed);
      std::vector<RasterTriangle> r(tris.begin(), tris.end());
      const double hi = 2.0 + 8 * cell;
      for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 24; ++x) {
          const double px = x + 0.5, py = y + 0.5;
          int owners = 0;
          double lambda[3];
          for (const auto& t : r) owners += t.contains(px, py, lambda);
          bool interior = px > 2.0 && px < hi && py > 2.0 && py < hi;
          if (interior) {
            EXPECT_EQ(owners, 1) << "cell " << cell << " seed " << seed << " at " << x << "," << y;
          } else {
            EXPECT_LE(owners, 1);
          }
        }
    }
  }
}

TEST(AtlasRaster, BarycentricsReproduceTheSample) {
  RasterTriangle t(Corners{1.25, 0.5, 7.5, 3.0, 2.0, 6.75});
  double lambda[3];
  ASSERT_TRUE(t.contains(3.5, 3.5, lambda));
  EXPECT_NEAR(lambda[0] + lambda[1] + lambda[2], 1.0, 1e-12);
  double x = lambda[0] * t.x[0] + lambda[1] * t.x[1] + lambda[2] * t.x[2];
  double y = lambda[0] * t.y[0] + lambda[1] * t.y[1] + lambda[2] * t.y[2];
  EXPECT_NEAR(x, 3.5, 1e-12);
  EXPECT_NEAR(y, 3.5, 1e-12);
  // Clockwise input is reordered; order[] maps back to the input corners.
  RasterTriangle cw(Corners{1.25, 0.5, 2.0, 6.75, 7.5, 3.0});
  EXPECT_EQ(cw.area2, t.area2);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(cw.x[k], (Corners{1.25, 0.5, 2.0, 6.75, 7.5, 3.0})[2 * cw.order[k]]);
  }
}

TEST(AtlasRaster, MarginGrowsTheOpenTexelSquare) {
  // Right edge at x = 5 exactly: texel 5's open square (5, 6) does not meet it; grown by any
  // margin it does.
  RasterTriangle t(Corners{0.5, 0.5, 5.0, 0.5, 0.5, 9.5});
  const TexelRect row0 = {0, 0, 20, 0};
  EXPECT_EQ(touched(t, 0.0, row0), (std::vector<int64_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(touched(t, kFootprintMargin, row0), (std::vector<int64_t>{0, 1, 2, 3, 4, 5}));
  // 1/32 texel short of texel 6: a larger margin reaches it, the footprint margin does not.
  RasterTriangle u(Corners{0.5, 0.5, 6.0 - 1.0 / 32, 0.5, 0.5, 9.5});
  EXPECT_EQ(touched(u, kFootprintMargin, row0).size(), 6u);
  EXPECT_EQ(touched(u, 1.0 / 16, row0).size(), 7u);
}

// Independent reference: the triangle clipped (Sutherland-Hodgman) to the closed square
// [x - g, x + 1 + g] x [y - g, y + 1 + g]; true when anything is left.
bool meets_square(const Corners& c, int64_t x, int64_t y, double g) {
  std::vector<std::array<double, 2>> poly = {{c[0], c[1]}, {c[2], c[3]}, {c[4], c[5]}};
  const double lo[2] = {x - g, y - g}, hi[2] = {x + 1 + g, y + 1 + g};
  for (int side = 0; side < 4 && !poly.empty(); ++side) {
    const int axis = side / 2;
    auto inside = [&](const std::array<double, 2>& p) {
      return side % 2 ? p[axis] <= hi[axis] : p[axis] >= lo[axis];
    };
    const double bound = side % 2 ? hi[axis] : lo[axis];
    std::vector<std::array<double, 2>> next;
    for (size_t i = 0; i < poly.size(); ++i) {
      const auto& p = poly[i];
      const auto& q = poly[(i + 1) % poly.size()];
      if (inside(p)) next.push_back(p);
      if (inside(p) != inside(q)) {
        double t = (bound - p[axis]) / (q[axis] - p[axis]);
        next.push_back({p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])});
      }
    }
    poly = std::move(next);
  }
  return !poly.empty();
}

TEST(AtlasRaster, ConservativeTouchMatchesPolygonClippingAtEveryMargin) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> pos(2.0, 14.0), size(-4.0, 4.0);
  const TexelRect clip = {0, 0, 15, 15};
  for (double margin : {0.0, kFootprintMargin, 0.25}) {
    int64_t missing = 0, far = 0;
    for (int n = 0; n < 60; ++n) {
      double cx = pos(rng), cy = pos(rng);
      Corners c = {cx, cy, cx + size(rng), cy + size(rng), cx + size(rng), cy + size(rng)};
      RasterTriangle t(c);
      std::vector<char> hit(256, 0);
      for_each_touched_texel(t, margin, clip, [&](int64_t x, int64_t y) { hit[y * 16 + x] = 1; });
      for (int64_t y = 0; y < 16; ++y)
        for (int64_t x = 0; x < 16; ++x) {
          // The open square lies between the square shrunk and grown by a hair.
          if (!hit[y * 16 + x] && meets_square(c, x, y, margin - 1e-9)) ++missing;
          if (hit[y * 16 + x] && !meets_square(c, x, y, margin + 1e-9)) ++far;
        }
    }
    EXPECT_EQ(missing, 0) << "margin " << margin;
    EXPECT_EQ(far, 0) << "margin " << margin;
  }
}

// The runs of each row and of each column are exactly the touched texels, in every clip, for
// ordinary triangles, slivers along and across the lattice, texel-aligned corners and triangles
// far larger than the clip (the packer's footprints read only the runs).
TEST(AtlasRaster, TouchedRunsAreTheTouchedTexelsByRowsAndByColumns) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> pos(-6.0, 38.0), size(-20.0, 20.0), eighth(0, 1);
  const TexelRect clip = {0, 0, 31, 23};
  std::vector<Corners> corners;
  for (int n = 0; n < 400; ++n) {
    const double cx = pos(rng), cy = pos(rng);
    Corners c = {cx, cy, cx + size(rng), cy + size(rng), cx + size(rng), cy + size(rng)};
    if (n % 4 == 1)  // on the lattice of eighths: ties with texel centres and square edges
      for (double& v : c) v = std::round(v * 8) / 8;
    if (n % 4 == 2) c[5] = c[3] + 1e-9 * eighth(rng);  // a sliver
    corners.push_back(c);
  }
  corners.push_back({-500, -500, 900, -400, 100, 700});       // covers the clip
  corners.push_back({3.5, 0.5, 3.5, 20.5, 3.5 + 1e-12, 10});  // a vertical sliver
  for (double margin : {0.0, kFootprintMargin, 0.75}) {
    for (const Corners& c : corners) {
      RasterTriangle t(c);
      std::vector<char> texels(32 * 24, 0), rows(32 * 24, 0), columns(32 * 24, 0);
      for_each_touched_texel(t, margin, clip,
                             [&](int64_t x, int64_t y) { texels[size_t(y * 32 + x)] = 1; });
      for_each_touched_run(t, margin, clip, false, [&](int64_t y, int64_t x0, int64_t x1) {
        ASSERT_LE(x0, x1);
        for (int64_t x = x0; x <= x1; ++x) rows[size_t(y * 32 + x)] += 1;
      });
      for_each_touched_run(t, margin, clip, true, [&](int64_t x, int64_t y0, int64_t y1) {
        ASSERT_LE(y0, y1);
        for (int64_t y = y0; y <= y1; ++y) columns[size_t(y * 32 + x)] += 1;
      });
      ASSERT_EQ(rows, texels) << "margin " << margin << " corner " << c[0] << "," << c[1];
      ASSERT_EQ(columns, texels) << "margin " << margin << " corner " << c[0] << "," << c[1];
    }
  }
}

TEST(AtlasRaster, SliversTouchTheTexelsTheyCrossAndSplitTheirCentres) {
  // A sliver 1e-9 texel thick along row 0's centres: it touches every texel it crosses.
  RasterTriangle above(Corners{0.5, 0.5, 9.5, 0.5, 9.5, 0.5 - 1e-9});
  RasterTriangle below(Corners{0.5, 0.5, 9.5, 0.5 + 1e-9, 9.5, 0.5});
  const TexelRect clip = {0, 0, 20, 20};
  EXPECT_EQ(touched(above, 0.0, clip), (std::vector<int64_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
  // The two slivers share the edge through the centres (1.5, 0.5) .. (8.5, 0.5): each centre
  // belongs to exactly one of them.
  double lambda[3];
  for (int x = 1; x <= 8; ++x) {
    int owners = above.contains(x + 0.5, 0.5, lambda) + below.contains(x + 0.5, 0.5, lambda);
    EXPECT_EQ(owners, 1) << x;
  }
}

TEST(AtlasRaster, EmptyTrianglesOwnNothing) {
  const std::vector<Corners> empty = {{1, 1, 5, 5, 9, 9},
                                      {2.5, 2.5, 2.5, 2.5, 2.5, 2.5},
                                      {NAN, 1, 2, 2, 3, 1},
                                      {1, 1, INFINITY, 3, 2, 8}};
  std::vector<RasterTriangle> r(empty.begin(), empty.end());
  for (const auto& t : r) {
    EXPECT_TRUE(t.empty());
    EXPECT_TRUE(t.bounds(0.5).empty());
    EXPECT_TRUE(touched(t, 0.5, {0, 0, 15, 15}).empty());
  }
  for (const auto& band : bin_by_rows(r, 16, 4)) EXPECT_TRUE(band.empty());
}

TEST(AtlasRaster, BinsListTrianglesPerBandInIndexOrder) {
  std::vector<RasterTriangle> r = {RasterTriangle(Corners{1, 14.5, 3, 14.5, 2, 17.5}),
                                   RasterTriangle(Corners{1, 1, 3, 1, 2, 3}),
                                   RasterTriangle(Corners{1, 40, 3, 40, 2, 41})};
  auto bins = bin_by_rows(r, 32, 16);
  ASSERT_EQ(bins.size(), 2u);
  EXPECT_EQ(bins[0], (std::vector<uint32_t>{0, 1}));
  EXPECT_EQ(bins[1], (std::vector<uint32_t>{0}));  // triangle 2 lies below the atlas
}

TEST(AtlasRaster, ClosestPointOfTheTriangle) {
  RasterTriangle t(Corners{0, 0, 4, 0, 0, 4});
  EXPECT_DOUBLE_EQ(t.distance2_to(1, 1), 0.0);
  EXPECT_DOUBLE_EQ(t.distance2_to(2, -3), 9.0);   // below the edge y = 0
  EXPECT_DOUBLE_EQ(t.distance2_to(-1, -1), 2.0);  // nearest the corner (0, 0)
  double lambda[3];
  t.closest_barycentrics(3, 3, lambda);  // onto the hypotenuse at (2, 2)
  double x = lambda[0] * t.x[0] + lambda[1] * t.x[1] + lambda[2] * t.x[2];
  double y = lambda[0] * t.y[0] + lambda[1] * t.y[1] + lambda[2] * t.y[2];
  EXPECT_DOUBLE_EQ(x, 2.0);
  EXPECT_DOUBLE_EQ(y, 2.0);
}

}  // namespace
}  // namespace vt::unwrap
