// Hard cases from issue 5: each gives a valid atlas (no overlap, no flip, no NaN, every face
// mapped) or a clear error, never a crash or a hang.
#include <gtest/gtest.h>

#include <chrono>

#include "mesh_gen.h"

namespace vt::test {
namespace {

void expect_unwraps(const Scene& s, unwrap::UnwrapOptions o = small_options(),
                    int padding_check = 4) {
  auto r = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  expect_valid(s, *r, padding_check);
}

TEST(HardCases, DegenerateTriangles) {
  Primitive p = flat_grid(6, 6);
  uint32_t n = static_cast<uint32_t>(p.positions.size());
  // Collinear (zero area, nonzero edges), a repeated index, and three identical positions.
  p.positions.push_back({0, 0, 1});
  p.positions.push_back({1, 0, 1});
  p.positions.push_back({2, 0, 1});
  p.positions.push_back({5, 5, 5});
  p.positions.push_back({5, 5, 5});
  p.positions.push_back({5, 5, 5});
  p.indices.insert(p.indices.end(), {n, n + 1, n + 2, 0, 0, 1, n + 3, n + 4, n + 5});
  Scene s = scene_of(p);
  auto r = unwrap::unwrap_scene(s, small_options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  expect_valid(s, *r, 4);
  EXPECT_EQ(r->stats.degenerate_faces, 3);
  EXPECT_NEAR(r->stats.stretch_l2, 1.0, 1e-3);  // zero-area faces carry no weight
}

TEST(HardCases, DegenerateInUvOfInputDoesNotMatter) {
  // An existing UV set that is all zeros (zero area in UV) must not break anything.
  Primitive p = sphere(12, 6);
  p.uvs.assign(1, std::vector<scene::Vec2>(p.positions.size(), {0, 0}));
  expect_unwraps(scene_of(p));
}

TEST(HardCases, Slivers1e6) {
  // A fan of needle triangles with aspect ratio ~1e6 plus a normal neighbour.
  Primitive p;
  p.positions.push_back({0, 0, 0});
  for (int i = 0; i <= 20; ++i) p.positions.push_back({1.0f, static_cast<float>(i * 1e-6), 0});
  for (uint32_t i = 1; i <= 20; ++i) p.indices.insert(p.indices.end(), {0, i, i + 1});
  p.positions.push_back({0, -1, 0});
  p.indices.insert(p.indices.end(), {0, 22, 1});
  expect_unwraps(scene_of(p));
}

TEST(HardCases, SliverThinnerThanFloatUvPrecision) {
  // Aspect ratio ~1e8: the isometric UV height is far below a float ulp of the atlas UVs, so
  // rounding alone would flatten it; the output must still be strictly front-facing.
  Primitive p;
  p.positions = {{0, 0, 0}, {1000, 0, 0}, {500, 1e-5f, 0}, {0, 0, 5}, {1, 0, 5}, {0, 1, 5}};
  p.indices = {0, 1, 2, 3, 4, 5};
  Scene s = scene_of(p);
  auto r = unwrap::unwrap_scene(s, small_options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  expect_valid(s, *r, 4);
  EXPECT_EQ(r->stats.degenerate_faces, 0);
}

TEST(HardCases, DuplicateVerticesWeld) {
  // The same sphere as an unindexed triangle soup: welding gives the same chart count.
  Primitive indexed = sphere(24, 12);
  Primitive soup;
  for (uint32_t i : indexed.indices) {
    soup.indices.push_back(static_cast<uint32_t>(soup.positions.size()));
    soup.positions.push_back(indexed.positions[i]);
  }
  auto a = unwrap::unwrap_scene(scene_of(indexed), small_options());
  auto b = unwrap::unwrap_scene(scene_of(soup), small_options());
  ASSERT_TRUE(a.ok() && b.ok());
  expect_valid(scene_of(soup), *b, 4);
  EXPECT_EQ(a->stats.charts, b->stats.charts);
}

TEST(HardCases, NonManifoldEdgesAndVertices) {
  Primitive p;
  // Three triangles on one edge (0, 1) and a bow-tie through vertex 5.
  p.positions = {{0, 0, 0}, {1, 0, 0}, {0.5f, 1, 0}, {0.5f, -1, 0}, {0.5f, 0, 1},
                 {3, 0, 0}, {2, 1, 0}, {2, -1, 0},   {4, 1, 0},     {4, -1, 0}};
  p.indices = {0, 1, 2, 1, 0, 3, 0, 1, 4, 5, 6, 7, 5, 9, 8};
  expect_unwraps(scene_of(p));
}

TEST(HardCases, TJunctions) {
  // A big quad beside two half-size quads: the middle vertex lies on the big quad's edge.
  Primitive p;
  p.positions = {{0, 0, 0}, {1, 0, 0},    {1, 1, 0},    {0, 1, 0},
                 {2, 0, 0}, {2, 0.5f, 0}, {1, 0.5f, 0}, {2, 1, 0}};
  p.indices = {0, 1, 2, 0, 2, 3, 1, 4, 5, 1, 5, 6, 6, 5, 7, 6, 7, 2};
  expect_unwraps(scene_of(p));
}

TEST(HardCases, TenThousandComponents) {
  Primitive p;
  for (int k = 0; k < 10000; ++k) {
    float x = static_cast<float>(k % 100) * 2, y = static_cast<float>(k / 100) * 2;
    uint32_t b = static_cast<uint32_t>(p.positions.size());
    p.positions.insert(p.positions.end(), {{x, y, 0}, {x + 1, y, 0}, {x, y + 1, 0}});
    p.indices.insert(p.indices.end(), {b, b + 1, b + 2});
  }
  Scene s = scene_of(p);
  // 10,000 charts in 8 x 8 pages leave each about 9 x 9 texels: a gutter of 4, not the
  // default's 8, so that the charts keep some texels.
  unwrap::UnwrapOptions o = small_options(8);
  o.padding = 4;
  auto r = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(r.ok()) << r.status().message();
  expect_valid(s, *r, 0);
  EXPECT_EQ(r->stats.charts, 10000);
}

TEST(HardCases, OpenBoundaries) {
  // An open cylinder (two boundary loops) and a half sphere.
  Primitive p = grid(32, 8, 2 * M_PI, 2.0, [](double, double) { return 0.0; });
  for (auto& v : p.positions) {
    double a = v[0];
    v = {static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), v[1]};
  }
  expect_unwraps(scene_of(p));
}

TEST(HardCases, HighGenusPlateWithHoles) {
  // A 40×40 grid with a 10×10 pattern of square holes (genus 100 once thickened; here an
  // open plate with 100 inner boundary loops, which no single disk can hold).
  Primitive full = flat_grid(40, 40);
  Primitive p;
  p.positions = full.positions;
  for (size_t t = 0; t < full.indices.size() / 3; ++t) {
    int quad = static_cast<int>(t / 2), i = quad % 40, j = quad / 40;
    if (i % 4 == 1 && j % 4 == 1) continue;  // a hole
    p.indices.insert(p.indices.end(), full.indices.begin() + 3 * t,
                     full.indices.begin() + 3 * t + 3);
  }
  Scene s = scene_of(p);
  auto r = unwrap::unwrap_scene(s, small_options());
  ASSERT_TRUE(r.ok());
  expect_valid(s, *r, 4);
  EXPECT_GT(r->stats.charts, 1);
  EXPECT_NEAR(r->stats.stretch_l2, 1.0, 1e-3);  // still flat
}

TEST(HardCases, FlippedWinding) {
  Primitive p = sphere(24, 12);
  for (size_t t = 0; t < p.indices.size() / 3; t += 3)
    std::swap(p.indices[3 * t + 1], p.indices[3 * t + 2]);
  expect_unwraps(scene_of(p));
}

TEST(HardCases, LargeOffsetAndTinyScale) {
  Primitive p = sphere(24, 12, 1.0);
  Scene offset = scene_of(p);
  offset.nodes[0].local[12] = 1e7;
  offset.nodes[0].local[13] = -1e7;
  auto a = unwrap::unwrap_scene(offset, small_options());
  ASSERT_TRUE(a.ok());
  expect_valid(offset, *a, 4);
  // Offset stored in the float positions themselves (a 1e4-sized mesh at 1e7).
  Primitive q = sphere(24, 12, 1e4);
  for (auto& v : q.positions) v[0] += 1e7f;
  expect_unwraps(scene_of(q));
  // Scaled by 1e-6.
  Primitive tiny = sphere(24, 12, 1e-6);
  auto c = unwrap::unwrap_scene(scene_of(tiny), small_options());
  ASSERT_TRUE(c.ok());
  expect_valid(scene_of(tiny), *c, 4);
  EXPECT_EQ(c->stats.degenerate_faces, 0);
  // Same charts and stretch as the unit sphere: the result does not depend on scale.
  auto unit = unwrap::unwrap_scene(scene_of(p), small_options());
  ASSERT_TRUE(unit.ok());
  EXPECT_EQ(unit->stats.charts, c->stats.charts);
  EXPECT_NEAR(unit->stats.stretch_l2, c->stats.stretch_l2, 1e-3);
  EXPECT_NEAR(unit->stats.stretch_l2, a->stats.stretch_l2, 1e-3);
}

TEST(HardCases, NonFinitePositionsAreAClearError) {
  for (float bad : {std::nanf(""), std::numeric_limits<float>::infinity()}) {
    Primitive p = flat_grid(2, 2);
    p.positions[4][1] = bad;
    auto r = unwrap::unwrap_scene(scene_of(p, "Body"), small_options());
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.status().message().find("'Body'"), std::string::npos) << r.status().message();
    EXPECT_NE(r.status().message().find("vertex 4"), std::string::npos) << r.status().message();
  }
}

TEST(HardCases, EmptyMeshAndOneTriangle) {
  Primitive empty;
  auto r = unwrap::unwrap_scene(scene_of(empty), small_options());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("no triangles"), std::string::npos);
  // An empty primitive beside a real one is skipped, not an error.
  Primitive one;
  one.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  one.indices = {0, 1, 2};
  std::vector<Primitive> both = {empty, one};
  Scene s = scene_of(both);
  auto r2 = unwrap::unwrap_scene(s, small_options());
  ASSERT_TRUE(r2.ok()) << r2.status().message();
  EXPECT_EQ(r2->stats.faces, 1);
  EXPECT_EQ(r2->stats.charts, 1);
  EXPECT_NEAR(r2->stats.stretch_l2, 1.0, 1e-6);
  expect_valid(s, *r2, 4);
}

TEST(HardCases, BadIndicesAreAClearError) {
  Primitive p = flat_grid(1, 1);
  p.indices[2] = 99;
  auto r = unwrap::unwrap_scene(scene_of(p, "Broken"), small_options());
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("uses vertex 99"), std::string::npos) << r.status().message();
}

TEST(HardCases, BigMesh200k) {
  // ~200k triangles of a bumpy sphere; the benchmark measures 1M.
  Primitive p = sphere(448, 224);
  for (auto& v : p.positions) {
    double bump = 1.0 + 0.02 * std::sin(17 * v[0]) * std::sin(13 * v[1]) * std::sin(11 * v[2]);
    for (float& c : v) c = static_cast<float>(c * bump);
  }
  ASSERT_GT(p.triangle_count(), 195000u);
  Scene s = scene_of(p);
  auto r = unwrap::unwrap_scene(s, small_options(16));
  ASSERT_TRUE(r.ok()) << r.status().message();
  expect_valid(s, *r, 0);
  EXPECT_LT(r->stats.stretch_l2, 1.05);
}

}  // namespace
}  // namespace vt::test
