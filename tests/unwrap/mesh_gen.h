// Procedural meshes and checks for the unwrap tests (no files from shared/testdata).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

#include "bake/unwrap/unwrap.h"
#include "scene/scene.h"

namespace vt::test {

using scene::Primitive;
using scene::Scene;
using scene::Vec3;

// (nx × ny) quads on [0, sx] × [0, sy], z = height(x, y); two triangles per quad.
template <typename Height>
Primitive grid(int nx, int ny, double sx, double sy, Height height) {
  Primitive p;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      double x = sx * i / nx, y = sy * j / ny;
      p.positions.push_back(
          {static_cast<float>(x), static_cast<float>(y), static_cast<float>(height(x, y))});
    }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      uint32_t a = j * (nx + 1) + i, b = a + 1, c = a + nx + 1, d = c + 1;
      p.indices.insert(p.indices.end(), {a, b, d, a, d, c});
    }
  return p;
}

inline Primitive flat_grid(int nx, int ny, double sx = 1, double sy = 1) {
  return grid(nx, ny, sx, sy, [](double, double) { return 0.0; });
}

// UV sphere (closed, poles welded).
inline Primitive sphere(int slices, int stacks, double r = 1.0) {
  Primitive p;
  p.positions.push_back({0, 0, static_cast<float>(r)});
  for (int j = 1; j < stacks; ++j)
    for (int i = 0; i < slices; ++i) {
      double th = M_PI * j / stacks, ph = 2 * M_PI * i / slices;
      p.positions.push_back({static_cast<float>(r * std::sin(th) * std::cos(ph)),
                             static_cast<float>(r * std::sin(th) * std::sin(ph)),
                             static_cast<float>(r * std::cos(th))});
    }
  p.positions.push_back({0, 0, static_cast<float>(-r)});
  uint32_t south = static_cast<uint32_t>(p.positions.size() - 1);
  auto v = [&](int j, int i) { return static_cast<uint32_t>(1 + (j - 1) * slices + (i % slices)); };
  for (int i = 0; i < slices; ++i) p.indices.insert(p.indices.end(), {0, v(1, i), v(1, i + 1)});
  for (int j = 1; j < stacks - 1; ++j)
    for (int i = 0; i < slices; ++i)
      p.indices.insert(p.indices.end(), {v(j, i), v(j + 1, i), v(j + 1, i + 1), v(j, i),
                                         v(j + 1, i + 1), v(j, i + 1)});
  for (int i = 0; i < slices; ++i)
    p.indices.insert(p.indices.end(), {v(stacks - 1, i), south, v(stacks - 1, i + 1)});
  return p;
}

inline Scene scene_of(std::vector<Primitive> prims, std::string name = "test") {
  Scene s;
  scene::Mesh m;
  m.name = std::move(name);
  m.primitives = std::move(prims);
  s.meshes.push_back(std::move(m));
  scene::Node n;
  n.mesh = 0;
  s.nodes.push_back(n);
  s.roots.push_back(0);
  return s;
}

inline Scene scene_of(Primitive p, std::string name = "test") {
  std::vector<Primitive> v;
  v.push_back(std::move(p));
  return scene_of(std::move(v), std::move(name));
}

// The tests' unwrap options: a small atlas target and two threads.
inline unwrap::UnwrapOptions small_options(int size_pages = 4) {
  unwrap::UnwrapOptions o;
  o.size_pages = size_pages;
  o.threads = 2;
  return o;
}

// Every output triangle keeps its source corners' positions; the new UV set is last, finite
// and inside [0, 1]; no flip, no overlap; optionally the gutter between charts is checked
// texel by texel (small atlases only).
inline void expect_valid(const Scene& in, const unwrap::UnwrapResult& r,
                         int padding_to_check = -1) {
  const auto& s = r.stats;
  EXPECT_EQ(s.flipped_triangles, 0);
  EXPECT_EQ(s.overlapping_triangles, 0);
  EXPECT_EQ(s.overlapping_texels, 0);
  EXPECT_EQ(s.unmapped_faces, 0);
  EXPECT_TRUE(std::isfinite(s.stretch_l2));
  EXPECT_GT(s.utilisation, 0.0);
  EXPECT_EQ(s.atlas_width % 120, 0);
  EXPECT_EQ(s.atlas_height % 120, 0);
  auto instances = in.instances();
  int64_t faces = 0;
  for (const auto& mesh : r.scene.meshes)
    for (const auto& p : mesh.primitives) {
      faces += static_cast<int64_t>(p.triangle_count());
      if (p.triangle_count() == 0) continue;  // empty primitives are left as they were
      ASSERT_FALSE(p.uvs.empty());
      const auto& uv = p.uvs.back();
      ASSERT_EQ(uv.size(), p.positions.size());
      for (const auto& t : uv) {
        ASSERT_TRUE(std::isfinite(t[0]) && std::isfinite(t[1]));
        ASSERT_GE(t[0], 0.0f);
        ASSERT_LE(t[0], 1.0f);
        ASSERT_GE(t[1], 0.0f);
        ASSERT_LE(t[1], 1.0f);
      }
    }
  EXPECT_EQ(faces, s.faces);
  EXPECT_EQ(static_cast<int64_t>(r.triangles.size()), s.faces);
  // Every triangle of nonzero 3D area is strictly front-facing in the float atlas UVs
  // (counter-clockwise as an image, y down: negative cross product).
  int64_t not_front = 0;
  for (const auto& t : r.triangles) {
    double cross =
        (static_cast<double>(t.uv[2]) - t.uv[0]) * (static_cast<double>(t.uv[5]) - t.uv[1]) -
        (static_cast<double>(t.uv[3]) - t.uv[1]) * (static_cast<double>(t.uv[4]) - t.uv[0]);
    not_front += !(cross < 0);
  }
  EXPECT_LE(not_front, s.degenerate_faces);
  if (padding_to_check > 0) {
    // Texels any triangle touches (a point-in-texel or edge-crossing test), per chart; then
    // every touched texel must have no other chart within `padding` texels (Chebyshev).
    int w = s.atlas_width, h = s.atlas_height;
    std::vector<int32_t> owner(static_cast<size_t>(w) * h, -1);
    int64_t shared = 0;
    for (const auto& t : r.triangles) {
      double x0 = std::min({t.uv[0], t.uv[2], t.uv[4]}), x1 = std::max({t.uv[0], t.uv[2], t.uv[4]});
      double y0 = std::min({t.uv[1], t.uv[3], t.uv[5]}), y1 = std::max({t.uv[1], t.uv[3], t.uv[5]});
      for (int y = std::max(0, (int)std::floor(y0)); y <= std::min(h - 1, (int)std::floor(y1)); ++y)
        for (int x = std::max(0, (int)std::floor(x0)); x <= std::min(w - 1, (int)std::floor(x1));
             ++x) {
          // Sample the texel densely: 9x9 points including its edges.
          bool touched = false;
          for (int sy = 0; sy <= 8 && !touched; ++sy)
            for (int sx = 0; sx <= 8 && !touched; ++sx) {
              double px = x + sx / 8.0, py = y + sy / 8.0;
              double d[3];
              for (int e = 0; e < 3; ++e) {
                int a = e, b = (e + 1) % 3;
                d[e] = (t.uv[2 * b] - t.uv[2 * a]) * (py - t.uv[2 * a + 1]) -
                       (t.uv[2 * b + 1] - t.uv[2 * a + 1]) * (px - t.uv[2 * a]);
              }
              touched =
                  (d[0] >= 0 && d[1] >= 0 && d[2] >= 0) || (d[0] <= 0 && d[1] <= 0 && d[2] <= 0);
            }
          if (!touched) continue;
          int32_t& o = owner[static_cast<size_t>(y) * w + x];
          if (o >= 0 && o != t.chart) ++shared;
          o = t.chart;
        }
    }
    EXPECT_EQ(shared, 0);
    int64_t too_close = 0;
    const int p = padding_to_check;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        int32_t o = owner[static_cast<size_t>(y) * w + x];
        if (o < 0) continue;
        for (int dy = -p; dy <= p; ++dy)
          for (int dx = -p; dx <= p; ++dx) {
            int xx = x + dx, yy = y + dy;
            if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
            int32_t q = owner[static_cast<size_t>(yy) * w + xx];
            if (q >= 0 && q != o && too_close++ == 0)
              ADD_FAILURE() << "chart " << o << " at (" << x << ", " << y << ") near chart " << q
                            << " at (" << xx << ", " << yy << ")";
          }
      }
    EXPECT_EQ(too_close, 0) << "charts closer than " << p << " texels";
  }
}

}  // namespace vt::test
