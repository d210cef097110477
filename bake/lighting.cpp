// Baked lighting (see lighting.h). Light falloff follows KHR_lights_punctual's recommended model:
// point and spot lights fall off as window(d / range) / d^2 with window(x) = clamp(1 - x^4, 0, 1);
// spot lights scale by the square of clamp((cos(angle to axis) - cos outer) / (cos inner - cos
// outer), 0, 1). Rays start off the surface by half a texel footprint along the geometric
// normal (never a fixed epsilon: the texel is the scale at which the bake can see anything).
#include "bake/lighting.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

namespace vt {

struct LightingBaker::Rays {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::atomic<int64_t> bytes{0}, peak{0};
  ~Rays() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

constexpr double kPi = 3.14159265358979323846;

Vec3d v3(const std::array<double, 3>& a) {
  return {a[0], a[1], a[2]};
}

uint64_t mix64(uint64_t z) {  // splitmix64's finaliser
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
double unit_double(uint64_t bits) {
  return double(bits >> 11) * (1.0 / 9007199254740992.0);
}

// Embree's allocations, for the figure of the structure's memory.
bool monitor(void* user, ssize_t bytes, bool /*post*/) {
  auto* rays = static_cast<LightingBaker::Rays*>(user);
  const int64_t now = rays->bytes.fetch_add(bytes) + bytes;
  int64_t peak = rays->peak.load();
  while (now > peak && !rays->peak.compare_exchange_weak(peak, now)) {
  }
  return true;
}

std::string device_error(RTCDevice device, const char* what) {
  return std::string("lighting: Embree ") + what + " failed (error " +
         std::to_string(int(rtcGetDeviceError(device))) + ")";
}

}  // namespace

bool scene_has_lights(const scene::Scene& scene) {
  return !scene.placed_lights().empty();
}

LightingBaker::~LightingBaker() = default;

Expected<std::unique_ptr<LightingBaker>> LightingBaker::create(const scene::Scene& scene,
                                                               const LightingOptions& options,
                                                               int threads) {
  if (options.ao_samples < 0 || options.ao_samples > 65536)
    return Error(ErrorCode::kInvalidArgument, "lighting: AO samples must be 0..65536");
  if (!(options.ao_distance >= 0) || !std::isfinite(options.ao_distance))
    return Error(ErrorCode::kInvalidArgument, "lighting: AO distance must be a finite number >= 0");
  std::unique_ptr<LightingBaker> b(new LightingBaker());
  b->options_ = options;
  for (const scene::PlacedLight& p : scene.placed_lights()) {
    const scene::Light& l = scene.lights[p.light];
    Placed q;
    q.type = l.type;
    q.position = v3(p.position);
    q.direction = normalized(v3(p.direction), Vec3d{0, 0, -1});
    q.radiant = Vec3d{l.color[0], l.color[1], l.color[2]} * double(l.intensity);
    q.range = l.range;
    const double cos_inner = std::cos(double(l.inner_cone_angle));
    q.cos_outer = std::cos(double(l.outer_cone_angle));
    q.angle_scale = 1.0 / std::max(0.001, cos_inner - q.cos_outer);  // the extension's guard
    b->lights_.push_back(q);
  }
  if (!options.shadows && options.ao_samples == 0) return b;

  auto start = std::chrono::steady_clock::now();
  b->rays_ = std::make_unique<Rays>();
  Rays& rays = *b->rays_;
  const std::string config = threads > 0 ? "threads=" + std::to_string(threads) : std::string();
  rays.device = rtcNewDevice(config.c_str());
  if (!rays.device) return Error(ErrorCode::kInternal, "lighting: Embree device creation failed");
  rtcSetDeviceMemoryMonitorFunction(rays.device, monitor, &rays);
  rays.scene = rtcNewScene(rays.device);
  // Robust: rays through shared edges and vertices are not missed (no light through seams).
  rtcSetSceneFlags(rays.scene, RTC_SCENE_FLAG_ROBUST);
  Vec3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const scene::Instance& inst : scene.instances()) {
    for (const scene::Primitive& p : scene.meshes[inst.mesh].primitives) {
      if (p.indices.size() < 3 || p.positions.empty()) continue;
      RTCGeometry g = rtcNewGeometry(rays.device, RTC_GEOMETRY_TYPE_TRIANGLE);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), p.positions.size()));
      auto* idx = static_cast<uint32_t*>(
          rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                  3 * sizeof(uint32_t), p.indices.size() / 3));
      if (!v || !idx) {
        rtcReleaseGeometry(g);
        return Error(ErrorCode::kResourceLimit, device_error(rays.device, "geometry buffer"));
      }
      for (size_t k = 0; k < p.positions.size(); ++k) {
        const auto w = scene::transform_point(inst.world, p.positions[k]);
        for (int c = 0; c < 3; ++c) v[3 * k + c] = float(w[c]);
        lo = {std::min(lo.x, w[0]), std::min(lo.y, w[1]), std::min(lo.z, w[2])};
        hi = {std::max(hi.x, w[0]), std::max(hi.y, w[1]), std::max(hi.z, w[2])};
      }
      const uint32_t n = uint32_t(p.positions.size());
      for (size_t k = 0; k + 2 < p.indices.size(); k += 3) {
        // An index out of range (the transfer refuses it) becomes a degenerate triangle.
        const bool ok = p.indices[k] < n && p.indices[k + 1] < n && p.indices[k + 2] < n;
        for (int c = 0; c < 3; ++c) idx[k + c] = ok ? p.indices[k + c] : 0;
      }
      rtcCommitGeometry(g);
      rtcAttachGeometry(rays.scene, g);
      rtcReleaseGeometry(g);
    }
  }
  rtcCommitScene(rays.scene);
  if (rtcGetDeviceError(rays.device) != RTC_ERROR_NONE)
    return Error(ErrorCode::kInternal, device_error(rays.device, "scene build"));
  const double diagonal = hi.x >= lo.x ? length(hi - lo) : 1.0;
  b->ao_distance_ = options.ao_distance > 0 ? options.ao_distance : diagonal;
  b->build_stats_.bvh_bytes = uint64_t(std::max<int64_t>(0, rays.peak.load()));
  b->build_stats_.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return b;
}

bool LightingBaker::occluded(const Vec3d& origin, const Vec3d& dir, double tfar) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray;
  ray.org_x = float(origin.x), ray.org_y = float(origin.y), ray.org_z = float(origin.z);
  ray.dir_x = float(dir.x), ray.dir_y = float(dir.y), ray.dir_z = float(dir.z);
  ray.tnear = 0.0f;
  ray.tfar = float(tfar);
  ray.time = 0.0f;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
  rtcOccluded1(rays_->scene, &context, &ray);
  return ray.tfar < 0;  // Embree sets -inf on a hit
}

void LightingBaker::evaluate(const LightingSample& s, float* out) const {
  const Vec3d ns = s.shading_normal;
  Vec3d ng = s.geometric_normal;
  if (dot(ng, ns) < 0) ng = ng * -1.0;
  // Half a texel off the surface, and never inside float's rounding of the position (the
  // structure holds floats): huge and tiny scene scales alike.
  const double scale =
      std::max({std::abs(s.position.x), std::abs(s.position.y), std::abs(s.position.z), 1e-30});
  const double offset =
      std::max(0.5 * (std::isfinite(s.footprint) ? s.footprint : 0.0), scale * 4e-7);
  const Vec3d origin = s.position + ng * offset;
  uint64_t shadow_rays = 0, ao_rays = 0;
  double sum[3] = {0, 0, 0};
  for (const Placed& l : lights_) {
    Vec3d to_light, ray_dir;  // from the surface point (shading), from the ray origin
    double tfar = std::numeric_limits<double>::infinity(), falloff = 1.0;
    if (l.type == scene::LightType::kDirectional) {
      to_light = ray_dir = l.direction * -1.0;
    } else {
      const Vec3d d = l.position - s.position;
      const double dist = length(d);
      if (!(dist > 0) || !std::isfinite(dist)) continue;  // a light on the surface: no direction
      to_light = d / dist;
      double window = 0;
      if (std::isinf(l.range))
        window = 1;
      else if (l.range > 0)
        window = std::clamp(1.0 - std::pow(dist / l.range, 4.0), 0.0, 1.0);
      falloff = window / (dist * dist);
      if (l.type == scene::LightType::kSpot) {
        const double a =
            std::clamp((dot(l.direction, to_light * -1.0) - l.cos_outer) * l.angle_scale, 0.0, 1.0);
        falloff *= a * a;
      }
      const Vec3d from_origin = l.position - origin;
      tfar = length(from_origin) * (1.0 - 1e-6);
      ray_dir = normalized(from_origin, to_light);
    }
    const double cosine = dot(ns, to_light);
    if (!(cosine > 0) || !(falloff > 0)) continue;
    const Vec3d e = l.radiant * (cosine * falloff);
    if (!(e.x > 0 || e.y > 0 || e.z > 0)) continue;
    if (rays_ && options_.shadows) {
      ++shadow_rays;
      if (occluded(origin, ray_dir, tfar)) continue;
    }
    sum[0] += e.x, sum[1] += e.y, sum[2] += e.z;
  }
  bool clamped = false, non_finite = false;
  for (int c = 0; c < 3; ++c) {
    double v = sum[c];
    if (!std::isfinite(v)) {
      non_finite = true;
      v = std::isnan(v) ? 0.0 : double(kMaxIrradiance);
    }
    if (v > kMaxIrradiance) clamped = true, v = kMaxIrradiance;
    out[c] = float(v);
  }
  if (options_.ao_samples > 0) {
    // A rank-1 lattice (R2 sequence) rotated per texel sample: stratified, and seeded by the
    // texel so that the bytes never depend on which thread takes the texel.
    const uint64_t h = mix64(s.seed ^ 0x9e3779b97f4a7c15ull);
    const double r0 = unit_double(h), r1 = unit_double(mix64(h));
    const Vec3d t = normalized(cross(std::abs(ns.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0}, ns),
                               Vec3d{1, 0, 0});
    const Vec3d b = cross(ns, t);
    const int n = options_.ao_samples;
    int open = 0;
    for (int i = 0; i < n; ++i) {
      double u1 = r0 + 0.7548776662466927 * i, u2 = r1 + 0.5698402909980532 * i;
      u1 -= std::floor(u1), u2 -= std::floor(u2);
      const double r = std::sqrt(u1), phi = 2.0 * kPi * u2;
      const Vec3d dir = t * (r * std::cos(phi)) + b * (r * std::sin(phi)) +
                        ns * std::sqrt(std::max(0.0, 1.0 - u1));
      if (!(dot(dir, ng) > 0)) continue;  // below the surface itself (normal-mapped normals)
      ++ao_rays;
      open += !occluded(origin, dir, ao_distance_);
    }
    out[3] = float(double(open) / double(n));
  }
  samples_.fetch_add(1, std::memory_order_relaxed);
  if (shadow_rays) shadow_rays_.fetch_add(shadow_rays, std::memory_order_relaxed);
  if (ao_rays) ao_rays_.fetch_add(ao_rays, std::memory_order_relaxed);
  if (clamped) clamped_.fetch_add(1, std::memory_order_relaxed);
  if (non_finite) non_finite_.fetch_add(1, std::memory_order_relaxed);
}

LightingStats LightingBaker::stats() const {
  LightingStats s = build_stats_;
  s.samples = samples_.load(), s.shadow_rays = shadow_rays_.load(), s.ao_rays = ao_rays_.load();
  s.clamped = clamped_.load(), s.non_finite = non_finite_.load();
  return s;
}

}  // namespace vt
