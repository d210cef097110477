// unwrap_scene on procedural meshes: validity (no flip, no overlap, every face mapped, UVs in
// [0, 1]), stretch, seams, instances and determinism.
#include <gtest/gtest.h>

#include <array>
#include <set>

#include "mesh_gen.h"
#include "scene/tangent_frame.h"

namespace vt::test {
namespace {

TEST(Unwrap, FlatGridIsOneIsometricChart) {
  Scene s = scene_of(flat_grid(20, 10, 2.0, 1.0));
  auto r = unwrap::unwrap_scene(s, small_options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  expect_valid(s, *r, 4);
  EXPECT_EQ(r->stats.charts, 1);
  EXPECT_NEAR(r->stats.stretch_l2, 1.0, 1e-4);
  EXPECT_NEAR(r->stats.stretch_linf, 1.0, 1e-3);
  // A 2:1 rectangle in a 480×480 atlas: the density search fills the width (rotation allowed).
  EXPECT_GT(r->stats.utilisation, 0.3);
}

TEST(Unwrap, SphereHasLowStretchAndFullCoverageOfFaces) {
  Scene s = scene_of(sphere(48, 24));
  auto r = unwrap::unwrap_scene(s, small_options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  expect_valid(s, *r, 4);
  EXPECT_GT(r->stats.charts, 1);  // a closed surface can never be one disk
  EXPECT_LT(r->stats.stretch_l2, 1.05);
  EXPECT_GT(r->stats.utilisation, 0.3);
}

TEST(Unwrap, NewUvSetIsAppendedAfterExistingSets) {
  Primitive p = flat_grid(4, 4);
  p.uvs.resize(2);
  for (auto& set : p.uvs)
    for (const auto& v : p.positions) set.push_back({v[0], v[1]});
  Scene s = scene_of(p);
  auto r = unwrap::unwrap_scene(s, small_options());
  ASSERT_TRUE(r.ok());
  const auto& out = r->scene.meshes[0].primitives[0];
  ASSERT_EQ(out.uvs.size(), 3u);  // TEXCOORD_2 is the atlas
  // Old UV sets are carried per vertex: each output vertex's old UV equals its position here.
  for (size_t v = 0; v < out.positions.size(); ++v) {
    EXPECT_EQ(out.uvs[0][v][0], out.positions[v][0]);
    EXPECT_EQ(out.uvs[1][v][1], out.positions[v][1]);
  }
}

TEST(Unwrap, OriginalUvSeamsAlwaysCut) {
  // A flat grid whose left and right halves have different UV islands (duplicated seam
  // vertices with different UVs): the seam must separate charts even though it is flat.
  Primitive p;
  auto half = flat_grid(5, 5, 1.0, 1.0);
  for (int side = 0; side < 2; ++side) {
    uint32_t base = static_cast<uint32_t>(p.positions.size());
    for (const auto& v : half.positions) p.positions.push_back({v[0] + side, v[1], 0});
    for (uint32_t i : half.indices) p.indices.push_back(base + i);
  }
  p.uvs.resize(1);
  for (size_t v = 0; v < p.positions.size(); ++v)
    p.uvs[0].push_back({v < half.positions.size() ? 0.0f : 0.5f, 0.0f});
  Scene s = scene_of(p);
  auto r = unwrap::unwrap_scene(s, small_options());
  ASSERT_TRUE(r.ok());
  expect_valid(s, *r, 4);
  EXPECT_EQ(r->stats.charts, 2);
  // Without the UV difference the two halves weld into one chart.
  p.uvs.clear();
  Scene s2 = scene_of(p);
  auto r2 = unwrap::unwrap_scene(s2, small_options());
  ASSERT_TRUE(r2.ok());
  EXPECT_EQ(r2->stats.charts, 1);
}

TEST(Unwrap, CoincidentCopiesOfASurfaceStayWholeCharts) {
  // The same grid three times over, vertices of its own each, positions and indices equal
  // (Sweet Home 3D's lily: petals stacked two to four deep), the third wound the other way (a
  // back side). Welded, every edge is used six times and cut, a chart a triangle; the copies'
  // own indices keep each a sheet: one chart each.
  const Primitive grid = flat_grid(8, 8);
  Primitive p;
  for (int copy = 0; copy < 3; ++copy) {
    const uint32_t base = static_cast<uint32_t>(p.positions.size());
    p.positions.insert(p.positions.end(), grid.positions.begin(), grid.positions.end());
    for (size_t i = 0; i < grid.indices.size(); i += 3) {
      const uint32_t a = grid.indices[i], b = grid.indices[i + 1], c = grid.indices[i + 2];
      for (uint32_t v : copy == 2 ? std::array{a, c, b} : std::array{a, b, c})
        p.indices.push_back(base + v);
    }
  }
  Scene s = scene_of(p);
  auto r = unwrap::unwrap_scene(s, small_options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  expect_valid(s, *r, 4);
  EXPECT_EQ(r->stats.charts, 3);
}

TEST(Unwrap, DefaultSizeGrowsWhereTheChartsCannotFitIt) {
  // 1,000 separate triangles, nothing textured, 64 texels between charts: the gutters alone
  // need ceil((sqrt(1000) * 65 - 64) / 120) = 17 pages, over the default 16.
  Primitive p;
  for (int i = 0; i < 1000; ++i) {
    const float x = float(i % 40) * 3.0f, y = float(i / 40) * 3.0f;
    const uint32_t base = static_cast<uint32_t>(p.positions.size());
    p.positions.push_back({x, y, 0});
    p.positions.push_back({x + 1, y, 0});
    p.positions.push_back({x, y + 1, 0});
    p.indices.insert(p.indices.end(), {base, base + 1, base + 2});
  }
  Scene s = scene_of(p);
  unwrap::UnwrapOptions o;
  o.padding = 64;
  o.threads = 2;
  auto grown = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(grown.ok()) << grown.status().message();
  expect_valid(s, *grown, 64);
  EXPECT_EQ(grown->stats.charts, 1000);
  EXPECT_GE(grown->stats.pages_x, 17);
  EXPECT_EQ(grown->stats.pages_x, grown->stats.pages_y);
  EXPECT_EQ(grown->stats.density_rule, "default size, grown to fit its charts");
  // A size asked for is kept, and the error says what would fit.
  o.size_pages = 16;
  auto asked = unwrap::unwrap_scene(s, o);
  ASSERT_FALSE(asked.ok());
  EXPECT_EQ(asked.status().message(),
            "1000 charts do not fit in 16 pages at any density (with --padding 64 between charts "
            "they need at least 17): a larger --size or --max-size, or a smaller --padding");
}

TEST(Unwrap, ACornerSharedAcrossChartsKeepsItsSmoothNormal) {
  // A box of 8 shared corners and no normals: every consumer shades it with normals smoothed
  // over the shared corners (scene::compute_normals). Its faces land in different charts, and
  // normals recomputed on the split corners would be flat; the unwrapped box carries the
  // source's instead, so the bake and the validator's reference light it alike.
  Primitive box;
  for (int i = 0; i < 8; ++i)
    box.positions.push_back({float(i & 1), float(i >> 1 & 1), float(i >> 2)});
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads)
    box.indices.insert(box.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
  const std::vector<scene::Vec3> smooth = scene::compute_normals(box);
  Scene s = scene_of(box);
  auto r = unwrap::unwrap_scene(s, small_options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  expect_valid(s, *r, 4);
  EXPECT_GT(r->stats.charts, 1);
  const Primitive& out = r->scene.meshes[0].primitives[0];
  ASSERT_GT(out.positions.size(), 8u);  // corners split along the charts
  ASSERT_EQ(out.normals.size(), out.positions.size());
  for (size_t v = 0; v < out.positions.size(); ++v) {
    const auto& q = out.positions[v];
    const size_t source = size_t(q[0]) | size_t(q[1]) << 1 | size_t(q[2]) << 2;
    for (int k = 0; k < 3; ++k) {
      EXPECT_FLOAT_EQ(out.normals[v][k], smooth[source][k]) << v;
      EXPECT_GT(std::abs(out.normals[v][k]), 0.1f) << v;  // between its three faces, not flat
    }
  }
}

TEST(Unwrap, ANormalMappedCornerSharedAcrossChartsKeepsItsSourceTangent) {
  // As the smooth normal above: a normal map's frame, derived from the source UVs where the
  // file gives none, averages every face around a shared corner in the validator's reference
  // (which derives it on the source). Derived on the corners split along the charts, a corner
  // averages its own chart's faces alone, so the unwrapped box carries the source's.
  Primitive box;
  for (int i = 0; i < 8; ++i) {
    const float x = float(i & 1), y = float(i >> 1 & 1), z = float(i >> 2);
    box.positions.push_back({x, y, z});
    box.uvs.resize(1);
    box.uvs[0].push_back({0.7f * x + 0.3f * z, 0.6f * y + 0.2f * x + 0.1f * z});
  }
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads)
    box.indices.insert(box.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
  box.material = 0;
  const std::vector<scene::Vec4> source =
      scene::compute_tangents(box, scene::compute_normals(box), 0);
  Scene s = scene_of(box);
  s.materials.resize(1);
  s.materials[0].normal_texture.image = 0;  // the unwrap reads no image
  auto r = unwrap::unwrap_scene(s, small_options());
  ASSERT_TRUE(r.ok()) << r.status().message();
  expect_valid(s, *r, 4);
  const Primitive& out = r->scene.meshes[0].primitives[0];
  ASSERT_GT(out.positions.size(), 8u);  // corners split along the charts
  ASSERT_EQ(out.tangents.size(), out.positions.size());
  const std::vector<scene::Vec4> split = scene::compute_tangents(out, out.normals, 0);
  int differs = 0;
  for (size_t v = 0; v < out.positions.size(); ++v) {
    const auto& q = out.positions[v];
    const size_t corner = size_t(q[0]) | size_t(q[1]) << 1 | size_t(q[2]) << 2;
    for (int k = 0; k < 4; ++k) EXPECT_FLOAT_EQ(out.tangents[v][k], source[corner][k]) << v;
    differs += std::abs(split[v][0] - source[corner][0]) +
                   std::abs(split[v][1] - source[corner][1]) +
                   std::abs(split[v][2] - source[corner][2]) >
               0.01f;
  }
  EXPECT_GT(differs, 0);  // what deriving on the split corners would have given instead
  // Without a normal map no frame is needed, and none is made.
  s.materials[0].normal_texture.image = -1;
  auto plain = unwrap::unwrap_scene(s, small_options());
  ASSERT_TRUE(plain.ok());
  EXPECT_TRUE(plain->scene.meshes[0].primitives[0].tangents.empty());
}

TEST(Unwrap, MaterialBoundariesCut) {
  Primitive a = flat_grid(4, 4), b = flat_grid(4, 4);
  for (auto& v : b.positions) v[0] += 1.0f;  // shares the x = 1 edge geometrically
  a.material = 0;
  b.material = 1;
  std::vector<Primitive> prims = {a, b};
  Scene s = scene_of(prims);
  s.materials.resize(2);
  auto r = unwrap::unwrap_scene(s, small_options());
  ASSERT_TRUE(r.ok());
  expect_valid(s, *r, 4);
  EXPECT_EQ(r->stats.charts, 2);
}

TEST(Unwrap, InstancesGetUniqueTexelsOrShare) {
  Scene s = scene_of(sphere(16, 8));
  scene::Node second;
  second.mesh = 0;
  second.local[12] = 5.0;  // translated copy
  s.nodes.push_back(second);
  s.roots.push_back(1);
  auto r = unwrap::unwrap_scene(s, small_options());
  ASSERT_TRUE(r.ok());
  expect_valid(s, *r, 4);
  ASSERT_EQ(r->scene.meshes.size(), 2u);
  EXPECT_EQ(r->scene.nodes[0].mesh, 0);
  EXPECT_EQ(r->scene.nodes[1].mesh, 1);
  EXPECT_EQ(r->stats.faces, 2 * static_cast<int64_t>(s.triangle_count()));
  // The two instances' charts do not share texels: the overlap check covers all triangles.
  auto o = small_options();
  o.share_instances = true;
  auto shared = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(shared.ok());
  EXPECT_EQ(shared->scene.meshes.size(), 1u);
  EXPECT_EQ(shared->stats.faces, static_cast<int64_t>(s.triangle_count()));
}

TEST(Unwrap, TexelsPerUnitSetsTheScale) {
  Scene s = scene_of(flat_grid(4, 4, 1.0, 1.0));
  unwrap::UnwrapOptions o;
  o.texels_per_unit = 100.0;
  o.padding = 2;
  auto r = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(r.ok());
  expect_valid(s, *r, 2);
  EXPECT_EQ(r->stats.atlas_width, 120);
  EXPECT_EQ(r->stats.atlas_height, 120);
  // A 1×1 square at 100 texels/unit covers 100×100 = 10,000 texel centres (± one row/column
  // per edge because the square sits at an integer offset).
  int64_t covered = static_cast<int64_t>(std::llround(r->stats.utilisation * 120 * 120));
  EXPECT_NEAR(covered, 10000, 201);
}

TEST(Unwrap, ArapMethodIsValid) {
  Scene s = scene_of(grid(
      16, 16, 1, 1, [](double x, double y) { return 0.3 * std::sin(3 * x) * std::cos(2 * y); }));
  auto o = small_options();
  o.method = unwrap::Method::kArap;
  auto r = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(r.ok());
  expect_valid(s, *r, 4);
  EXPECT_LT(r->stats.stretch_l2, 1.05);
}

TEST(Unwrap, Deterministic) {
  Scene s = scene_of(sphere(32, 16));
  auto o = small_options();
  auto a = unwrap::unwrap_scene(s, o);
  o.threads = 1;
  auto b = unwrap::unwrap_scene(s, o);
  ASSERT_TRUE(a.ok() && b.ok());
  const auto& pa = a->scene.meshes[0].primitives[0];
  const auto& pb = b->scene.meshes[0].primitives[0];
  EXPECT_EQ(pa.indices, pb.indices);
  EXPECT_EQ(pa.uvs.back(), pb.uvs.back());
}

TEST(Unwrap, RejectsBadOptions) {
  Scene s = scene_of(flat_grid(1, 1));
  unwrap::UnwrapOptions o;
  o.padding = -1;
  EXPECT_EQ(unwrap::unwrap_scene(s, o).status().code(), ErrorCode::kInvalidArgument);
  o = {};
  o.texels_per_unit = std::nan("");
  EXPECT_EQ(unwrap::unwrap_scene(s, o).status().code(), ErrorCode::kInvalidArgument);
  o = {};
  o.texels_per_unit = 1e9;  // a 1e9-texel-wide atlas
  EXPECT_EQ(unwrap::unwrap_scene(s, o).status().code(), ErrorCode::kResourceLimit);
}

TEST(Unwrap, ReportAndPicture) {
  Scene s = scene_of(sphere(16, 8));
  auto r = unwrap::unwrap_scene(s, small_options());
  ASSERT_TRUE(r.ok());
  std::string json = unwrap::report_json(r->stats);
  EXPECT_NE(json.find("\"utilisation\""), std::string::npos);
  EXPECT_NE(json.find("\"overlapping_texels\": 0"), std::string::npos);
  std::string png = ::testing::TempDir() + "unwrap_atlas.png";
  ASSERT_TRUE(unwrap::write_atlas_picture(*r, png, 256).ok());
  FILE* f = std::fopen(png.c_str(), "rb");
  ASSERT_NE(f, nullptr);
  unsigned char sig[8] = {};
  EXPECT_EQ(std::fread(sig, 1, 8, f), 8u);
  std::fclose(f);
  EXPECT_EQ(sig[1], 'P');
  EXPECT_EQ(sig[2], 'N');
}

// Fitting to a size searches the density: at every size the charts fill the square alike, so
// the density follows the side (the step sizing from the last trial must not stop short).
TEST(Unwrap, FittedDensityFollowsTheAtlasSide) {
  Scene s = scene_of(sphere(32, 16));
  double tpu[2] = {0, 0};
  const int sizes[2] = {4, 16};
  for (int i = 0; i < 2; ++i) {
    auto r = unwrap::unwrap_scene(s, small_options(sizes[i]));
    ASSERT_TRUE(r.ok()) << r.status().message();
    EXPECT_EQ(r->stats.pages_x, sizes[i]);
    EXPECT_EQ(r->stats.pages_y, sizes[i]);
    EXPECT_GT(r->stats.utilisation, 0.35);
    tpu[i] = r->stats.texels_per_unit;
  }
  EXPECT_NEAR(tpu[1] / tpu[0], 4.0, 0.4);
}

}  // namespace
}  // namespace vt::test
