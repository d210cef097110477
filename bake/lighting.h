// Baked lighting: direct irradiance from a scene's KHR_lights_punctual lights, with shadows cast
// by ray against every triangle of the scene (Embree 3), and ambient occlusion on request. The
// transfer (bake/transfer.h) calls it at each texel sample of the lighting layer, which exists
// only when the scene places a light: no light, no ray-tracing structure, no time spent.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "common/status.h"
#include "common/vec.h"
#include "scene/scene.h"

namespace vt {

// What the baked light becomes (`--lighting`). kSeparate: irradiance in its own lighting layer.
// kCombined: a lit-albedo layer instead (LayerSemantic::kLitAlbedo), base colour x irradiance /
// pi per texel sample, for engines that want one texture (docs/ARCHITECTURE.md, "Baked
// lighting": why / pi, and why no AO).
enum class LightingLayer { kSeparate, kCombined };
Expected<LightingLayer> parse_lighting_layer(const std::string& name);  // "separate", "combined"
const char* to_string(LightingLayer v);

struct LightingOptions {
  LightingLayer layer = LightingLayer::kSeparate;

  bool shadows = true;  // false: every light reaches every texel that faces it
  // Ambient occlusion: cosine-weighted rays per texel sample over the shading normal's
  // hemisphere (0 = none). The lighting layer then has a 4th channel: the fraction of them that
  // reach `ao_distance` world units unblocked (1 = open sky).
  int ao_samples = 0;
  double ao_distance = 0;  // 0 = the scene's bounding-box diagonal
  // One diffuse bounce (0 = direct light only, 1): `bounce_samples` cosine-weighted rays per
  // texel sample over the shading normal; each surface one meets adds its base colour (linear:
  // factor x texture, sRGB decoded, x vertex colour) times its own direct irradiance, so the
  // sample gains the mean of albedo x E over the rays (a Lambertian bounce: E = pi x mean L).
  int bounces = 0;
  int bounce_samples = 16;
};

// The options' ranges, and no AO with the combined layer (LightingBaker::create checks them; a
// scene bake before any work).
Status check_lighting_options(const LightingOptions& options);

// The largest value the layer keeps: half float's largest finite value. Larger (or non-finite)
// results are clamped and counted (LightingStats).
constexpr float kMaxIrradiance = 65504.0f;

// The combined layer's value (LightingLayer::kCombined): the exitant radiance of a Lambertian
// surface of linear base colour `base` under irradiance `e` (lux), base x e / pi, clamped as
// irradiance is.
inline float lit_albedo(double base, double e) {
  const double v = base * e * std::numbers::inv_pi;
  return v > 0 ? float(std::min(v, double(kMaxIrradiance))) : 0.0f;
}

struct LightingStats {
  uint64_t samples = 0;      // texel samples lit
  uint64_t shadow_rays = 0;  // rays cast to lights
  uint64_t ao_rays = 0;      // ambient occlusion rays
  uint64_t bounce_rays = 0;  // rays looking for a surface to bounce from (their shadow rays
                             // are counted in shadow_rays)
  uint64_t clamped = 0;      // samples above kMaxIrradiance, clamped to it
  uint64_t non_finite = 0;   // samples whose sum was NaN or infinite (stored as 0 or the max)
  uint64_t bvh_bytes = 0;    // memory Embree allocated for the scene's structure (peak)
  double build_seconds = 0;  // building that structure
};

// One point of a surface to light, in world space.
struct LightingSample {
  Vec3d position;
  Vec3d geometric_normal;  // unit, the triangle's (either winding: turned to the shading side)
  Vec3d shading_normal;    // unit: interpolated vertex normal, normal map applied
  double footprint = 0;    // world size of a texel here: rays start this far off the surface
  uint64_t seed = 0;       // per texel and sub-sample: the same numbers at any thread count
};

class LightingBaker {
 public:
  // The scene's placed lights and, when shadows or AO need it, a ray-tracing structure over
  // every instance's triangles in world space. `threads` bounds Embree's build (0 = all cores).
  // Alpha cuts holes in what casts: a MASK material blocks a ray only where its base colour's
  // alpha (texture at the hit's UV, level 0, x factor x vertex alpha) reaches alphaCutoff; a
  // BLEND material likewise at 0.5 (a hard cut: no partial transmission, so a half-transparent
  // pane casts either a full shadow or none). A texture that cannot be read leaves the factor.
  static Expected<std::unique_ptr<LightingBaker>> create(const scene::Scene& scene,
                                                         const LightingOptions& options,
                                                         int threads);
  ~LightingBaker();

  // Channels the lighting layer has: RGB irradiance, + AO when asked.
  uint32_t channels() const { return options_.ao_samples > 0 ? 4 : 3; }
  // Irradiance (lux: lm/m^2, the lights' own unit) at the sample from every light, in [0,
  // kMaxIrradiance], then AO in [0, 1] when asked. Thread-safe.
  void evaluate(const LightingSample& sample, float* out) const;
  LightingStats stats() const;

  struct Rays;  // the Embree device and scene (lighting.cpp)

 private:
  LightingBaker() = default;
  bool occluded(const Vec3d& origin, const Vec3d& dir, double tfar) const;
  // Direct irradiance at a point (shadowed when options_.shadows), added to `sum`.
  void direct(const Vec3d& position, const Vec3d& ng, const Vec3d& ns, double offset, double sum[3],
              uint64_t& shadow_rays) const;
  // The bounce's irradiance at a sample (see LightingOptions::bounces), added to `sum`.
  void bounce(const Vec3d& origin, const Vec3d& ng, const Vec3d& ns, uint64_t seed, double sum[3],
              uint64_t& shadow_rays, uint64_t& bounce_rays) const;

  LightingOptions options_;
  struct Placed {
    scene::LightType type;
    Vec3d position, direction;  // direction: where the light travels
    Vec3d radiant;              // colour x intensity
    double range, cos_outer, angle_scale;
  };
  std::vector<Placed> lights_;
  double ao_distance_ = 0;
  std::unique_ptr<Rays> rays_;  // null when nothing needs rays
  mutable std::atomic<uint64_t> samples_{0}, shadow_rays_{0}, ao_rays_{0}, bounce_rays_{0},
      clamped_{0}, non_finite_{0};
  LightingStats build_stats_;
};

// The first surface along a ray through world-space triangle meshes (Embree 3, robust). The
// screen-space check of the lighting layer (render/lighting_check.h) finds each pixel's surface of
// the original scene with it, as a G-buffer pass would.
class SurfaceCaster {
 public:
  struct Mesh {
    std::span<const float> positions;   // x, y, z per vertex, world space
    std::span<const uint32_t> indices;  // triangle list; an index out of range: no triangle
  };
  struct Hit {
    uint32_t mesh = 0, triangle = 0;
    double u = 0, v = 0;  // barycentric weights of the triangle's 2nd and 3rd vertex
    double t = 0;         // distance along the (unit) direction
  };
  // `threads` bounds Embree's build (0 = all cores).
  static Expected<std::unique_ptr<SurfaceCaster>> create(std::span<const Mesh> meshes, int threads);
  ~SurfaceCaster();
  // The nearest hit in (0, tfar] along unit `dir`, either side of a triangle. Thread-safe.
  std::optional<Hit> first_hit(const Vec3d& origin, const Vec3d& dir, double tfar) const;

 private:
  SurfaceCaster() = default;
  std::unique_ptr<LightingBaker::Rays> rays_;
};

// Whether `scene` calls for a lighting layer: some displayed node places a light.
bool scene_has_lights(const scene::Scene& scene);

}  // namespace vt
