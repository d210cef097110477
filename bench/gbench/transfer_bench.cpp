// Material transfer: supersampling accuracy versus time, and covered texels per second.
// A quad carrying a linear EXR of fine diagonal stripes (512^2) is baked at 64 texels per unit
// (8 source texels per atlas texel); the error is the RMSE against the exact footprint
// average (16 x 16 analytic samples per atlas texel) over fully covered texels.
//   build/release/bench/transfer_bench --benchmark_repetitions=5
//   --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include "bake/transfer.h"
#include "bake/unwrap/unwrap.h"
#include "samples/sample_scene.h"
#include "tests/transfer/atlas_reference.h"

namespace {

double stripes(double u, double v) {
  return 0.5 + 0.45 * std::sin(2 * std::numbers::pi * (37 * u + 11 * v));
}

struct Fixture {
  vt::unwrap::UnwrapResult unwrapped;
  std::vector<double> reference;  // per atlas texel, NaN where not fully inside the quad
  std::string dir;
};

Fixture& fixture() {
  static Fixture f = [] {
    Fixture f;
    f.dir =
        (std::filesystem::temp_directory_path() / ("vt_transfer_bench_" + std::to_string(getpid())))
            .string();
    std::filesystem::create_directories(f.dir);
    std::string tex = f.dir + "/stripes.exr";
    (void)vt::write_texture(tex, 512, 512, 3, [](double u, double v, float* t) {
      t[0] = t[1] = t[2] = float(stripes(u, v));
    });
    vt::scene::Scene s;
    vt::scene::Image im;
    im.path = tex;
    s.images.push_back(im);
    vt::scene::Material m;
    m.base_color_texture.image = 0;
    s.materials.push_back(m);
    vt::scene::Mesh mesh;
    mesh.primitives.push_back(vt::make_grid(1.0f, 1, 1));
    mesh.primitives[0].material = 0;
    s.meshes.push_back(mesh);
    vt::scene::Node n;
    n.mesh = 0;
    s.nodes.push_back(n);
    s.roots.push_back(0);
    vt::unwrap::UnwrapOptions uo;
    uo.texels_per_unit = 64;
    f.unwrapped = std::move(vt::unwrap::unwrap_scene(s, uo)).value();
    const auto& p = f.unwrapped.scene.meshes[0].primitives[0];
    uint32_t W = f.unwrapped.stats.atlas_width, H = f.unwrapped.stats.atlas_height;
    f.reference = vt::test::atlas_reference(p, W, H, 16, stripes);
    return f;
  }();
  return f;
}

void BM_TransferSupersample(benchmark::State& state) {
  Fixture& f = fixture();
  vt::TransferOptions o;
  o.width = f.unwrapped.stats.atlas_width;
  o.height = f.unwrapped.stats.atlas_height;
  o.supersample = int(state.range(0));
  o.threads = 1;
  uint64_t covered = 0;
  double rmse = 0;
  for (auto _ : state) {
    auto t = vt::transfer_materials(f.unwrapped.scene, o);
    if (!t.ok()) {
      state.SkipWithError(t.status().message().c_str());
      return;
    }
    covered = t->stats.covered_texels;
    double se = 0;
    uint64_t n = 0;
    for (size_t i = 0; i < f.reference.size(); ++i) {
      if (std::isnan(f.reference[i])) continue;
      double d = t->layers[0].texels[3 * i] - f.reference[i];
      se += d * d, ++n;
    }
    rmse = std::sqrt(se / double(n));
  }
  state.counters["rmse"] = rmse;
  state.counters["psnr_db"] = 20 * std::log10(1.0 / rmse);
  state.counters["covered_texels_per_s"] =
      benchmark::Counter(double(covered), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_TransferSupersample)
    ->Arg(1)
    ->Arg(4)
    ->Arg(16)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
