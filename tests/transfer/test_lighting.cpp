// Baked lighting (bake/lighting.h) through the transfer, on hand-made scenes whose answer is
// known: a plane under a directional light has E = E_light cos(theta) everywhere; a point light
// falls off as I cos / d^2 (times the range window); an occluder casts a shadow; a spot lights its
// cone only; AO is 1 on an open plane and lower in a corner; the bytes do not depend on threads
// or bands; a scene with no light has no lighting layer and bakes the same bytes whatever the
// lighting options; zero, huge and infinite intensities and range 0 give finite texels.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>
#include <vector>

#include "bake/lighting.h"
#include "bake/scene_bake.h"
#include "bake/transfer.h"
#include "bake/unwrap/unwrap.h"
#include "bake/update_scene.h"
#include "common/half.h"
#include "format/page_file.h"
#include "samples/sample_scene.h"
#include "tests/transfer/transfer_test_util.h"

namespace vt {
namespace {

constexpr uint32_t kAtlas = 64;

// A square at height z in the XY plane, [x0, x1] x [y0, y1], normals +Z (counter-clockwise seen
// from above), split into n x n quads, with its atlas UVs in [u0, u1] x [v0, v1].
scene::Primitive square(double x0, double x1, double y0, double y1, double z, double u0, double u1,
                        double v0, double v1, int n = 4) {
  scene::Primitive p;
  std::vector<scene::Vec2> uv;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double a = double(i) / n, b = double(j) / n;
      p.positions.push_back({float(x0 + (x1 - x0) * a), float(y0 + (y1 - y0) * b), float(z)});
      p.normals.push_back({0, 0, 1});
      uv.push_back({float(u0 + (u1 - u0) * a), float(v1 - (v1 - v0) * b)});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      for (uint32_t k : {a, b, d, a, d, c}) p.indices.push_back(k);
    }
  p.uvs.push_back(uv);
  return p;
}

// The floor: [-1, 1]^2 at z = 0, over most of the atlas.
scene::Primitive floor_square() {
  return square(-1, 1, -1, 1, 0, 0.05, 0.65, 0.05, 0.65);
}

// World position of a texel centre of the floor (inverse of floor_square's UV map).
std::array<double, 2> floor_xy(uint32_t tx, uint32_t ty) {
  const double u = (tx + 0.5) / kAtlas, v = (ty + 0.5) / kAtlas;
  return {(u - 0.05) / 0.6 * 2 - 1, (0.65 - v) / 0.6 * 2 - 1};
}
bool inside_floor(uint32_t tx, uint32_t ty, double margin = 1.5 / kAtlas) {
  const double u = (tx + 0.5) / kAtlas, v = (ty + 0.5) / kAtlas;
  return u > 0.05 + margin && u < 0.65 - margin && v > 0.05 + margin && v < 0.65 - margin;
}

scene::Scene floor_scene() {
  return test::single_mesh_scene(floor_square(), scene::Material{});
}

// Places `light` at a node of its own with this local matrix.
void add_light(scene::Scene& s, const scene::Light& light, const scene::Mat4& local) {
  s.lights.push_back(light);
  scene::Node n;
  n.name = "light";
  n.local = local;
  n.light = int(s.lights.size() - 1);
  s.nodes.push_back(n);
  s.roots.push_back(int(s.nodes.size() - 1));
}
scene::Mat4 at(double x, double y, double z) {
  scene::Mat4 m = scene::kIdentity;
  m[12] = x, m[13] = y, m[14] = z;
  return m;
}
// Turned by `a` radians about +X: -Z goes to (0, sin a, -cos a).
scene::Mat4 turned_about_x(double a) {
  scene::Mat4 m = scene::kIdentity;
  m[5] = std::cos(a), m[6] = std::sin(a), m[9] = -std::sin(a), m[10] = std::cos(a);
  return m;
}

scene::Light light_of(scene::LightType type, float intensity) {
  scene::Light l;
  l.type = type;
  l.intensity = intensity;
  return l;
}

TransferResult transfer(const scene::Scene& s, LightingOptions lighting = {}, int threads = 2,
                        uint32_t band_rows = 0) {
  TransferOptions o;
  o.width = o.height = kAtlas;
  o.threads = threads;
  o.lighting = lighting;
  o.band_rows = band_rows;
  auto r = transfer_materials(s, o);
  EXPECT_TRUE(r.ok()) << r.status().message();
  return r.ok() ? std::move(r).value() : TransferResult{};
}

const TransferLayer* lighting_layer(const TransferResult& r) {
  for (const TransferLayer& l : r.layers)
    if (l.semantic == LayerSemantic::kLighting) return &l;
  return nullptr;
}

// Calls check(x, y, texel) for every floor texel well inside the square.
template <class Check>
void for_floor_texels(const TransferLayer& l, Check&& check) {
  for (uint32_t y = 0; y < kAtlas; ++y)
    for (uint32_t x = 0; x < kAtlas; ++x)
      if (inside_floor(x, y))
        check(floor_xy(x, y), &l.texels[(size_t(y) * kAtlas + x) * l.channels]);
}

TEST(Lighting, DirectionalLightGivesIlluminanceTimesCosine) {
  for (double theta : {0.0, 0.5, 1.2}) {
    scene::Scene s = floor_scene();
    scene::Light sun = light_of(scene::LightType::kDirectional, 1000);
    sun.color = {1, 0.5f, 0.25f};
    add_light(s, sun, turned_about_x(theta));
    TransferResult r = transfer(s);
    const TransferLayer* l = lighting_layer(r);
    ASSERT_NE(l, nullptr);
    EXPECT_EQ(l->channels, 3u);
    EXPECT_TRUE(l->hdr);
    const double e = 1000 * std::cos(theta);
    int n = 0;
    for_floor_texels(*l, [&](std::array<double, 2>, const float* t) {
      ++n;
      ASSERT_NEAR(t[0], e, 1e-5 * 1000);
      ASSERT_NEAR(t[1], 0.5 * e, 1e-5 * 1000);
      ASSERT_NEAR(t[2], 0.25 * e, 1e-5 * 1000);
    });
    EXPECT_GT(n, 1000);
    EXPECT_GT(r.stats.lighting.shadow_rays, 0u);
    EXPECT_EQ(r.stats.lighting.clamped + r.stats.lighting.non_finite, 0u);
  }
}

// A mirroring node reverses the winding of its triangles; the floor still faces the way its
// normals say (glTF: the front face is then clockwise). Mirrored in x it faces up as before;
// mirrored in z (the floor at z = 0 stays put) it faces down.
TEST(Lighting, MirroredInstancesAreLitOnTheSideTheyFace) {
  for (const int axis : {0, 2}) {
    for (const double theta : {0.0, std::numbers::pi}) {
      scene::Scene s = floor_scene();
      s.nodes[0].local[axis * 5] = -1;
      add_light(s, light_of(scene::LightType::kDirectional, 1000), turned_about_x(theta));
      const bool lit = (axis == 0) == (theta == 0.0);
      TransferResult r = transfer(s);
      const TransferLayer* l = lighting_layer(r);
      ASSERT_NE(l, nullptr);
      int n = 0;
      for_floor_texels(*l, [&](std::array<double, 2>, const float* t) {
        ++n;
        ASSERT_NEAR(t[0], lit ? 1000 : 0, 1e-2)
            << "mirrored axis " << axis << ", light at " << theta;
      });
      EXPECT_GT(n, 1000);
    }
  }
}

TEST(Lighting, PointLightFallsOffAsInverseSquareWithinItsRange) {
  const double h = 0.5, intensity = 10;
  for (float range : {std::numeric_limits<float>::infinity(), 1.2f}) {
    scene::Scene s = floor_scene();
    scene::Light bulb = light_of(scene::LightType::kPoint, float(intensity));
    bulb.range = range;
    add_light(s, bulb, at(0, 0, h));
    TransferResult r = transfer(s);
    const TransferLayer* l = lighting_layer(r);
    ASSERT_NE(l, nullptr);
    int lit = 0, dark = 0;
    for_floor_texels(*l, [&](std::array<double, 2> p, const float* t) {
      const double d2 = p[0] * p[0] + p[1] * p[1] + h * h, d = std::sqrt(d2);
      const double window =
          std::isinf(range) ? 1.0 : std::clamp(1.0 - std::pow(d / range, 4.0), 0.0, 1.0);
      const double e = intensity * (h / d) / d2 * window;
      // The texel centre's position is exact; float rounding of the atlas UVs moves it little.
      ASSERT_NEAR(t[0], e, 2e-3 * e + 1e-5) << p[0] << " " << p[1];
      ASSERT_EQ(t[1], t[0]);
      (e > 0 ? lit : dark)++;
    });
    EXPECT_GT(lit, 100);
    if (!std::isinf(range)) {
      EXPECT_GT(dark, 30);  // the corners lie beyond 1.2
    }
  }
}

TEST(Lighting, AnOccluderCastsAShadow) {
  scene::Scene s = floor_scene();
  // A lid over the middle, its own part of the atlas; the sun straight above.
  s.meshes[0].primitives.push_back(square(-0.3, 0.3, -0.3, 0.3, 0.5, 0.72, 0.95, 0.72, 0.95, 1));
  s.meshes[0].primitives.back().material = 0;
  add_light(s, light_of(scene::LightType::kDirectional, 100), scene::kIdentity);
  TransferResult r = transfer(s);
  const TransferLayer* l = lighting_layer(r);
  ASSERT_NE(l, nullptr);
  int shadowed = 0, lit = 0;
  for_floor_texels(*l, [&](std::array<double, 2> p, const float* t) {
    const double m = std::max(std::abs(p[0]), std::abs(p[1]));
    if (m < 0.27) {
      ASSERT_EQ(t[0], 0.0f) << p[0] << " " << p[1];
      ++shadowed;
    } else if (m > 0.33) {
      ASSERT_NEAR(t[0], 100.0f, 1e-3) << p[0] << " " << p[1];
      ++lit;
    }
  });
  EXPECT_GT(shadowed, 100);
  EXPECT_GT(lit, 1000);
  // The lid's top is lit, not shadowed by itself (the ray starts off the surface).
  const uint32_t x = uint32_t(0.83 * kAtlas), y = uint32_t(0.83 * kAtlas);
  EXPECT_NEAR(l->texels[(size_t(y) * kAtlas + x) * 3], 100.0f, 1e-3);
  // Without shadows the floor is lit under the lid too.
  LightingOptions no_shadows;
  no_shadows.shadows = false;
  TransferResult open = transfer(s, no_shadows);
  for_floor_texels(*lighting_layer(open),
                   [&](std::array<double, 2>, const float* t) { ASSERT_NEAR(t[0], 100.0f, 1e-3); });
  EXPECT_EQ(open.stats.lighting.shadow_rays, 0u);
}

// A lid over the floor whose material is alpha-masked with a square hole in the middle (alpha 0
// where the lid's UVs are in [0.78, 0.89]^2, world |x|, |y| < ~0.143): light falls through the
// hole, the rest of the lid shadows. As MASK, as BLEND (cut at 0.5), and the same lid opaque.
TEST(Lighting, AlphaMaskedCasterLetsLightThroughItsHoles) {
  test::ScratchDir dir;
  const std::string png = dir.file("holed.png");
  {
    const int w = 100;
    std::vector<uint8_t> rgba(size_t(w) * w * 4, 255);
    for (int j = 0; j < w; ++j)
      for (int i = 0; i < w; ++i) {
        const double u = (i + 0.5) / w, v = (j + 0.5) / w;
        if (u > 0.78 && u < 0.89 && v > 0.78 && v < 0.89) rgba[(size_t(j) * w + i) * 4 + 3] = 0;
      }
    auto out = OIIO::ImageOutput::create(png);
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(w, w, 4, OIIO::TypeDesc::UINT8);
    ASSERT_TRUE(out->open(png, spec) && out->write_image(OIIO::TypeDesc::UINT8, rgba.data()) &&
                out->close());
  }
  for (scene::AlphaMode mode :
       {scene::AlphaMode::kMask, scene::AlphaMode::kBlend, scene::AlphaMode::kOpaque}) {
    scene::Scene s = floor_scene();
    scene::Material lid;
    lid.alpha_mode = mode;
    lid.alpha_cutoff = 0.5f;
    lid.base_color_texture.image = test::add_image(s, png);
    s.materials.push_back(lid);
    s.meshes[0].primitives.push_back(square(-0.3, 0.3, -0.3, 0.3, 0.5, 0.72, 0.95, 0.72, 0.95, 1));
    s.meshes[0].primitives.back().material = 1;
    add_light(s, light_of(scene::LightType::kDirectional, 100), scene::kIdentity);
    for (int ao : {0, 16}) {
      LightingOptions o;
      o.ao_samples = ao;
      TransferResult r = transfer(s, o);
      const TransferLayer* l = lighting_layer(r);
      ASSERT_NE(l, nullptr);
      int through = 0, shadowed = 0;
      for_floor_texels(*l, [&](std::array<double, 2> p, const float* t) {
        const double m = std::max(std::abs(p[0]), std::abs(p[1]));
        if (m < 0.1) {
          ASSERT_NEAR(t[0], mode == scene::AlphaMode::kOpaque ? 0.0f : 100.0f, 1e-3)
              << int(mode) << " " << p[0] << " " << p[1];
          ++through;
        } else if (m > 0.19 && m < 0.27) {
          ASSERT_EQ(t[0], 0.0f) << int(mode) << " " << p[0] << " " << p[1];
          ++shadowed;
        }
      });
      EXPECT_GE(through, 12);  // 4 x 4 texels
      EXPECT_GT(shadowed, 50);
    }
  }
}

// A wall of no thickness standing on the floor along x = 0 (its own chart, meeting the floor's at
// a seam), a bulb low on its -x side: every floor texel whose centre lies on the +x side is dark,
// right up to the seam (no light under or through the wall), and the -x side is lit.
TEST(Lighting, AThinWallLeaksNoLightAtItsSeam) {
  scene::Scene s = floor_scene();
  scene::Primitive wall = square(-1, 1, 0, 1, 0, 0.72, 0.95, 0.05, 0.65, 2);
  for (auto& p : wall.positions) p = {0.0f, p[0], p[1]};  // the plane x = 0, z from 0 up to 1
  for (auto& n : wall.normals) n = {-1, 0, 0};
  s.meshes[0].primitives.push_back(wall);
  s.meshes[0].primitives.back().material = 0;
  add_light(s, light_of(scene::LightType::kPoint, 10), at(-0.5, 0, 0.3));
  for (int ao : {0, 16}) {
    LightingOptions o;
    o.ao_samples = ao;
    TransferResult r = transfer(s, o);
    const TransferLayer* l = lighting_layer(r);
    ASSERT_NE(l, nullptr);
    int dark = 0, lit = 0, seam = 0;
    for_floor_texels(*l, [&](std::array<double, 2> p, const float* t) {
      if (p[0] > 0.0) {
        ASSERT_EQ(t[0], 0.0f) << p[0] << " " << p[1];
        ++dark;
        seam += p[0] < 0.06;  // within a texel of the wall
      } else if (p[0] < -0.06) {
        ASSERT_GT(t[0], 0.0f) << p[0] << " " << p[1];
        ++lit;
      }
    });
    EXPECT_GT(dark, 300);
    EXPECT_GT(lit, 300);
    EXPECT_GT(seam, 10);
  }
}

// One diffuse bounce: a white wall along y = 0.5 lit by a slanted sun throws light onto the floor
// in front of it, near the wall as its form factor says, more near than far, never more than the
// wall's own irradiance over two (a half-space); the floor in the wall's shadow stays dark (the
// wall's back is unlit, the floor does not light itself); the same bytes on 1 and 2 threads.
TEST(Lighting, OneBounceLightsTheFloorInFrontOfALitWall) {
  scene::Scene s = floor_scene();
  scene::Primitive wall = square(-1, 1, 0, 1, 0, 0.72, 0.95, 0.05, 0.65, 2);
  for (auto& p : wall.positions) p = {p[0], 0.5f, p[1]};
  for (auto& n : wall.normals) n = {0, -1, 0};
  s.meshes[0].primitives.push_back(wall);
  s.meshes[0].primitives.back().material = 0;
  const double a = 0.6;  // the sun comes from -y, up: to the light (0, -sin a, cos a)
  add_light(s, light_of(scene::LightType::kDirectional, 100), turned_about_x(a));
  const double wall_e = 100 * std::sin(a);
  LightingOptions direct_only, bounced;
  bounced.bounces = 1;
  bounced.bounce_samples = 64;
  TransferResult r0 = transfer(s, direct_only), r1 = transfer(s, bounced, 2);
  const TransferLayer *l0 = lighting_layer(r0), *l1 = lighting_layer(r1);
  ASSERT_NE(l0, nullptr);
  ASSERT_NE(l1, nullptr);
  EXPECT_GT(r1.stats.lighting.bounce_rays, 0u);
  EXPECT_EQ(r0.stats.lighting.bounce_rays, 0u);
  // Close to the wall it looks infinite: a floor point at distance d from a wall of height 1
  // sees it with the form factor (1 - d / sqrt(d^2 + 1)) / 2.
  double near_gain = 0, far_gain = 0, near_expected = 0;
  int near = 0, far = 0, shadowed = 0;
  for (uint32_t y = 0; y < kAtlas; ++y)
    for (uint32_t x = 0; x < kAtlas; ++x) {
      if (!inside_floor(x, y)) continue;
      const auto p = floor_xy(x, y);
      const size_t i = (size_t(y) * kAtlas + x) * 3;
      const double gain = l1->texels[i] - l0->texels[i];
      if (p[1] > 0.56) {
        ASSERT_EQ(l0->texels[i], 0.0f) << p[0] << " " << p[1];
        ASSERT_EQ(l1->texels[i], 0.0f) << p[0] << " " << p[1];
        ++shadowed;
      } else if (p[1] < 0.45) {
        ASSERT_GE(gain, 0.0) << p[0] << " " << p[1];
        ASSERT_LT(gain, 0.5 * wall_e) << p[0] << " " << p[1];
      }
      if (std::abs(p[0]) < 0.5 && p[1] > 0.3 && p[1] < 0.45) {
        const double d = 0.5 - p[1];
        near_gain += gain, ++near;
        near_expected += wall_e * 0.5 * (1 - d / std::sqrt(d * d + 1));
      }
      if (std::abs(p[0]) < 0.5 && p[1] < -0.7) far_gain += gain, ++far;
    }
  ASSERT_GT(near, 10);
  ASSERT_GT(far, 10);
  // Measured 23.5 lux against 24.9 for an infinite wall (this one is 2 wide).
  EXPECT_NEAR(near_gain / near, near_expected / near, 0.1 * near_expected / near);
  EXPECT_GT(near_gain / near, 2.0 * far_gain / far);
  EXPECT_GT(shadowed, 50);
  TransferResult one = transfer(s, bounced, 1);
  EXPECT_EQ(lighting_layer(one)->texels, l1->texels);
}

TEST(Lighting, SpotLightsItsConeOnly) {
  scene::Scene s = floor_scene();
  scene::Light spot = light_of(scene::LightType::kSpot, 50);
  spot.inner_cone_angle = 0.2f;
  spot.outer_cone_angle = 0.4f;
  add_light(s, spot, at(0, 0, 1));
  TransferResult r = transfer(s);
  const TransferLayer* l = lighting_layer(r);
  ASSERT_NE(l, nullptr);
  int full = 0, edge = 0, out = 0;
  for_floor_texels(*l, [&](std::array<double, 2> p, const float* t) {
    const double rho = std::hypot(p[0], p[1]), angle = std::atan(rho);
    const double d2 = rho * rho + 1, cosine = 1 / std::sqrt(d2);
    const double e = 50 * cosine / d2;
    if (angle < 0.19) {
      ASSERT_NEAR(t[0], e, 2e-3 * e);
      ++full;
    } else if (angle > 0.41) {
      ASSERT_EQ(t[0], 0.0f);
      ++out;
    } else if (angle > 0.21 && angle < 0.39) {
      ASSERT_GT(t[0], 0.0f);
      ASSERT_LT(t[0], e);
      ++edge;
    }
  });
  EXPECT_GT(full, 20);
  EXPECT_GT(edge, 50);
  EXPECT_GT(out, 500);
}

// The floor with a wall standing along x = 1 (facing -X), both in the atlas.
scene::Scene corner_scene() {
  scene::Scene s = floor_scene();
  scene::Primitive wall = square(-1, 1, 0, 1, 0, 0.7, 0.95, 0.05, 0.65, 2);
  for (scene::Vec3& p : wall.positions) p = {1, p[0], p[1]};  // (x, y, z) -> (1, x, y)
  for (scene::Vec3& n : wall.normals) n = {-1, 0, 0};
  // Turn the winding to face -X: swap two corners of every triangle.
  for (size_t k = 0; k + 2 < wall.indices.size(); k += 3)
    std::swap(wall.indices[k + 1], wall.indices[k + 2]);
  wall.material = 0;
  s.meshes[0].primitives.push_back(wall);
  add_light(s, light_of(scene::LightType::kDirectional, 1), scene::kIdentity);
  return s;
}

TEST(Lighting, AmbientOcclusionIsOpenOnAPlaneAndLowerInACorner) {
  LightingOptions ao;
  ao.ao_samples = 64;
  ao.ao_distance = 2;
  scene::Scene open = floor_scene();
  add_light(open, light_of(scene::LightType::kDirectional, 1), scene::kIdentity);
  TransferResult r = transfer(open, ao);
  const TransferLayer* l = lighting_layer(r);
  ASSERT_NE(l, nullptr);
  ASSERT_EQ(l->channels, 4u);
  for_floor_texels(*l, [&](std::array<double, 2>, const float* t) { ASSERT_EQ(t[3], 1.0f); });
  EXPECT_GT(r.stats.lighting.ao_rays, 0u);

  TransferResult c = transfer(corner_scene(), ao);
  const TransferLayer* lc = lighting_layer(c);
  ASSERT_NE(lc, nullptr);
  double near_sum = 0, far_sum = 0;
  int near_n = 0, far_n = 0;
  for_floor_texels(*lc, [&](std::array<double, 2> p, const float* t) {
    ASSERT_GE(t[3], 0.0f);
    ASSERT_LE(t[3], 1.0f);
    if (p[0] > 0.8 && std::abs(p[1]) < 0.5) near_sum += t[3], ++near_n;
    if (p[0] < -0.5 && std::abs(p[1]) < 0.5) far_sum += t[3], ++far_n;
  });
  ASSERT_GT(near_n, 10);
  ASSERT_GT(far_n, 10);
  // Beside the wall half the hemisphere is a wall: about 0.5 of a cosine lobe is blocked
  // (exactly 0.5 at the foot); far from it most rays are open.
  EXPECT_LT(near_sum / near_n, 0.75);
  EXPECT_GT(far_sum / far_n, 0.9);
}

TEST(Lighting, SameBytesAtAnyThreadCountAndBandHeight) {
  LightingOptions ao;
  ao.ao_samples = 16;
  scene::Scene s = corner_scene();
  add_light(s, light_of(scene::LightType::kPoint, 5), at(0.2, 0.1, 0.6));
  TransferResult a = transfer(s, ao, 1);
  TransferResult b = transfer(s, ao, 2, 16);
  TransferResult c = transfer(s, ao, 3, 32);
  const TransferLayer *la = lighting_layer(a), *lb = lighting_layer(b), *lc = lighting_layer(c);
  ASSERT_TRUE(la && lb && lc);
  ASSERT_EQ(la->texels.size(), lb->texels.size());
  EXPECT_EQ(std::memcmp(la->texels.data(), lb->texels.data(), la->texels.size() * 4), 0);
  EXPECT_EQ(std::memcmp(la->texels.data(), lc->texels.data(), la->texels.size() * 4), 0);
  EXPECT_EQ(a.stats.lighting.ao_rays, b.stats.lighting.ao_rays);
}

TEST(Lighting, ExtremeValuesGiveFiniteTexels) {
  struct Case {
    scene::LightType type;
    float intensity, range;
    scene::Mat4 where;
    bool clamped;
  } cases[] = {
      {scene::LightType::kDirectional, 0, 0, scene::kIdentity, false},
      {scene::LightType::kDirectional, 1e30f, 0, scene::kIdentity, true},
      {scene::LightType::kPoint, std::numeric_limits<float>::infinity(), 1e30f, at(0, 0, 1), true},
      {scene::LightType::kPoint, 100, 0, at(0, 0, 0.5), false},  // range 0: reaches nothing
      {scene::LightType::kPoint, 100, 1e30f, at(0.01f, 0.02f, 0), false},  // inside the floor
      {scene::LightType::kSpot, 1e38f, 1e-30f, at(0, 0, 1), false},
  };
  for (const Case& c : cases) {
    scene::Scene s = floor_scene();
    scene::Light l = light_of(c.type, c.intensity);
    if (c.range > 0)
      l.range = c.range;
    else if (c.type != scene::LightType::kDirectional)
      l.range = 0;
    add_light(s, l, c.where);
    TransferResult r = transfer(s);
    const TransferLayer* layer = lighting_layer(r);
    ASSERT_NE(layer, nullptr);
    for (float v : layer->texels) {
      ASSERT_TRUE(std::isfinite(v));
      ASSERT_GE(v, 0.0f);
      ASSERT_LE(v, kMaxIrradiance);
    }
    EXPECT_EQ(r.stats.lighting.clamped + r.stats.lighting.non_finite > 0, c.clamped)
        << int(c.type) << " " << c.intensity;
  }
}

// The shadow terminator and acne on a low-poly sphere (12 segments, smooth normals, degenerate
// pole triangles), at tiny, unit and huge scales: rays start half a texel footprint off the
// surface, so shadow rays change nothing where the triangles face the light, and every texel is
// finite whatever the scale.
TEST(Lighting, LowPolySphereHasNoAcneAtAnyScale) {
  for (double scale : {1e-3, 1.0, 1e4}) {
    SCOPED_TRACE(scale);
    scene::Scene s = test::single_mesh_scene(make_uv_sphere(1, 12), scene::Material{});
    for (int i = 0; i < 3; ++i) s.nodes[0].local[5 * i] = scale;
    add_light(s, light_of(scene::LightType::kDirectional, 10), turned_about_x(0.6));
    unwrap::UnwrapOptions uo;
    uo.size_pages = 1;
    uo.padding = 4;  // charts big enough for 500 facing texels in one page
    auto un = unwrap::unwrap_scene(s, uo);
    ASSERT_TRUE(un.ok()) << un.status().message();
    TransferOptions o = test::atlas_transfer_options(un->stats);
    o.threads = 2;
    auto lit = transfer_materials(un->scene, o);
    o.lighting.shadows = false;
    auto open = transfer_materials(un->scene, o);
    ASSERT_TRUE(lit.ok() && open.ok());
    const TransferLayer *a = lighting_layer(*lit), *b = lighting_layer(*open);
    ASSERT_TRUE(a && b);
    int facing = 0, terminator = 0;
    for (size_t i = 0; i < a->texels.size(); i += 3) {
      ASSERT_TRUE(std::isfinite(a->texels[i]));
      // Shading cosine above 0.8: within 37 degrees of the light, where 30-degree facets
      // face it too (no triangle of a convex sphere can shadow them).
      if (b->texels[i] > 8.0f) {
        ASSERT_EQ(a->texels[i], b->texels[i]) << "texel " << i / 3;
        ++facing;
      } else if (a->texels[i] != b->texels[i]) {
        ++terminator;
      }
    }
    EXPECT_GT(facing, 500);
    // Shadowed texels lie where the smooth normal still sees the light but the facet does not.
    EXPECT_LT(terminator, facing);
  }
}

TEST(Lighting, OnlyDisplayedLightsCallForTheLayer) {
  scene::Scene s = floor_scene();
  EXPECT_EQ(layers_used(s), std::vector<LayerSemantic>{LayerSemantic::kAlbedo});
  s.lights.push_back(light_of(scene::LightType::kPoint, 1));  // no node places it
  EXPECT_FALSE(scene_has_lights(s));
  EXPECT_EQ(lighting_layer(transfer(s)), nullptr);
  add_light(s, light_of(scene::LightType::kPoint, 1), at(0, 0, 1));
  EXPECT_EQ(layers_used(s),
            (std::vector<LayerSemantic>{LayerSemantic::kAlbedo, LayerSemantic::kLighting}));
}

std::vector<uint8_t> file_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), {}};
}

// `s` baked into a one-page file at `path`.
SceneBakeSummary bake_one_page(const scene::Scene& s, const std::string& path,
                               const LightingOptions& lighting) {
  SceneBakeOptions o;
  o.build.output = path;
  o.build.threads = 2;
  o.unwrapped = "-";
  o.unwrap.size_pages = 1;
  o.lighting = lighting;
  auto summary = bake_scene(s, o);
  EXPECT_TRUE(summary.ok()) << summary.status().message();
  return summary.ok() ? *summary : SceneBakeSummary{};
}

// A light-less scene bakes the same page file whatever the lighting options (no layer, no
// structure, nothing in the metadata); a lit one gets a half-float lighting layer.
TEST(Lighting, SceneBakeAddsTheLayerOnlyForLitScenes) {
  test::ScratchDir dir;
  auto bake = [&](const scene::Scene& s, const std::string& name, LightingOptions lighting) {
    return bake_one_page(s, dir.file(name), lighting);
  };
  LightingOptions ao;
  ao.ao_samples = 8;
  ao.shadows = false;
  scene::Scene dark = floor_scene();
  SceneBakeSummary a = bake(dark, "a.vtpf", {});
  SceneBakeSummary b = bake(dark, "b.vtpf", ao);
  EXPECT_EQ(b.transfer.lighting.samples, 0u);
  EXPECT_EQ(file_bytes(dir.file("a.vtpf")), file_bytes(dir.file("b.vtpf")));
  auto ra = PageFileReader::open(dir.file("a.vtpf"));
  ASSERT_TRUE(ra.ok());
  for (const LayerSpec& l : (*ra)->layers()) EXPECT_NE(l.semantic, LayerSemantic::kLighting);
  EXPECT_EQ((*ra)->metadata_json().find("lighting"), std::string::npos);

  scene::Scene lit = floor_scene();
  add_light(lit, light_of(scene::LightType::kDirectional, 3), scene::kIdentity);
  SceneBakeSummary c = bake(lit, "c.vtpf", {});
  EXPECT_GT(c.transfer.lighting.samples, 0u);
  auto rc = PageFileReader::open(dir.file("c.vtpf"));
  ASSERT_TRUE(rc.ok()) << rc.status().message();
  int found = -1;
  for (uint32_t i = 0; i < (*rc)->layers().size(); ++i)
    if ((*rc)->layers()[i].semantic == LayerSemantic::kLighting) found = int(i);
  ASSERT_GE(found, 0);
  const LayerSpec& spec = (*rc)->layers()[found];
  EXPECT_EQ(spec.name, "lighting");
  EXPECT_EQ(spec.texel_type, TexelType::kF16);
  EXPECT_EQ(spec.channels, 3);
  EXPECT_EQ(spec.runtime_format, RuntimeFormat::kBc6hUf16);
  EXPECT_NE((*rc)->metadata_json().find("\"lighting\""), std::string::npos);
  // Every stored texel of level 0 is the sun's 3 lux (half float holds 3 exactly; dilated
  // background takes its neighbours' value).
  test::Level0 level = test::read_level0(**rc, uint32_t(found));
  int checked = 0;
  for (size_t i = 0; i < level.present.size(); ++i) {
    if (!level.present[i]) continue;
    ASSERT_EQ(level.texels[3 * i], 3.0f);
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

// A floor whose base colour varies per texel (factor x a gradient texture x vertex colours),
// lit by a sun (colour and slant) and a bulb (shading varies over the floor), with a half-
// transparent or opaque material.
scene::Scene lit_colour_floor(const test::ScratchDir& dir, scene::AlphaMode mode) {
  const std::string png = dir.file("gradient.png");
  const int w = 16;
  std::vector<uint8_t> rgba(size_t(w) * w * 4, 255);
  for (int j = 0; j < w; ++j)
    for (int i = 0; i < w; ++i) {
      uint8_t* t = &rgba[(size_t(j) * w + i) * 4];
      t[0] = uint8_t(40 + 13 * i), t[1] = uint8_t(250 - 11 * j), t[2] = uint8_t(90 + 7 * (i ^ j));
      t[3] = uint8_t(100 + 9 * i);
    }
  auto out = OIIO::ImageOutput::create(png);
  OIIO::ImageSpec spec(w, w, 4, OIIO::TypeDesc::UINT8);
  EXPECT_TRUE(out && out->open(png, spec) && out->write_image(OIIO::TypeDesc::UINT8, rgba.data()) &&
              out->close());
  scene::Primitive p = floor_square();
  p.uvs.insert(p.uvs.begin(), p.uvs[0]);  // set 0 reads the texture, the last is the atlas
  for (const scene::Vec3& v : p.positions)
    p.colors.push_back({0.5f + 0.25f * v[0], 0.75f, 0.5f - 0.25f * v[1], 1.0f});
  scene::Material m;
  m.base_color_factor = {0.9f, 0.6f, 0.8f, 1.0f};
  m.alpha_mode = mode;
  scene::Scene s = test::textured_scene(p, png, m);
  scene::Light sun = light_of(scene::LightType::kDirectional, 900);
  sun.color = {1, 0.8f, 0.6f};
  add_light(s, sun, turned_about_x(0.4));
  add_light(s, light_of(scene::LightType::kPoint, 40), at(0.3, -0.2, 0.6));
  return s;
}

const TransferLayer* layer_of(const TransferResult& r, LayerSemantic semantic) {
  for (const TransferLayer& l : r.layers)
    if (l.semantic == semantic) return &l;
  return nullptr;
}

// --lighting combined: a lit-albedo layer in the lighting layer's place, each texel the separate
// bake's albedo x irradiance / pi (one sample per texel: the product of the two layers' texels,
// to float rounding), alpha kept as albedo keeps it.
TEST(Lighting, CombinedLayerIsAlbedoTimesIrradianceOverPi) {
  test::ScratchDir dir;
  for (scene::AlphaMode mode : {scene::AlphaMode::kOpaque, scene::AlphaMode::kBlend}) {
    const scene::Scene s = lit_colour_floor(dir, mode);
    LightingOptions combined;
    combined.layer = LightingLayer::kCombined;
    EXPECT_EQ(layers_used(s, combined.layer),
              (std::vector<LayerSemantic>{LayerSemantic::kAlbedo, LayerSemantic::kLitAlbedo}));
    const TransferResult sep = transfer(s), com = transfer(s, combined);
    const TransferLayer* albedo = layer_of(sep, LayerSemantic::kAlbedo);
    const TransferLayer* light = layer_of(sep, LayerSemantic::kLighting);
    const TransferLayer* lit = layer_of(com, LayerSemantic::kLitAlbedo);
    ASSERT_TRUE(albedo && light && lit);
    EXPECT_EQ(layer_of(com, LayerSemantic::kLighting), nullptr);
    EXPECT_TRUE(lit->hdr);
    const uint32_t alpha = mode == scene::AlphaMode::kOpaque ? 3u : 4u;
    ASSERT_EQ(albedo->channels, alpha);
    ASSERT_EQ(lit->channels, alpha);
    // The albedo layer is the same in both bakes.
    EXPECT_EQ(albedo->texels, layer_of(com, LayerSemantic::kAlbedo)->texels);
    int n = 0;
    double lo = 1e9, hi = 0;
    const std::vector<uint8_t> coverage = *sep.coverage->to_bytes();
    for (size_t i = 0; i < size_t(kAtlas) * kAtlas; ++i) {
      if (!coverage[i]) continue;
      for (int c = 0; c < 3; ++c) {
        const double want =
            double(albedo->texels[i * alpha + c]) * light->texels[i * 3 + c] / std::numbers::pi;
        ASSERT_NEAR(lit->texels[i * alpha + c], want, 1e-6 * want + 1e-9) << i << " " << c;
        lo = std::min(lo, want), hi = std::max(hi, want);
      }
      if (alpha == 4) ASSERT_EQ(lit->texels[i * 4 + 3], albedo->texels[i * 4 + 3]);
      ++n;
    }
    EXPECT_GT(n, 1000);
    EXPECT_GT(hi, 2 * lo);  // the product varies: a constant would not test it
  }
}

// AO is no light: a combined bake refuses it rather than dropping it unseen.
TEST(Lighting, CombinedLayerRefusesAmbientOcclusion) {
  scene::Scene s = floor_scene();
  add_light(s, light_of(scene::LightType::kDirectional, 3), scene::kIdentity);
  LightingOptions o;
  o.layer = LightingLayer::kCombined;
  o.ao_samples = 4;
  TransferOptions t;
  t.width = t.height = kAtlas;
  t.lighting = o;
  auto r = transfer_materials(s, t);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("separate"), std::string::npos) << r.status().message();
}

// The scene bake of a combined layer: 'lit_albedo', half float, level 0 the product to half
// rounding, the mode in the metadata; a light-less scene bakes the same bytes in either mode.
TEST(Lighting, SceneBakeOfTheCombinedLayer) {
  test::ScratchDir dir;
  auto bake = [&](const scene::Scene& s, const std::string& name, LightingOptions lighting) {
    return bake_one_page(s, dir.file(name), lighting);
  };
  LightingOptions combined;
  combined.layer = LightingLayer::kCombined;
  const scene::Scene dark = floor_scene();
  bake(dark, "a.vtpf", {});
  const SceneBakeSummary b = bake(dark, "b.vtpf", combined);
  EXPECT_EQ(file_bytes(dir.file("a.vtpf")), file_bytes(dir.file("b.vtpf")));
  bool warned = false;
  for (const std::string& w : b.warnings)
    warned |= w.find("nothing to combine") != std::string::npos;
  EXPECT_TRUE(warned);

  // A grey floor under a 3-lux sun: every texel 0.5 x 3 / pi.
  scene::Scene lit = floor_scene();
  lit.materials[0].base_color_factor = {0.5f, 0.5f, 0.5f, 1.0f};
  add_light(lit, light_of(scene::LightType::kDirectional, 3), scene::kIdentity);
  bake(lit, "c.vtpf", combined);
  auto rc = PageFileReader::open(dir.file("c.vtpf"));
  ASSERT_TRUE(rc.ok()) << rc.status().message();
  int found = -1;
  for (uint32_t i = 0; i < (*rc)->layers().size(); ++i) {
    EXPECT_NE((*rc)->layers()[i].semantic, LayerSemantic::kLighting);
    if ((*rc)->layers()[i].semantic == LayerSemantic::kLitAlbedo) found = int(i);
  }
  ASSERT_GE(found, 0);
  const LayerSpec& spec = (*rc)->layers()[found];
  EXPECT_EQ(spec.name, "lit_albedo");
  EXPECT_EQ(spec.texel_type, TexelType::kF16);
  EXPECT_EQ(spec.channels, 3);
  EXPECT_EQ(spec.color_space, ColorSpace::kLinear);
  EXPECT_NE((*rc)->metadata_json().find("\"layer\":\"combined\""), std::string::npos);
  const float want = half_to_float(float_to_half(float(0.5 * 3 / std::numbers::pi)));
  test::Level0 level = test::read_level0(**rc, uint32_t(found));
  int checked = 0;
  for (size_t i = 0; i < level.present.size(); ++i) {
    if (!level.present[i]) continue;
    ASSERT_EQ(level.texels[3 * i], want) << i;
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

// The content key (update mode) tells the layer modes and bounces apart on a lit scene, so an
// update never keeps a bake of the other mode; a light-less scene's key ignores them.
TEST(Lighting, ContentKeyKnowsTheLayerModeAndBounces) {
  auto key = [](const scene::Scene& s, LightingOptions lighting) {
    SceneBakeOptions o;
    o.lighting = lighting;
    auto k = scene_bake_key(s, o);
    EXPECT_TRUE(k.ok()) << k.status().message();
    return k.ok() ? *k : 0;
  };
  LightingOptions combined, bounced;
  combined.layer = LightingLayer::kCombined;
  bounced.bounces = 1;
  const scene::Scene dark = floor_scene();
  EXPECT_EQ(key(dark, {}), key(dark, combined));
  EXPECT_EQ(key(dark, {}), key(dark, bounced));
  scene::Scene lit = floor_scene();
  add_light(lit, light_of(scene::LightType::kDirectional, 3), scene::kIdentity);
  EXPECT_NE(key(lit, {}), key(lit, combined));
  EXPECT_NE(key(lit, {}), key(lit, bounced));
}

}  // namespace
}  // namespace vt
