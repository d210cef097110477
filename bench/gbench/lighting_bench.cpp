// Baked lighting's cost and accuracy (docs/BENCHMARKS.md "Baked lighting").
// BM_AoSamples/N: the transfer of a corner scene (a floor, a wall standing on it and a box) lit
// by one directional light with N AO rays per texel, against a 4096-ray reference computed
// once: time per million covered texels, relative RMSE of the AO channel (RMSE / mean of the
// reference), PSNR of AO (peak 1) and PSNR in log2 space (log2 of AO clamped at 1/1024, peak
// 10). BM_SampleScene/L: the transfer of the sample scene (samples/) with L of 3 lights (sun,
// point, spot) placed: what lighting adds; rays per second per thread. BM_LitScene*: the same on
// the lit sample scene and on a real level lit by bench/add_lights.py ($VTBAKE_LIT_LEVEL).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <vector>

#include "bake/coverage_mask.h"
#include "bake/lighting.h"
#include "bake/transfer.h"
#include "bake/unwrap/unwrap.h"
#include "common/parallel.h"
#include "samples/sample_scene.h"
#include "scene/scene.h"

namespace vt {
namespace {

constexpr uint32_t kAtlas = 256;

scene::Primitive box_face_grid(std::array<float, 3> o, std::array<float, 3> a,
                               std::array<float, 3> b, std::array<float, 4> uv, int n = 8) {
  scene::Primitive p;
  std::vector<scene::Vec2> t;
  std::array<float, 3> nrm = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                              a[0] * b[1] - a[1] * b[0]};
  const float len = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
  for (float& c : nrm) c /= len;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float s = float(i) / n, r = float(j) / n;
      p.positions.push_back(
          {o[0] + a[0] * s + b[0] * r, o[1] + a[1] * s + b[1] * r, o[2] + a[2] * s + b[2] * r});
      p.normals.push_back(nrm);
      t.push_back({uv[0] + (uv[1] - uv[0]) * s, uv[3] - (uv[3] - uv[2]) * r});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t q = j * (n + 1) + i;
      for (uint32_t k : {q, q + 1, q + n + 2, q, q + n + 2, q + n + 1}) p.indices.push_back(k);
    }
  p.uvs.push_back(t);
  p.material = 0;
  return p;
}

// Floor [-1, 1]^2 (z = 0, facing +z), a wall at x = 1 (facing -x) and a box top at z = 0.3.
scene::Scene corner_scene() {
  scene::Scene s;
  s.materials.push_back({});
  scene::Mesh m;
  m.primitives.push_back(
      box_face_grid({-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, {0.02f, 0.6f, 0.02f, 0.6f}));
  m.primitives.push_back(
      box_face_grid({1, -1, 0}, {0, 0, 1}, {0, 2, 0}, {0.65f, 0.98f, 0.02f, 0.6f}));
  m.primitives.push_back(
      box_face_grid({-0.5f, -0.3f, 0.3f}, {0.6f, 0, 0}, {0, 0.6f, 0}, {0.02f, 0.4f, 0.65f, 0.98f}));
  s.meshes.push_back(m);
  scene::Node n;
  n.mesh = 0;
  s.nodes.push_back(n);
  scene::Light sun;
  sun.type = scene::LightType::kDirectional;
  sun.intensity = 1;
  s.lights.push_back(sun);
  scene::Node ln;
  ln.light = 0;
  s.nodes.push_back(ln);
  s.roots = {0, 1};
  return s;
}

std::vector<float> ao_of(const TransferResult& r) {
  for (const TransferLayer& l : r.layers)
    if (l.semantic == LayerSemantic::kLighting) {
      std::vector<float> ao;
      const std::vector<uint8_t> coverage = *r.coverage->to_bytes();
      for (size_t i = 0; i < l.texels.size() / 4; ++i)
        if (coverage[i]) ao.push_back(l.texels[4 * i + 3]);
      return ao;
    }
  return {};
}

TransferResult run(const scene::Scene& s, uint32_t size, int ao, int threads) {
  TransferOptions o;
  o.width = o.height = size;
  o.threads = threads;
  o.lighting.ao_samples = ao;
  o.lighting.ao_distance = 1.0;
  return std::move(transfer_materials(s, o)).value();
}

void BM_AoSamples(benchmark::State& state) {
  static const scene::Scene scene = corner_scene();
  static const std::vector<float> reference = ao_of(run(scene, kAtlas, 4096, 0));
  const int n = int(state.range(0));
  std::vector<float> ao;
  uint64_t texels = 0;
  for (auto _ : state) {
    TransferResult r = run(scene, kAtlas, n, 1);
    texels = r.stats.covered_texels;
    ao = ao_of(r);
  }
  double se = 0, sel = 0, mean = 0;
  for (size_t i = 0; i < ao.size(); ++i) {
    const double d = ao[i] - reference[i];
    const double dl =
        std::log2(std::max(ao[i], 1.0f / 1024)) - std::log2(std::max(reference[i], 1.0f / 1024));
    se += d * d, sel += dl * dl, mean += reference[i];
  }
  const double count = double(std::max<size_t>(ao.size(), 1));
  state.counters["rel_rmse"] = std::sqrt(se / count) / (mean / count);
  state.counters["psnr_db"] = 10 * std::log10(1.0 / std::max(se / count, 1e-20));
  state.counters["psnr_log_db"] = 10 * std::log10(100.0 / std::max(sel / count, 1e-20));
  state.counters["texels"] = double(texels);
  state.counters["s_per_Mtexel"] =
      benchmark::Counter(double(texels) / 1e6, benchmark::Counter::kIsIterationInvariantRate |
                                                   benchmark::Counter::kInvert);
}
BENCHMARK(BM_AoSamples)
    ->RangeMultiplier(4)
    ->Range(1, 1024)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// One bounce on the corner scene: the sun straight down lights the floor and the box top; the
// wall standing on the floor has only the floor's bounced light. Error of every texel's
// irradiance against a 4096-ray bounce (relative RMSE; PSNR in log2 space of lux clamped at
// 1/1024, peak log2 range 10).
void BM_BounceSamples(benchmark::State& state) {
  static const scene::Scene scene = corner_scene();
  auto run_bounce = [&](int n, int threads) {
    TransferOptions o;
    o.width = o.height = kAtlas;
    o.threads = threads;
    o.lighting.bounces = 1;
    o.lighting.bounce_samples = n;
    return std::move(transfer_materials(scene, o)).value();
  };
  auto rgb_of = [](const TransferResult& r) {
    std::vector<float> e;
    for (const TransferLayer& l : r.layers)
      if (l.semantic == LayerSemantic::kLighting) {
        const std::vector<uint8_t> coverage = *r.coverage->to_bytes();
        for (size_t i = 0; i < l.texels.size() / l.channels; ++i)
          if (coverage[i]) e.push_back(l.texels[l.channels * i]);
      }
    return e;
  };
  static const std::vector<float> reference = rgb_of(run_bounce(4096, 0));
  const int n = int(state.range(0));
  std::vector<float> e;
  uint64_t texels = 0;
  for (auto _ : state) {
    TransferResult r = run_bounce(n, 1);
    texels = r.stats.covered_texels;
    e = rgb_of(r);
  }
  double se = 0, sel = 0, mean = 0;
  for (size_t i = 0; i < e.size() && i < reference.size(); ++i) {
    const double d = e[i] - reference[i];
    const double dl =
        std::log2(std::max(e[i], 1.0f / 1024)) - std::log2(std::max(reference[i], 1.0f / 1024));
    se += d * d, sel += dl * dl, mean += reference[i];
  }
  const double count = double(std::max<size_t>(e.size(), 1));
  state.counters["rel_rmse"] = std::sqrt(se / count) / (mean / count);
  state.counters["psnr_log_db"] = 10 * std::log10(100.0 / std::max(sel / count, 1e-20));
  state.counters["s_per_Mtexel"] =
      benchmark::Counter(double(texels) / 1e6, benchmark::Counter::kIsIterationInvariantRate |
                                                   benchmark::Counter::kInvert);
}
BENCHMARK(BM_BounceSamples)
    ->RangeMultiplier(4)
    ->Range(1, 256)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The sample scene, unwrapped once, with 0 or 3 lights.
const unwrap::UnwrapResult& sample_scene() {
  static const unwrap::UnwrapResult u = [] {
    const std::string dir =
        (std::filesystem::temp_directory_path() / "vtbake-lighting-bench").string();
    SampleSceneOptions so;
    so.texture_size = 256;
    (void)write_sample_scene(dir, so);
    scene::Scene s = std::move(scene::load_scene(dir + "/scene.gltf")).value();
    unwrap::UnwrapOptions uo;
    uo.size_pages = 8;
    uo.threads = 1;
    return std::move(unwrap::unwrap_scene(s, uo)).value();
  }();
  return u;
}

void BM_SampleScene(benchmark::State& state) {
  scene::Scene s = sample_scene().scene;
  s.lights.clear();
  for (scene::Node& n : s.nodes) n.light = -1;
  const int lights = int(state.range(0)), ao = int(state.range(1));
  auto place = [&](scene::Light l, scene::Mat4 m) {
    s.lights.push_back(l);
    scene::Node n;
    n.local = m;
    n.light = int(s.lights.size() - 1);
    s.nodes.push_back(n);
    s.roots.push_back(int(s.nodes.size() - 1));
  };
  {
    scene::Light sun, bulb, spot;
    sun.type = scene::LightType::kDirectional, sun.intensity = 3;
    bulb.type = scene::LightType::kPoint, bulb.intensity = 50;
    spot.type = scene::LightType::kSpot, spot.intensity = 200;
    scene::Mat4 down = scene::kIdentity;  // -Z turned to -Y (the sample scene's ground is y = 0)
    down[5] = 0, down[6] = -1, down[9] = 1, down[10] = 0;
    if (lights >= 1) place(sun, down);
    scene::Mat4 m = scene::kIdentity;
    m[12] = 1, m[13] = 3, m[14] = 1;
    if (lights >= 2) place(bulb, m);
    down[12] = -1, down[13] = 4, down[14] = 0;
    if (lights >= 3) place(spot, down);
  }
  const auto& st = sample_scene().stats;
  TransferOptions o;
  o.width = uint32_t(st.atlas_width), o.height = uint32_t(st.atlas_height);
  o.threads = 1;
  o.lighting.ao_samples = ao;
  uint64_t rays = 0, texels = 0, bvh = 0;
  for (auto _ : state) {
    TransferResult r = std::move(transfer_materials(s, o)).value();
    rays = r.stats.lighting.shadow_rays + r.stats.lighting.ao_rays;
    texels = r.stats.covered_texels, bvh = r.stats.lighting.bvh_bytes;
  }
  state.counters["texels"] = double(texels);
  state.counters["rays_per_s"] =
      benchmark::Counter(double(rays), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["bvh_MiB"] = double(bvh) / (1 << 20);
  state.counters["rays"] = double(rays);
}
// (lights, AO rays per texel sample): what each light and each AO ray adds.
BENCHMARK(BM_SampleScene)
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({3, 0})
    ->Args({3, 4})
    ->Args({3, 16})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Embree's rate alone: LightingBaker::evaluate at 100,000 points spread over the sample
// scene's ground (3 lights with shadows, 64 AO rays each: ~6.7 M rays a pass), on 1 or 2 threads
// (common/parallel.h, as the transfer runs it). rays_per_s_per_thread: rays over wall time and
// threads.
void BM_RaysPerThread(benchmark::State& state) {
  scene::Scene s = sample_scene().scene;
  s.lights.clear();
  for (scene::Node& n : s.nodes) n.light = -1;
  scene::Light sun;
  sun.type = scene::LightType::kDirectional, sun.intensity = 3;
  s.lights = {sun, sun, sun};
  for (int k = 0; k < 3; ++k) {  // three suns straight down (the ground is y = 0)
    scene::Node n;
    n.local = scene::kIdentity;
    n.local[5] = 0, n.local[6] = -1, n.local[9] = 1, n.local[10] = 0;
    n.light = k;
    s.nodes.push_back(n);
    s.roots.push_back(int(s.nodes.size() - 1));
  }
  LightingOptions lo;
  lo.ao_samples = 64;
  lo.ao_distance = 2.0;
  const int threads = int(state.range(0));
  auto baker = std::move(LightingBaker::create(s, lo, threads)).value();
  constexpr size_t kPoints = 100000;
  std::vector<LightingSample> points(kPoints);
  for (size_t i = 0; i < kPoints; ++i) {
    const double u = (i % 317) / 317.0, v = (i / 317) / 316.0;  // the ground is 12 x 12 at y = 0
    points[i].position = {(u - 0.5) * 11.0, 0.0, (v - 0.5) * 11.0};
    points[i].geometric_normal = points[i].shading_normal = {0, 1, 0};
    points[i].footprint = 0.01;
    points[i].seed = i;
  }
  const uint64_t before = baker->stats().shadow_rays + baker->stats().ao_rays;
  uint64_t passes = 0;
  for (auto _ : state) {
    parallel_for(kPoints / 1000, threads, [&](size_t chunk) {
      float out[4];
      for (size_t i = chunk * 1000; i < (chunk + 1) * 1000; ++i) baker->evaluate(points[i], out);
    });
    ++passes;
  }
  const double rays = double(baker->stats().shadow_rays + baker->stats().ao_rays - before);
  state.counters["rays_per_pass"] = rays / double(std::max<uint64_t>(passes, 1));
  state.counters["rays_per_s_per_thread"] = benchmark::Counter(
      rays / double(passes) / threads, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_RaysPerThread)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// The lit scenes of the samples-versus-error figures, unwrapped once at 4 x 4 pages (480^2; the
// level at 8 x 8, 960^2, whose atlas it covers more thinly):
// 0 = `sample-scene --lights` (64-texel textures), 1 = the glTF at $VTBAKE_LIT_LEVEL (a real
// level with lights added by bench/add_lights.py). Null when the level is not given.
const unwrap::UnwrapResult* lit_scene(int which) {
  static std::map<int, std::optional<unwrap::UnwrapResult>> scenes;
  auto it = scenes.find(which);
  if (it == scenes.end()) {
    std::optional<unwrap::UnwrapResult> u;
    std::string path;
    if (which == 0) {
      path = (std::filesystem::temp_directory_path() / "vtbake-lit-sample").string();
      SampleSceneOptions so;
      so.texture_size = 64;
      so.lights = true;
      (void)write_sample_scene(path, so);
      path += "/scene.gltf";
    } else if (const char* level = std::getenv("VTBAKE_LIT_LEVEL")) {
      path = level;
    }
    if (auto s = path.empty() ? Expected<scene::Scene>(Error(ErrorCode::kNotFound, "no level"))
                              : scene::load_scene(path);
        s.ok()) {
      unwrap::UnwrapOptions uo;
      uo.size_pages = which == 0 ? 4 : 8;
      uo.threads = 1;
      if (auto r = unwrap::unwrap_scene(*s, uo); r.ok()) u = std::move(r).value();
    }
    it = scenes.emplace(which, std::move(u)).first;
  }
  return it->second ? &*it->second : nullptr;
}

TransferResult lit_transfer(const unwrap::UnwrapResult& u, const LightingOptions& lo, int threads) {
  TransferOptions o;
  o.width = uint32_t(u.stats.atlas_width), o.height = uint32_t(u.stats.atlas_height);
  o.threads = threads;
  o.lighting = lo;
  return std::move(transfer_materials(u.scene, o)).value();
}

// Channel `c` of the lighting layer at every covered texel.
std::vector<float> lighting_channel(const TransferResult& r, uint32_t c) {
  std::vector<float> out;
  const std::vector<uint8_t> coverage = *r.coverage->to_bytes();
  for (const TransferLayer& l : r.layers)
    if (l.semantic == LayerSemantic::kLighting)
      for (size_t i = 0; i < l.texels.size() / l.channels; ++i)
        if (coverage[i]) out.push_back(l.texels[l.channels * i + c]);
  return out;
}

// Relative RMSE and PSNR in log2 space (values clamped at 1/1024, peak log2 range 10) of `v`
// against `ref`, into the benchmark's counters.
void error_counters(benchmark::State& state, const std::vector<float>& v,
                    const std::vector<float>& ref) {
  double se = 0, sel = 0, mean = 0;
  const size_t n = std::min(v.size(), ref.size());
  for (size_t i = 0; i < n; ++i) {
    const double d = v[i] - ref[i];
    const double dl =
        std::log2(std::max(v[i], 1.0f / 1024)) - std::log2(std::max(ref[i], 1.0f / 1024));
    se += d * d, sel += dl * dl, mean += ref[i];
  }
  const double count = double(std::max<size_t>(n, 1));
  state.counters["rel_rmse"] = std::sqrt(se / count) / std::max(mean / count, 1e-30);
  state.counters["psnr_log_db"] = 10 * std::log10(100.0 / std::max(sel / count, 1e-20));
}

// How far AO looks in each lit scene (metres): the sample scene's objects are about 1 m, the
// level's streets about 10 m wide.
constexpr double kAoDistance[2] = {2.0, 10.0};

// BM_LitSceneSamples/SCENE/KIND/N: N AO rays (KIND 0, kAoDistance) or N bounce rays (KIND 1) per
// texel, all the scene's lights with shadows, against 4096 of them (computed once per scene and
// kind, on all threads); the error of the AO channel or of the irradiance (green), and wall seconds
// of the whole transfer per million covered texels on one thread. Registered for AO only: a
// 4096-ray bounce reference (each ray with its shadow rays) takes minutes per scene here; the
// corner scene's BM_BounceSamples has the bounce's curve.
void BM_LitSceneSamples(benchmark::State& state) {
  const int which = int(state.range(0)), kind = int(state.range(1)), n = int(state.range(2));
  const unwrap::UnwrapResult* u = lit_scene(which);
  if (!u) {
    state.SkipWithError("no level: set VTBAKE_LIT_LEVEL to a lit glTF");
    return;
  }
  auto options = [&](int samples) {
    LightingOptions lo;
    if (kind == 0) {
      lo.ao_samples = samples;
      lo.ao_distance = kAoDistance[which];
    } else {
      lo.bounces = 1;
      lo.bounce_samples = samples;
    }
    return lo;
  };
  const uint32_t channel = kind == 0 ? 3 : 1;
  static std::map<std::pair<int, int>, std::vector<float>> references;
  std::vector<float>& reference = references[{which, kind}];
  if (reference.empty()) reference = lighting_channel(lit_transfer(*u, options(4096), 0), channel);
  std::vector<float> v;
  uint64_t texels = 0;
  for (auto _ : state) {
    TransferResult r = lit_transfer(*u, options(n), 1);
    texels = r.stats.covered_texels;
    v = lighting_channel(r, channel);
  }
  error_counters(state, v, reference);
  state.counters["texels"] = double(texels);
  state.counters["s_per_Mtexel"] =
      benchmark::Counter(double(texels) / 1e6, benchmark::Counter::kIsIterationInvariantRate |
                                                   benchmark::Counter::kInvert);
}
BENCHMARK(BM_LitSceneSamples)
    ->ArgsProduct({{0, 1}, {0}, {1, 4, 16, 64, 256, 1024}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

// BM_LitSceneCost/SCENE/LIGHTS/AO: the transfer of a lit scene on one thread with its first
// LIGHTS placed lights (shadows on) and AO rays per texel: what each light and AO ray adds, and
// the Embree structure's memory.
void BM_LitSceneCost(benchmark::State& state) {
  const int which = int(state.range(0)), keep = int(state.range(1));
  const unwrap::UnwrapResult* u = lit_scene(which);
  if (!u) {
    state.SkipWithError("no level: set VTBAKE_LIT_LEVEL to a lit glTF");
    return;
  }
  scene::Scene s = u->scene;
  int placed = 0;
  for (scene::Node& node : s.nodes)
    if (node.light >= 0 && placed++ >= keep) node.light = -1;
  TransferOptions o;
  o.width = uint32_t(u->stats.atlas_width), o.height = uint32_t(u->stats.atlas_height);
  o.threads = 1;
  o.lighting.ao_samples = int(state.range(2));
  o.lighting.ao_distance = kAoDistance[which];
  uint64_t rays = 0, texels = 0, bvh = 0;
  double structure = 0;
  for (auto _ : state) {
    TransferResult r = std::move(transfer_materials(s, o)).value();
    rays = r.stats.lighting.shadow_rays + r.stats.lighting.ao_rays;
    texels = r.stats.covered_texels, bvh = r.stats.lighting.bvh_bytes;
    structure = r.stats.lighting.build_seconds;
  }
  state.counters["texels"] = double(texels);
  state.counters["rays"] = double(rays);
  state.counters["bvh_MiB"] = double(bvh) / (1 << 20);
  state.counters["bvh_ms"] = structure * 1e3;
}
BENCHMARK(BM_LitSceneCost)
    ->ArgsProduct({{0, 1}, {0, 1, 5}, {0}})
    ->ArgsProduct({{0, 1}, {5}, {4, 16}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace vt

BENCHMARK_MAIN();
