// Baked lighting (see lighting.h). Light falloff follows KHR_lights_punctual's recommended model:
// point and spot lights fall off as window(d / range) / d^2 with window(x) = clamp(1 - x^4, 0, 1);
// spot lights scale by the square of clamp((cos(angle to axis) - cos outer) / (cos inner - cos
// outer), 0, 1). Rays start off the surface by half a texel footprint along the geometric
// normal (never a fixed epsilon: the texel is the scale at which the bake can see anything).
#include "bake/lighting.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <string>

#include "common/srgb.h"
#include "scene/image_load.h"
#include "scene/material_rules.h"
#include "scene/tangent_frame.h"

namespace vt {

// A shadow caster whose material cuts holes (MASK, and BLEND: see lighting.h): what the
// occlusion filter needs to find the base colour's alpha at a hit.
struct AlphaPlane {
  uint32_t width = 0, height = 0;
  std::vector<float> alpha;  // row-major; empty: the image could not be read
};
struct AlphaCaster {
  const AlphaPlane* plane = nullptr;  // the base colour texture's alpha; null: none
  scene::TextureRef ref;
  std::vector<scene::Vec2> uvs;     // the texture's UV set, per vertex (empty without a texture)
  std::vector<float> vertex_alpha;  // COLOR_0's alpha per vertex (empty: 1)
  std::vector<uint32_t> indices;
  float factor = 1.0f, cutoff = 0.5f;
};

// A surface a bounce ray can meet: what its base colour and shading need (world space).
struct RgbPlane {
  uint32_t width = 0, height = 0;
  std::vector<float> rgb;  // linear, row-major; empty: the image could not be read
};
struct BounceSurface {
  std::vector<Vec3d> positions, normals;
  std::vector<uint32_t> indices;
  double factor[3] = {1, 1, 1};
  std::vector<std::array<float, 3>> vertex_rgb;  // COLOR_0 (empty: white)
  const RgbPlane* plane = nullptr;               // the base colour texture; null: none
  scene::TextureRef ref;
  std::vector<scene::Vec2> uvs;
};

struct LightingBaker::Rays {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::atomic<int64_t> bytes{0}, peak{0};
  std::map<int, AlphaPlane> alpha_images;  // by scene image index
  std::map<int, RgbPlane> rgb_images;      // by scene image index (bounces)
  std::vector<BounceSurface> surfaces;     // by geometry id (bounces)
  std::vector<std::unique_ptr<AlphaCaster>> casters;
  ~Rays() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

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

// Direction i of the rank-1 lattice (R2 sequence) rotated by (r0, r1), cosine-weighted about n
// (t, b, n an orthonormal frame).
Vec3d lattice_direction(const Vec3d& t, const Vec3d& b, const Vec3d& n, double r0, double r1,
                        int i) {
  double u1 = r0 + 0.7548776662466927 * i, u2 = r1 + 0.5698402909980532 * i;
  u1 -= std::floor(u1), u2 -= std::floor(u2);
  const double r = std::sqrt(u1), phi = 2.0 * std::numbers::pi * u2;
  return t * (r * std::cos(phi)) + b * (r * std::sin(phi)) + n * std::sqrt(std::max(0.0, 1.0 - u1));
}

// A texel of an alpha plane, wrapped as the texture's sampler says.
float alpha_texel(const AlphaCaster& c, int x, int y) {
  const AlphaPlane& p = *c.plane;
  return p.alpha[size_t(scene::wrap_texel(c.ref.wrap_t, y, p.height)) * p.width +
                 size_t(scene::wrap_texel(c.ref.wrap_s, x, p.width))];
}

// The base colour's alpha at barycentric (u, v) of `triangle`: texture (bilinear, or nearest
// for a nearest magFilter, level 0) x factor x vertex alpha (scene/material_rules.h).
float caster_alpha(const AlphaCaster& c, uint32_t triangle, float u, float v) {
  const uint32_t* t = &c.indices[3 * size_t(triangle)];
  const double b[3] = {1.0 - u - v, u, v};
  double a = c.factor;
  if (!c.vertex_alpha.empty())
    a *= b[0] * c.vertex_alpha[t[0]] + b[1] * c.vertex_alpha[t[1]] + b[2] * c.vertex_alpha[t[2]];
  if (c.plane) {
    double s = 0, r = 0;
    for (int k = 0; k < 3; ++k) s += b[k] * c.uvs[t[k]][0], r += b[k] * c.uvs[t[k]][1];
    const auto st = scene::texture_uv(c.ref, s, r);
    const double x = st[0] * c.plane->width - 0.5, y = st[1] * c.plane->height - 0.5;
    if (c.ref.mag_filter == scene::FilterMode::kNearest) {
      a *= alpha_texel(c, int(std::floor(x + 0.5)), int(std::floor(y + 0.5)));
    } else {
      const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
      const double fx = x - x0, fy = y - y0;
      a *= (1 - fy) * ((1 - fx) * alpha_texel(c, x0, y0) + fx * alpha_texel(c, x0 + 1, y0)) +
           fy * ((1 - fx) * alpha_texel(c, x0, y0 + 1) + fx * alpha_texel(c, x0 + 1, y0 + 1));
    }
  }
  return float(a);
}

// The base colour (linear RGB) at barycentric `w` of `triangle`: factor x texture (bilinear,
// level 0) x vertex colour.
void surface_albedo(const BounceSurface& sf, uint32_t triangle, const double w[3], double out[3]) {
  const uint32_t* t = &sf.indices[3 * size_t(triangle)];
  for (int c = 0; c < 3; ++c) out[c] = sf.factor[c];
  if (!sf.vertex_rgb.empty()) {
    for (int c = 0; c < 3; ++c)
      out[c] *= w[0] * sf.vertex_rgb[t[0]][c] + w[1] * sf.vertex_rgb[t[1]][c] +
                w[2] * sf.vertex_rgb[t[2]][c];
  }
  if (sf.plane) {
    double u = 0, v = 0;
    for (int k = 0; k < 3; ++k) u += w[k] * sf.uvs[t[k]][0], v += w[k] * sf.uvs[t[k]][1];
    const auto st = scene::texture_uv(sf.ref, u, v);
    const RgbPlane& p = *sf.plane;
    const double x = st[0] * p.width - 0.5, y = st[1] * p.height - 0.5;
    const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
    const double fx = x - x0, fy = y - y0;
    double tex[3] = {0, 0, 0};
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const double wt = (i ? fx : 1 - fx) * (j ? fy : 1 - fy);
        const size_t o =
            (size_t(scene::wrap_texel(sf.ref.wrap_t, y0 + j, int(p.height))) * p.width +
             scene::wrap_texel(sf.ref.wrap_s, x0 + i, int(p.width))) *
            3;
        for (int c = 0; c < 3; ++c) tex[c] += wt * p.rgb[o + c];
      }
    for (int c = 0; c < 3; ++c) out[c] *= tex[c];
  }
}

// What a bounce ray needs of primitive `p` placed by `world` (attached as the next geometry).
void add_bounce_surface(const scene::Scene& scene, const scene::Primitive& p,
                        const scene::Mat4& world, LightingBaker::Rays& rays) {
  BounceSurface sf;
  const std::vector<scene::Vec3> normals =
      p.normals.size() == p.positions.size() ? p.normals : scene::compute_normals(p);
  for (size_t k = 0; k < p.positions.size(); ++k) {
    const auto w = scene::transform_point(world, p.positions[k]);
    const auto n = scene::transform_direction(world, normals[k]);
    sf.positions.push_back({w[0], w[1], w[2]});
    sf.normals.push_back(normalized(Vec3d{n[0], n[1], n[2]}, Vec3d{0, 0, 1}));
  }
  const uint32_t count = uint32_t(p.positions.size());
  for (size_t k = 0; k + 2 < p.indices.size(); k += 3) {
    const bool ok = p.indices[k] < count && p.indices[k + 1] < count && p.indices[k + 2] < count;
    for (int c = 0; c < 3; ++c) sf.indices.push_back(ok ? p.indices[k + c] : 0);
  }
  if (p.colors.size() == p.positions.size())
    for (const auto& c : p.colors) sf.vertex_rgb.push_back({c[0], c[1], c[2]});
  if (p.material >= 0 && size_t(p.material) < scene.materials.size()) {
    const scene::Material& m = scene.materials[p.material];
    for (int c = 0; c < 3; ++c) sf.factor[c] = m.base_color_factor[c];
    const scene::TextureRef& ref = m.base_color_texture;
    const std::vector<scene::Vec2>* uvs = ref.valid() ? scene::texture_uv_set(p, ref) : nullptr;
    if (uvs && uvs->size() == p.positions.size() && size_t(ref.image) < scene.images.size()) {
      auto it = rays.rgb_images.find(ref.image);
      if (it == rays.rgb_images.end()) {
        RgbPlane plane;
        if (Expected<scene::FloatImage> img = scene::load_float_image(scene.images[ref.image])) {
          plane.width = img->width, plane.height = img->height;
          plane.rgb.resize(size_t(img->width) * img->height * 3);
          // 8- and 16-bit colour images carry the sRGB curve; float ones are linear.
          for (size_t i = 0; i < size_t(img->width) * img->height; ++i)
            for (int c = 0; c < 3; ++c) {
              const float v = img->rgba[4 * i + c];
              plane.rgb[3 * i + c] = img->is_float ? std::max(v, 0.0f) : srgb_to_linear(v);
            }
        }
        it = rays.rgb_images.emplace(ref.image, std::move(plane)).first;
      }
      if (!it->second.rgb.empty()) {
        sf.plane = &it->second;
        sf.uvs = *uvs;
        sf.ref = ref;
      }
    }
  }
  rays.surfaces.push_back(std::move(sf));
}

// Embree's occlusion filter of a cutting caster: a hit where alpha is below the cutoff is no
// hit (the ray goes on through the hole).
void alpha_filter(const RTCFilterFunctionNArguments* args) {
  const auto* c = static_cast<const AlphaCaster*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
    if (caster_alpha(*c, prim, RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i)) <
        c->cutoff)
      args->valid[i] = 0;
  }
}

std::string device_error(RTCDevice device, const char* what) {
  return std::string("lighting: Embree ") + what + " failed (error " +
         std::to_string(int(rtcGetDeviceError(device))) + ")";
}

// Makes `g` (primitive `p`) cut holes in shadows where its material asks: MASK at its cutoff,
// BLEND at 0.5. An image that cannot be read leaves the factor alone (as the transfer does with
// a missing texture, which it reports).
Status add_alpha_caster(const scene::Scene& scene, const scene::Primitive& p,
                        LightingBaker::Rays& rays, RTCGeometry g) {
  if (p.material < 0 || size_t(p.material) >= scene.materials.size()) return Status::Ok();
  const scene::Material& m = scene.materials[p.material];
  if (m.alpha_mode == scene::AlphaMode::kOpaque) return Status::Ok();
  auto c = std::make_unique<AlphaCaster>();
  c->cutoff = m.alpha_mode == scene::AlphaMode::kMask ? m.alpha_cutoff : 0.5f;
  c->factor = m.base_color_factor[3];
  c->indices = p.indices;
  for (const auto& col : p.colors) c->vertex_alpha.push_back(col[3]);
  if (c->vertex_alpha.size() != p.positions.size()) c->vertex_alpha.clear();
  const scene::TextureRef& ref = m.base_color_texture;
  const std::vector<scene::Vec2>* uvs = ref.valid() ? scene::texture_uv_set(p, ref) : nullptr;
  if (uvs && uvs->size() == p.positions.size() && size_t(ref.image) < scene.images.size()) {
    auto it = rays.alpha_images.find(ref.image);
    if (it == rays.alpha_images.end()) {
      AlphaPlane plane;
      if (Expected<scene::FloatImage> img = scene::load_float_image(scene.images[ref.image])) {
        plane.width = img->width, plane.height = img->height;
        plane.alpha.resize(size_t(img->width) * img->height);
        for (size_t i = 0; i < plane.alpha.size(); ++i) plane.alpha[i] = img->rgba[4 * i + 3];
      }
      it = rays.alpha_images.emplace(ref.image, std::move(plane)).first;
    }
    if (!it->second.alpha.empty()) {
      c->plane = &it->second;
      c->uvs = *uvs;
      c->ref = ref;
    }
  }
  // Nothing can fall below the cutoff: an ordinary caster.
  if (!c->plane && c->vertex_alpha.empty() && c->factor >= c->cutoff) return Status::Ok();
  rtcSetGeometryUserData(g, c.get());
  rtcSetGeometryOccludedFilterFunction(g, alpha_filter);
  rays.casters.push_back(std::move(c));
  return Status::Ok();
}

}  // namespace

Expected<LightingLayer> parse_lighting_layer(const std::string& name) {
  if (name == "separate") return LightingLayer::kSeparate;
  if (name == "combined") return LightingLayer::kCombined;
  return Error(ErrorCode::kInvalidArgument,
               "lighting: unknown layer mode '" + name + "' (separate or combined)");
}

const char* to_string(LightingLayer v) {
  return v == LightingLayer::kCombined ? "combined" : "separate";
}

bool scene_has_lights(const scene::Scene& scene) {
  return !scene.placed_lights().empty();
}

LightingBaker::~LightingBaker() = default;

Status check_lighting_options(const LightingOptions& options) {
  if (options.ao_samples < 0 || options.ao_samples > 65536)
    return Error(ErrorCode::kInvalidArgument, "lighting: AO samples must be 0..65536");
  if (options.bounces < 0 || options.bounces > 1)
    return Error(ErrorCode::kInvalidArgument, "lighting: bounces must be 0 or 1");
  if (options.bounces > 0 && (options.bounce_samples < 1 || options.bounce_samples > 65536))
    return Error(ErrorCode::kInvalidArgument, "lighting: bounce samples must be 1..65536");
  if (!(options.ao_distance >= 0) || !std::isfinite(options.ao_distance))
    return Error(ErrorCode::kInvalidArgument, "lighting: AO distance must be a finite number >= 0");
  if (options.layer == LightingLayer::kCombined && options.ao_samples > 0) {
    return Error(ErrorCode::kInvalidArgument,
                 "lighting: AO samples need --lighting separate (the combined layer is base colour "
                 "x irradiance / pi: AO is no light, and it has no channel of its own there)");
  }
  return Status::Ok();
}

Expected<std::unique_ptr<LightingBaker>> LightingBaker::create(const scene::Scene& scene,
                                                               const LightingOptions& options,
                                                               int threads) {
  VT_RETURN_IF_ERROR(check_lighting_options(options));
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
  if (!options.shadows && options.ao_samples == 0 && options.bounces == 0) return b;

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
      VT_RETURN_IF_ERROR(add_alpha_caster(scene, p, rays, g));
      if (options.bounces > 0) add_bounce_surface(scene, p, inst.world, rays);
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

void LightingBaker::direct(const Vec3d& position, const Vec3d& ng, const Vec3d& ns, double offset,
                           double sum[3], uint64_t& shadow_rays) const {
  const Vec3d origin = position + ng * offset;
  for (const Placed& l : lights_) {
    Vec3d to_light, ray_dir;  // from the surface point (shading), from the ray origin
    double tfar = std::numeric_limits<double>::infinity(), falloff = 1.0;
    if (l.type == scene::LightType::kDirectional) {
      to_light = ray_dir = l.direction * -1.0;
    } else {
      const Vec3d d = l.position - position;
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
      // A light behind the surface itself (a normal map turning the shading normal towards it)
      // is blocked by the surface: on a closed mesh the ray would hit it, except within the
      // offset of an edge, where light leaked in bands (found by the screen-space check). The
      // same rule as the AO rays'.
      if (!(dot(ng, ray_dir) > 0)) continue;
      ++shadow_rays;
      if (occluded(origin, ray_dir, tfar)) continue;
    }
    sum[0] += e.x, sum[1] += e.y, sum[2] += e.z;
  }
}

void LightingBaker::bounce(const Vec3d& origin, const Vec3d& ng, const Vec3d& ns, uint64_t seed,
                           double sum[3], uint64_t& shadow_rays, uint64_t& bounce_rays) const {
  // The AO rays' lattice under another seed: stratified, per texel sample, thread-independent.
  const uint64_t h = mix64(seed ^ 0x5851f42d4c957f2dull);
  const double r0 = unit_double(h), r1 = unit_double(mix64(h));
  const Vec3d t =
      normalized(cross(std::abs(ns.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0}, ns), Vec3d{1, 0, 0});
  const Vec3d b = cross(ns, t);
  const int n = options_.bounce_samples;
  double add[3] = {0, 0, 0};
  for (int i = 0; i < n; ++i) {
    const Vec3d dir = lattice_direction(t, b, ns, r0, r1, i);
    if (!(dot(dir, ng) > 0)) continue;  // below the surface itself
    ++bounce_rays;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = float(origin.x), rh.ray.org_y = float(origin.y), rh.ray.org_z = float(origin.z);
    rh.ray.dir_x = float(dir.x), rh.ray.dir_y = float(dir.y), rh.ray.dir_z = float(dir.z);
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(rays_->scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID || rh.hit.geomID >= rays_->surfaces.size())
      continue;
    const BounceSurface& sf = rays_->surfaces[rh.hit.geomID];
    const uint32_t* tri = &sf.indices[3 * size_t(rh.hit.primID)];
    const double w[3] = {1.0 - rh.hit.u - rh.hit.v, rh.hit.u, rh.hit.v};
    Vec3d p{0, 0, 0}, nrm{0, 0, 0};
    for (int k = 0; k < 3; ++k)
      p = p + sf.positions[tri[k]] * w[k], nrm = nrm + sf.normals[tri[k]] * w[k];
    const Vec3d gn = normalized(cross(sf.positions[tri[1]] - sf.positions[tri[0]],
                                      sf.positions[tri[2]] - sf.positions[tri[0]]),
                                dir * -1.0);
    // The side the ray arrived on is the side that reflects (either winding).
    Vec3d hn = normalized(nrm, gn), hg = gn;
    if (dot(hg, dir) > 0) hg = hg * -1.0;
    if (dot(hn, hg) < 0) hn = hn * -1.0;
    double albedo[3];
    surface_albedo(sf, rh.hit.primID, w, albedo);
    if (!(albedo[0] > 0 || albedo[1] > 0 || albedo[2] > 0)) continue;
    const double scale = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z), 1e-30});
    // Off the hit surface by the distance's rounding, and at least as far as the sample's own.
    const double off = std::max(scale * 4e-7, length(origin - p) * 1e-5);
    double e[3] = {0, 0, 0};
    direct(p, hg, hn, off, e, shadow_rays);
    for (int c = 0; c < 3; ++c) add[c] += albedo[c] * e[c];
  }
  for (int c = 0; c < 3; ++c) sum[c] += add[c] / std::max(n, 1);
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
  uint64_t shadow_rays = 0, ao_rays = 0, bounce_rays = 0;
  double sum[3] = {0, 0, 0};
  direct(s.position, ng, ns, offset, sum, shadow_rays);
  if (options_.bounces > 0 && rays_) bounce(origin, ng, ns, s.seed, sum, shadow_rays, bounce_rays);
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
      const Vec3d dir = lattice_direction(t, b, ns, r0, r1, i);
      if (!(dot(dir, ng) > 0)) continue;  // below the surface itself (normal-mapped normals)
      ++ao_rays;
      open += !occluded(origin, dir, ao_distance_);
    }
    out[3] = float(double(open) / double(n));
  }
  samples_.fetch_add(1, std::memory_order_relaxed);
  if (shadow_rays) shadow_rays_.fetch_add(shadow_rays, std::memory_order_relaxed);
  if (ao_rays) ao_rays_.fetch_add(ao_rays, std::memory_order_relaxed);
  if (bounce_rays) bounce_rays_.fetch_add(bounce_rays, std::memory_order_relaxed);
  if (clamped) clamped_.fetch_add(1, std::memory_order_relaxed);
  if (non_finite) non_finite_.fetch_add(1, std::memory_order_relaxed);
}

SurfaceCaster::~SurfaceCaster() = default;

Expected<std::unique_ptr<SurfaceCaster>> SurfaceCaster::create(std::span<const Mesh> meshes,
                                                               int threads) {
  std::unique_ptr<SurfaceCaster> c(new SurfaceCaster());
  c->rays_ = std::make_unique<LightingBaker::Rays>();
  LightingBaker::Rays& rays = *c->rays_;
  const std::string config = threads > 0 ? "threads=" + std::to_string(threads) : std::string();
  rays.device = rtcNewDevice(config.c_str());
  if (!rays.device) return Error(ErrorCode::kInternal, "lighting: Embree device creation failed");
  rays.scene = rtcNewScene(rays.device);
  rtcSetSceneFlags(rays.scene, RTC_SCENE_FLAG_ROBUST);
  for (uint32_t m = 0; m < meshes.size(); ++m) {
    // One geometry per mesh, so that the geometry id is the mesh index (empty ones too).
    const Mesh& mesh = meshes[m];
    const size_t vertices = mesh.positions.size() / 3, triangles = mesh.indices.size() / 3;
    RTCGeometry g = rtcNewGeometry(rays.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0,
                                                          RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                          std::max<size_t>(vertices, 1)));
    auto* idx = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t),
                                std::max<size_t>(triangles, 1)));
    if (!v || !idx) {
      rtcReleaseGeometry(g);
      return Error(ErrorCode::kResourceLimit, device_error(rays.device, "geometry buffer"));
    }
    std::fill(v, v + 3, 0.0f);
    std::copy(mesh.positions.begin(), mesh.positions.begin() + 3 * vertices, v);
    std::fill(idx, idx + 3, 0u);
    for (size_t k = 0; k < 3 * triangles; k += 3) {
      const bool ok = mesh.indices[k] < vertices && mesh.indices[k + 1] < vertices &&
                      mesh.indices[k + 2] < vertices;
      for (int i = 0; i < 3; ++i) idx[k + i] = ok ? mesh.indices[k + i] : 0;
    }
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(rays.scene, g, m);
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(rays.scene);
  if (rtcGetDeviceError(rays.device) != RTC_ERROR_NONE)
    return Error(ErrorCode::kInternal, device_error(rays.device, "scene build"));
  return c;
}

std::optional<SurfaceCaster::Hit> SurfaceCaster::first_hit(const Vec3d& origin, const Vec3d& dir,
                                                           double tfar) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = float(origin.x), rh.ray.org_y = float(origin.y), rh.ray.org_z = float(origin.z);
  rh.ray.dir_x = float(dir.x), rh.ray.dir_y = float(dir.y), rh.ray.dir_z = float(dir.z);
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = float(tfar);
  rh.ray.time = 0.0f;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(rays_->scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  return Hit{rh.hit.geomID, rh.hit.primID, double(rh.hit.u), double(rh.hit.v), double(rh.ray.tfar)};
}

LightingStats LightingBaker::stats() const {
  LightingStats s = build_stats_;
  s.samples = samples_.load(), s.shadow_rays = shadow_rays_.load(), s.ao_rays = ao_rays_.load();
  s.bounce_rays = bounce_rays_.load();
  s.clamped = clamped_.load(), s.non_finite = non_finite_.load();
  return s;
}

}  // namespace vt
