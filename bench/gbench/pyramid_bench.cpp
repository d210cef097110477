// The mip filter's cost with and without the chart rule (docs/BENCHMARKS.md "Coarse levels
// filtered within each chart"). BM_Downsample/F/C: one 2x reduction of a 2,048^2 RGBA level
// of flat charts 8 texels apart (sides 5..100 texels, 44% covered), pull-push dilated as the
// build dilates it, with filter F (0 box, 1 Kaiser, 2 Lanczos-3) and C = 1 when the coverage
// keeps the filter inside each chart. Reports megatexels per second of the source level and
// the share of output texels the chart rule changed.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "bake/pyramid.h"

namespace vt {
namespace {

constexpr uint32_t kSide = 2048, kPadding = 8;

struct Atlas {
  std::vector<float> texels;
  std::vector<uint8_t> coverage;
};

// Rows of charts packed left to right, each row as tall as its tallest chart.
const Atlas& atlas() {
  static const Atlas a = [] {
    Atlas r;
    r.texels.assign(size_t(kSide) * kSide * 4, 0.0f);
    r.coverage.assign(size_t(kSide) * kSide, 0);
    std::mt19937 rng(7);
    std::uniform_int_distribution<uint32_t> size(5, 100);
    std::uniform_real_distribution<float> value(0.0f, 1.0f);
    for (uint32_t y = 0; y < kSide;) {
      uint32_t row_height = 0;
      for (uint32_t x = 0; x < kSide;) {
        const uint32_t w = std::min(size(rng), kSide - x), h = std::min(size(rng), kSide - y);
        const float c[4] = {value(rng), value(rng), value(rng), 1.0f};
        for (uint32_t v = y; v < y + h; ++v)
          for (uint32_t u = x; u < x + w; ++u) {
            r.coverage[size_t(v) * kSide + u] = 1;
            for (int k = 0; k < 4; ++k) r.texels[(size_t(v) * kSide + u) * 4 + k] = c[k];
          }
        row_height = std::max(row_height, h);
        x += w + kPadding;
      }
      y += row_height + kPadding;
    }
    pull_push(r.texels.data(), r.coverage.data(), kSide, kSide, 4);
    return r;
  }();
  return a;
}

void BM_Downsample(benchmark::State& state) {
  const Atlas& a = atlas();
  const DownsampleKernel kernel = make_downsample_kernel(MipFilter(state.range(0)));
  const bool chart_rule = state.range(1) != 0;
  std::vector<float> out;
  for (auto _ : state) {
    out = downsample_level(kernel, DownsampleRules{}, a.texels.data(), kSide, kSide, 4,
                           chart_rule ? a.coverage.data() : nullptr);
    benchmark::DoNotOptimize(out.data());
  }
  // Output texels whose value the chart rule changed (flat charts: only where the plain filter
  // read another chart or a gutter texel of another chart's colour).
  if (chart_rule) {
    const std::vector<float> plain =
        downsample_level(kernel, DownsampleRules{}, a.texels.data(), kSide, kSide, 4, nullptr);
    size_t changed = 0;
    for (size_t i = 0; i < plain.size(); i += 4) changed += plain[i] != out[i];
    state.counters["changed_share"] = double(changed) / double(plain.size() / 4);
  }
  size_t covered = 0;
  for (uint8_t c : a.coverage) covered += c;
  state.counters["covered_share"] = double(covered) / double(a.coverage.size());
  state.counters["Mtexel/s"] = benchmark::Counter(double(kSide) * kSide * 1e-6,
                                                  benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_Downsample)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);

}  // namespace
}  // namespace vt

BENCHMARK_MAIN();
