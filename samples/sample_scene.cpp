// The procedural sample scene (see sample_scene.h).
#include "samples/sample_scene.h"

#include <cmath>
#include <filesystem>
#include <numbers>

#include "bake/image_source.h"
#include "format/atomic_output.h"
#include "scene/gltf_export.h"

namespace vt {
namespace {

// How scene.gltf has always been spelled: samplers name their filters, texture references
// their UV set, materials their sidedness (users' incremental builds hash the file).
const scene::GltfWriteOptions kSampleSceneGltf = {.generator = "vtbake sample-scene",
                                                  .write_texcoord_0 = true,
                                                  .write_single_sided = true,
                                                  .write_opaque = false,
                                                  .sampler_filters = true};

using scene::Vec2;
using scene::Vec3;
using scene::Vec4;

// Deterministic hash noise in [0, 1).
double hash2(int64_t x, int64_t y, uint32_t seed) {
  uint64_t h = uint64_t(x) * 0x9E3779B97F4A7C15ull ^
               (uint64_t(y) + 0x632BE59BD9B4E019ull) * 0xC2B2AE3D27D4EB4Full;
  h ^= seed * 0x165667B19E3779F9ull;
  h ^= h >> 31;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 29;
  return double(h >> 11) * (1.0 / 9007199254740992.0);
}

// Smooth value noise at frequency `f` cells per unit.
double value_noise(double u, double v, double f, uint32_t seed) {
  double x = u * f, y = v * f;
  int64_t xi = int64_t(std::floor(x)), yi = int64_t(std::floor(y));
  double fx = x - xi, fy = y - yi;
  fx = fx * fx * (3 - 2 * fx), fy = fy * fy * (3 - 2 * fy);
  int64_t p = int64_t(f);  // periodic over [0, 1) so repeat wrapping shows no seam
  auto h = [&](int64_t a, int64_t b) { return hash2(((a % p) + p) % p, ((b % p) + p) % p, seed); };
  double a = h(xi, yi), b = h(xi + 1, yi), c = h(xi, yi + 1), d = h(xi + 1, yi + 1);
  return (a * (1 - fx) + b * fx) * (1 - fy) + (c * (1 - fx) + d * fx) * fy;
}

double fbm(double u, double v, double f, uint32_t seed) {
  double sum = 0, amp = 0.5;
  for (int o = 0; o < 4; ++o, f *= 2, amp *= 0.5) sum += amp * value_noise(u, v, f, seed + o);
  return sum / 0.9375;
}

// Tangent-space normal (n * 0.5 + 0.5) of a height field h(u, v) by central differences;
// x along +u, y up the image (-v), as glTF expects.
void height_normal(const std::function<double(double, double)>& h, double u, double v,
                   double strength, double step, float* out) {
  double dhdu = (h(u + step, v) - h(u - step, v)) / (2 * step);
  double dhdv = (h(u, v + step) - h(u, v - step)) / (2 * step);
  double nx = -dhdu * strength, ny = dhdv * strength, nz = 1.0;
  double l = std::sqrt(nx * nx + ny * ny + nz * nz);
  out[0] = float(nx / l * 0.5 + 0.5), out[1] = float(ny / l * 0.5 + 0.5),
  out[2] = float(nz / l * 0.5 + 0.5);
}

Vec3 normalize3(Vec3 v) {
  double l = std::sqrt(double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]);
  if (!(l > 0)) return {0, 0, 1};
  return {float(v[0] / l), float(v[1] / l), float(v[2] / l)};
}

scene::Mat4 translate_scale(double tx, double ty, double tz, double s, double rot_y = 0) {
  double c = std::cos(rot_y) * s, si = std::sin(rot_y) * s;
  return {c, 0, -si, 0, 0, s, 0, 0, si, 0, c, 0, tx, ty, tz, 1};
}

}  // namespace

scene::Primitive make_grid(float size, uint32_t cells, float uv_repeat) {
  scene::Primitive p;
  cells = std::max(1u, cells);
  p.uvs.resize(1);
  for (uint32_t j = 0; j <= cells; ++j) {
    for (uint32_t i = 0; i <= cells; ++i) {
      float u = float(i) / cells, v = float(j) / cells;
      p.positions.push_back({(u - 0.5f) * size, 0.0f, (v - 0.5f) * size});
      p.normals.push_back({0, 1, 0});
      p.uvs[0].push_back({u * uv_repeat, v * uv_repeat});
    }
  }
  for (uint32_t j = 0; j < cells; ++j) {
    for (uint32_t i = 0; i < cells; ++i) {
      uint32_t a = j * (cells + 1) + i, b = a + 1, c = a + cells + 1, d = c + 1;
      // Counter-clockwise seen from +y.
      p.indices.insert(p.indices.end(), {a, c, b, b, c, d});
    }
  }
  return p;
}

scene::Primitive make_box(float sx, float sy, float sz) {
  scene::Primitive p;
  p.uvs.resize(1);
  const Vec3 h = {sx / 2, sy / 2, sz / 2};
  // Per face: normal, then u and v axes (v down the image = -up on the face).
  const int axes[6][3] = {{0, 2, 1}, {0, 2, 1}, {1, 0, 2}, {1, 0, 2}, {2, 0, 1}, {2, 0, 1}};
  for (int f = 0; f < 6; ++f) {
    int n = axes[f][0];
    float sign = (f % 2 == 0) ? 1.0f : -1.0f;
    Vec3 normal = {0, 0, 0};
    normal[n] = sign;
    // Tangent (u) and up directions with cross(tangent, up) = normal (counter-clockwise front).
    Vec3 up = {0, 0, 0}, tangent;
    up[n == 1 ? 2 : 1] = 1;
    tangent = {up[1] * normal[2] - up[2] * normal[1], up[2] * normal[0] - up[0] * normal[2],
               up[0] * normal[1] - up[1] * normal[0]};
    uint32_t base = uint32_t(p.positions.size());
    for (int k = 0; k < 4; ++k) {
      float u = (k == 1 || k == 2) ? 1.0f : 0.0f, v = (k >= 2) ? 0.0f : 1.0f;
      Vec3 pos;
      for (int c = 0; c < 3; ++c) {
        pos[c] = (normal[c] + tangent[c] * (2 * u - 1) + up[c] * (1 - 2 * v)) * h[c];
      }
      p.positions.push_back(pos);
      p.normals.push_back(normal);
      p.uvs[0].push_back({u, v});
    }
    p.indices.insert(p.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  }
  return p;
}

scene::Primitive make_uv_sphere(float radius, uint32_t segments) {
  scene::Primitive p;
  p.uvs.resize(1);
  segments = std::max(4u, segments);
  uint32_t rings = std::max(2u, segments / 2);
  for (uint32_t j = 0; j <= rings; ++j) {
    double theta = std::numbers::pi * j / rings;  // 0 at the north pole (top of the image)
    for (uint32_t i = 0; i <= segments; ++i) {
      double phi = 2 * std::numbers::pi * i / segments;
      Vec3 n = {float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
                float(-std::sin(theta) * std::sin(phi))};
      p.positions.push_back({n[0] * radius, n[1] * radius, n[2] * radius});
      p.normals.push_back(n);
      p.uvs[0].push_back({float(i) / segments, float(j) / rings});
    }
  }
  for (uint32_t j = 0; j < rings; ++j) {
    for (uint32_t i = 0; i < segments; ++i) {
      uint32_t a = j * (segments + 1) + i, b = a + 1, c = a + segments + 1, d = c + 1;
      if (j > 0) p.indices.insert(p.indices.end(), {a, c, b});
      if (j + 1 < rings) p.indices.insert(p.indices.end(), {b, c, d});
    }
  }
  return p;
}

scene::Primitive make_torus(float major, float minor, uint32_t segments) {
  scene::Primitive p;
  p.uvs.resize(1);
  segments = std::max(6u, segments);
  uint32_t sides = std::max(3u, segments / 2);
  for (uint32_t j = 0; j <= sides; ++j) {
    double b = 2 * std::numbers::pi * j / sides;
    for (uint32_t i = 0; i <= segments; ++i) {
      double a = 2 * std::numbers::pi * i / segments;
      Vec3 n = {float(std::cos(b) * std::cos(a)), float(std::sin(b)),
                float(-std::cos(b) * std::sin(a))};
      double r = major + minor * std::cos(b);
      p.positions.push_back(
          {float(r * std::cos(a)), float(minor * std::sin(b)), float(-r * std::sin(a))});
      p.normals.push_back(n);
      p.uvs[0].push_back({float(i) / segments * 4, float(j) / sides});
    }
  }
  for (uint32_t j = 0; j < sides; ++j) {
    for (uint32_t i = 0; i < segments; ++i) {
      uint32_t a = j * (segments + 1) + i, b = a + 1, c = a + segments + 1, d = c + 1;
      p.indices.insert(p.indices.end(), {a, b, c, b, d, c});
    }
  }
  return p;
}

Status write_texture(const std::string& path, uint32_t width, uint32_t height, uint32_t channels,
                     const std::function<void(double u, double v, float* out)>& texel) {
  std::vector<float> data(size_t(width) * height * channels);
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      float t[4] = {0, 0, 0, 1};
      texel((x + 0.5) / width, (y + 0.5) / height, t);
      for (uint32_t c = 0; c < channels; ++c) data[(size_t(y) * width + x) * channels + c] = t[c];
    }
  }
  ImageInfo info;
  info.width = width, info.height = height, info.channels = channels;
  info.is_float = true;
  info.alpha_channel = channels == 4 ? 3 : -1;
  MemoryImageSource source(info, std::move(data));
  return write_image_file(source, path);
}

namespace {

// Albedo of a material made of cells: per-channel base + range * cell, lit by `light`, darkened
// by `mask` (grout, mortar), in that order of operations.
void cell_albedo(float* t, const double (&base)[3], const double (&range)[3], double cell,
                 double light, double mask) {
  for (int c = 0; c < 3; ++c) t[c] = float((base[c] + range[c] * cell) * light * mask);
}

// The textures, procedural, written under `dir` at `S` texels a side (some at 1/2 or 1/4).
Status write_sample_textures(const std::string& dir, uint32_t S) {
  auto file = [&](const std::string& name) { return (std::filesystem::path(dir) / name).string(); };
  // Ground: tiles with grout, grain and a bump map; roughness/metal varying per tile.
  auto tile_h = [](double u, double v) {
    double fu = u * 8 - std::floor(u * 8), fv = v * 8 - std::floor(v * 8);
    double edge = std::min({fu, 1 - fu, fv, 1 - fv});
    return std::min(1.0, edge * 20) * 0.6 + 0.4 * fbm(u, v, 32, 7);
  };
  VT_RETURN_IF_ERROR(
      write_texture(file("ground_albedo.png"), S, S, 3, [&](double u, double v, float* t) {
        double cell = hash2(int64_t(u * 8), int64_t(v * 8), 1), g = fbm(u, v, 64, 3);
        double grout = tile_h(u, v) < 0.45 ? 0.35 : 1.0;
        cell_albedo(t, {0.45, 0.40, 0.30}, {0.35, 0.20, 0.15}, cell, 0.7 + 0.3 * g, grout);
      }));
  VT_RETURN_IF_ERROR(write_texture(
      file("ground_normal.png"), S, S, 3,
      [&](double u, double v, float* t) { height_normal(tile_h, u, v, 0.02, 0.5 / S, t); }));
  VT_RETURN_IF_ERROR(
      write_texture(file("ground_mr.png"), S, S, 3, [&](double u, double v, float* t) {
        double cell = hash2(int64_t(u * 8), int64_t(v * 8), 9);
        t[0] = 1, t[1] = float(0.3 + 0.6 * fbm(u, v, 16, 5)), t[2] = cell > 0.8 ? 1.0f : 0.0f;
      }));
  // Bricks (boxes): colour, grooves, ambient occlusion in the grooves.
  auto brick = [](double u, double v) {
    double row = std::floor(v * 8), bu = u * 4 + (int64_t(row) % 2) * 0.5;
    double fu = bu - std::floor(bu), fv = v * 8 - row;
    return std::min(1.0, std::min({fu, 1 - fu}) * 24) * std::min(1.0, std::min(fv, 1 - fv) * 12);
  };
  VT_RETURN_IF_ERROR(
      write_texture(file("brick_albedo.png"), S, S, 3, [&](double u, double v, float* t) {
        double row = std::floor(v * 8), bu = u * 4 + (int64_t(row) % 2) * 0.5;
        double c = hash2(int64_t(std::floor(bu)), int64_t(row), 4), g = fbm(u, v, 128, 11);
        double m = brick(u, v) > 0.5 ? 1.0 : 0.5;
        cell_albedo(t, {0.55, 0.22, 0.15}, {0.25, 0.10, 0.05}, c, 0.8 + 0.2 * g, m);
      }));
  VT_RETURN_IF_ERROR(write_texture(
      file("brick_normal.png"), S, S, 3,
      [&](double u, double v, float* t) { height_normal(brick, u, v, 0.05, 0.5 / S, t); }));
  VT_RETURN_IF_ERROR(
      write_texture(file("brick_ao.png"), S, S, 1,
                    [&](double u, double v, float* t) { t[0] = float(0.4 + 0.6 * brick(u, v)); }));
  // Sphere: a linear (scene-referred) EXR with fine bands, to exercise colour spaces.
  VT_RETURN_IF_ERROR(
      write_texture(file("sphere_albedo.exr"), S, S / 2, 3, [&](double u, double v, float* t) {
        double band = 0.5 + 0.5 * std::sin(u * 2 * std::numbers::pi * 24) *
                                std::sin(v * std::numbers::pi * 12);
        t[0] = float(0.05 + 0.6 * band), t[1] = float(0.1 + 0.3 * fbm(u, v, 64, 2)),
        t[2] = float(0.6 - 0.5 * band);
      }));
  // Torus: emissive fine lines.
  VT_RETURN_IF_ERROR(
      write_texture(file("torus_emissive.png"), S, S / 4, 3, [&](double u, double v, float* t) {
        double line = std::abs(std::sin(u * 2 * std::numbers::pi * 16)) > 0.97 ||
                              std::abs(std::sin(v * 2 * std::numbers::pi * 4)) > 0.97
                          ? 1
                          : 0;
        t[0] = float(line), t[1] = float(0.6 * line), t[2] = float(0.2 * line);
      }));
  // Card: a leaf with an alpha mask.
  return write_texture(file("leaf_albedo.png"), S / 2, S / 2, 4, [&](double u, double v, float* t) {
    double x = (u - 0.5) * 2, y = (v - 0.5) * 2;
    double inside = x * x / 0.5 + y * y < 1 - 0.15 * std::sin(std::atan2(y, x) * 12) ? 1 : 0;
    double vein = std::abs(x) < 0.02 ? 0.6 : 1.0;
    t[0] = float(0.15 * vein), t[1] = float((0.45 + 0.2 * fbm(u, v, 32, 8)) * vein),
    t[2] = float(0.1 * vein);
    t[3] = float(inside);
  });
}

// The images the textures became and the five materials over them (sc.images, sc.materials).
void add_sample_materials(scene::Scene& sc, const std::string& dir) {
  namespace fs = std::filesystem;
  auto image = [&](const std::string& file) {
    scene::Image im;
    im.name = fs::path(file).stem().string();
    im.uri = file;
    im.path = (fs::path(dir) / file).string();
    if (file.ends_with(".png")) im.mime_type = "image/png";
    sc.images.push_back(im);
    scene::TextureRef r;
    r.image = int(sc.images.size() - 1);
    return r;
  };
  auto ground_albedo = image("ground_albedo.png"), ground_normal = image("ground_normal.png");
  auto ground_mr = image("ground_mr.png"), brick_albedo = image("brick_albedo.png");
  auto brick_normal = image("brick_normal.png"), brick_ao = image("brick_ao.png");
  auto sphere_albedo = image("sphere_albedo.exr"), torus_emissive = image("torus_emissive.png");
  auto leaf_albedo = image("leaf_albedo.png");

  scene::Material ground;
  ground.name = "ground";
  ground.base_color_texture = ground_albedo;
  ground.normal_texture = ground_normal;
  ground.metallic_roughness_texture = ground_mr;
  scene::Material bricks;
  bricks.name = "bricks";
  bricks.base_color_texture = brick_albedo;
  bricks.normal_texture = brick_normal;
  bricks.occlusion_texture = brick_ao;
  bricks.metallic_factor = 0.0f;
  bricks.roughness_factor = 0.8f;
  scene::Material sphere;
  sphere.name = "sphere (linear EXR)";
  sphere.base_color_texture = sphere_albedo;
  sphere.metallic_factor = 0.6f;
  sphere.roughness_factor = 0.3f;
  scene::Material torus;
  torus.name = "glowing torus";
  torus.base_color_factor = {0.1f, 0.1f, 0.12f, 1.0f};
  torus.emissive_texture = torus_emissive;
  torus.emissive_factor = {1.0f, 1.0f, 1.0f};
  torus.metallic_factor = 0.0f;
  torus.roughness_factor = 0.5f;
  scene::Material leaf;
  leaf.name = "leaf (alpha mask)";
  leaf.base_color_texture = leaf_albedo;
  leaf.alpha_mode = scene::AlphaMode::kMask;
  leaf.double_sided = true;
  leaf.metallic_factor = 0.0f;
  leaf.roughness_factor = 0.6f;
  sc.materials = {ground, bricks, sphere, torus, leaf};
}

// The meshes (material i of add_sample_materials) and the nodes placing them.
void add_sample_meshes(scene::Scene& sc, const SampleSceneOptions& o) {
  auto mesh = [&](const std::string& name, scene::Primitive p, int material) {
    p.material = material;
    scene::Mesh m;
    m.name = name;
    m.primitives.push_back(std::move(p));
    sc.meshes.push_back(std::move(m));
    return int(sc.meshes.size() - 1);
  };
  int ground_mesh = mesh("ground", make_grid(12, o.ground_cells, 3), 0);
  int box_mesh = mesh("box", make_box(1.2f, 1.2f, 1.2f), 1);
  int sphere_mesh = mesh("sphere", make_uv_sphere(1.0f, o.sphere_segments), 2);
  int torus_mesh = mesh("torus", make_torus(0.9f, 0.3f, std::max(12u, o.sphere_segments / 2)), 3);
  scene::Primitive card = make_grid(1.5f, 1, 1);
  for (auto& n : card.normals) n = normalize3({0, 0, 1});
  for (auto& pos : card.positions) pos = {pos[0], -pos[2] + 0.75f, 0.0f};  // stand it up, facing +z
  int card_mesh = mesh("leaf card", card, 4);

  auto node = [&](const std::string& name, int m, const scene::Mat4& local) {
    scene::Node n;
    n.name = name, n.mesh = m, n.local = local;
    sc.nodes.push_back(n);
    sc.roots.push_back(int(sc.nodes.size() - 1));
  };
  node("ground", ground_mesh, scene::kIdentity);
  node("box 1", box_mesh, translate_scale(-3, 0.6, -2, 1.0, 0.3));  // one mesh, three instances
  node("box 2", box_mesh, translate_scale(-1.4, 0.6, -2.6, 1.0, 1.1));
  node("box 3", box_mesh, translate_scale(-2.2, 1.8, -2.3, 0.8, 0.7));
  node("sphere", sphere_mesh, translate_scale(1.5, 1.0, -1.0, 1.0));
  node("torus", torus_mesh, translate_scale(-1.0, 0.3, 2.0, 1.0, 0.5));
  node("leaf card", card_mesh, translate_scale(3.0, 0.0, 2.0, 1.0, -0.6));
}

// The lit variant's lights: a warm sun from above left, a bulb over the sphere and a spot
// looking straight down at the boxes, each at a node of its own (its -Z along the light).
void add_sample_lights(scene::Scene& sc) {
  auto place = [&](const std::string& name, scene::Light light, Vec3 position, Vec3 direction) {
    light.name = name;
    sc.lights.push_back(light);
    const Vec3 z = normalize3({-direction[0], -direction[1], -direction[2]});
    const Vec3 x = normalize3(std::abs(z[1]) < 0.9f ? Vec3{z[2], 0, -z[0]} : Vec3{0, -z[2], z[1]});
    const Vec3 y = {z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2],
                    z[0] * x[1] - z[1] * x[0]};
    scene::Node n;
    n.name = name;
    n.light = int(sc.lights.size() - 1);
    n.local = {x[0], x[1], x[2], 0, y[0],        y[1],        y[2],        0,
               z[0], z[1], z[2], 0, position[0], position[1], position[2], 1};
    sc.nodes.push_back(n);
    sc.roots.push_back(int(sc.nodes.size() - 1));
  };
  scene::Light sun;
  sun.type = scene::LightType::kDirectional;
  sun.color = {1.0f, 0.9f, 0.8f};
  sun.intensity = 3.0f;  // lux
  place("sun", sun, {0, 8, 0}, {0.4f, -1.0f, 0.3f});
  scene::Light bulb;
  bulb.type = scene::LightType::kPoint;
  bulb.intensity = 40.0f;  // candela
  bulb.range = 20.0f;
  place("bulb", bulb, {1.0f, 3.0f, 1.0f}, {0, -1, 0});
  scene::Light spot;
  spot.type = scene::LightType::kSpot;
  spot.intensity = 80.0f;
  spot.inner_cone_angle = 0.2f;
  spot.outer_cone_angle = 0.6f;
  place("spot", spot, {-2.0f, 4.0f, -2.0f}, {0, -1, 0});
}

}  // namespace

Status write_sample_scene(const std::string& dir, const SampleSceneOptions& o) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return Error(ErrorCode::kIo, dir + ": cannot create folder (" + ec.message() + ")");
  VT_RETURN_IF_ERROR(write_sample_textures(dir, std::max(16u, o.texture_size)));
  scene::Scene sc;
  add_sample_materials(sc, dir);
  add_sample_meshes(sc, o);
  if (o.lights) add_sample_lights(sc);
  sc.source_path = (fs::path(dir) / "scene.gltf").string();
  scene::GltfWriteOptions wo = kSampleSceneGltf;
  wo.lights_required = o.lights;
  VT_RETURN_IF_ERROR(scene::save_gltf(sc, sc.source_path, wo));
  // The scene's own atlas size (bake/unwrap/texel_density.h): its textures would ask for about
  // 52 x 53 pages (the bricks' 427 texels per unit); 16 keeps the main job within its few
  // minutes and its output as it always was.
  const std::string density = (fs::path(dir) / "scene.density.json").string();
  return write_output_bytes(density, "{\"size_pages\": 16}\n");
}

}  // namespace vt
