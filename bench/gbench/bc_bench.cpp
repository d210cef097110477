// BC encoders and decoders per 128x128 page, single thread, on procedural photo-like content
// (no data files needed): vtbake's levels against stb_dxt's BC1 modes, and the decoders.
//
//   bc_bench [google benchmark flags]
//
// Counters: texels/s (Mtexel/s = items_per_second / 1e6). The Kodak figures with PSNR come
// from `vtbake-bench codec` (docs/BENCHMARKS.md).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <cstring>  // stb_dxt uses memcpy
#include <vector>

#include "codec/bc.h"

#define STB_DXT_STATIC
#define STB_DXT_IMPLEMENTATION
#include <stb/stb_dxt.h>

namespace {

using namespace vt;
constexpr int kPage = 128;

// Smooth content with texture-like detail: several octaves of sines, deterministic.
std::vector<uint8_t> make_page(int channels) {
  std::vector<uint8_t> page(size_t(kPage) * kPage * channels);
  uint32_t s = 12345;
  for (int y = 0; y < kPage; ++y) {
    for (int x = 0; x < kPage; ++x) {
      for (int c = 0; c < channels; ++c) {
        s ^= s << 13, s ^= s >> 17, s ^= s << 5;
        double v = 128 + 70 * std::sin(0.05 * x + c) * std::cos(0.07 * y - c) +
                   30 * std::sin(0.3 * (x + y) + 2 * c) + double(s >> 28) - 8;
        page[(size_t(y) * kPage + x) * channels + c] = uint8_t(std::fmin(255, std::fmax(0, v)));
      }
    }
  }
  return page;
}

void BM_Encode(benchmark::State& state) {
  const auto format = BcFormat(state.range(0));
  const auto quality = BcQuality(state.range(1));
  const int channels = format == BcFormat::kBc4 ? 1 : format == BcFormat::kBc5 ? 2 : 3;
  const auto page = make_page(channels);
  std::vector<uint8_t> out(bc_image_bytes(format, kPage, kPage));
  for (auto _ : state) {
    (void)bc_encode_image(format, quality, page.data(), kPage, kPage, channels, out.data());
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * kPage * kPage);
}
// (format, level): BC1/BC3/BC4/BC5 at every level; BC7 real-time and normal.
BENCHMARK(BM_Encode)
    ->ArgNames({"format", "level"})
    ->Args({0, 0})
    ->Args({0, 1})
    ->Args({0, 2})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Args({2, 0})
    ->Args({2, 2})
    ->Args({3, 0})
    ->Args({3, 2})
    ->Args({4, 0})
    ->Args({4, 1});

void BM_StbDxtBc1(benchmark::State& state) {
  const int mode = int(state.range(0));
  const auto page = make_page(3);
  std::vector<uint8_t> out(bc_image_bytes(BcFormat::kBc1, kPage, kPage));
  uint8_t rgba[64];
  for (auto _ : state) {
    uint8_t* dst = out.data();
    for (int by = 0; by < kPage / 4; ++by) {
      for (int bx = 0; bx < kPage / 4; ++bx) {
        for (int i = 0; i < 16; ++i) {
          const uint8_t* src = &page[(size_t(by * 4 + i / 4) * kPage + bx * 4 + i % 4) * 3];
          rgba[4 * i] = src[0], rgba[4 * i + 1] = src[1], rgba[4 * i + 2] = src[2];
          rgba[4 * i + 3] = 255;
        }
        stb_compress_dxt_block(dst, rgba, 0, mode);
        dst += 8;
      }
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * kPage * kPage);
}
BENCHMARK(BM_StbDxtBc1)->ArgName("mode")->Arg(STB_DXT_NORMAL)->Arg(STB_DXT_HIGHQUAL);

void BM_Decode(benchmark::State& state) {
  const auto format = BcFormat(state.range(0));
  const int channels = bc_format_channels(format);
  const auto page = make_page(channels);
  std::vector<uint8_t> blocks(bc_image_bytes(format, kPage, kPage)), out(page.size());
  (void)bc_encode_image(format, BcQuality::kRealtime, page.data(), kPage, kPage, channels,
                        blocks.data());
  for (auto _ : state) {
    (void)bc_decode_image(format, blocks.data(), kPage, kPage, channels, out.data());
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * kPage * kPage);
}
BENCHMARK(BM_Decode)->ArgName("format")->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Arg(4);

}  // namespace

BENCHMARK_MAIN();
