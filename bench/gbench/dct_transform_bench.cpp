// The DCT decoder's pixel back end (codec/dct_transform.h) per 128x128 RGB 4:2:0 page, for every
// implementation this host runs (avx2, sse2, scalar):
//   BM_IdctPage/<impl>      384 blocks (256 Y + 2 x 64 chroma): 40% DC-only, 40% nv, nu <= 4,
//                           20% up to 8x8, coefficients shaped like quantised photo blocks
//   BM_Colour420Page/<impl>/<ch>   YCoCg 4:2:0 -> RGB(A)
//   BM_Colour444Page/<impl>/<ch>   YCoCg 4:4:4 -> RGB(A)
//   BM_PlaneToChannel/<impl>/<ch>  one plane into the last channel (alpha for ch = 4)
//   BM_BackEndPage/<impl>   IDCT + 4:2:0 colour, the whole back end of one RGB page
// The CPU column is the benchmark thread's CPU time (the machine is shared). For medians:
//   dct_transform_bench --benchmark_repetitions=15 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "codec/dct_transform.h"
#include "common/hash.h"

namespace {

using vt::Lcg64;
using vt::dct_detail::idct_dc_block;
using vt::dct_detail::TransformImpl;

constexpr int kPage = 128;

struct Block {
  int16_t f[64];
  int nv, nu;  // 0: DC only
  int plane, bx, by;
};

// One synthetic page of dequantised blocks with the mix of a real decode.
struct PageBlocks {
  std::vector<Block> blocks;
  PageBlocks() {
    Lcg64 rng{2024};
    auto add_plane = [&](int plane, int bw, int bh) {
      for (int by = 0; by < bh; by++)
        for (int bx = 0; bx < bw; bx++) {
          Block b{};
          b.plane = plane, b.bx = bx, b.by = by;
          const int kind = rng.range(0, 9);  // 0-3 DC, 4-7 small, 8-9 large
          b.f[0] = int16_t(rng.range(plane == 0 ? -900 : -300, plane == 0 ? 900 : 300));
          if (kind >= 4) {
            b.nv = kind < 8 ? rng.range(1, 4) : rng.range(5, 8);
            b.nu = kind < 8 ? rng.range(2, 4) : rng.range(5, 8);
            for (int v = 0; v < b.nv; v++)
              for (int u = 0; u < b.nu; u++) {
                const int amp = 400 / (1 + u + v);
                if ((u || v) && rng.range(0, 2)) b.f[v * 8 + u] = int16_t(rng.range(-amp, amp));
              }
          }
          blocks.push_back(b);
        }
    };
    add_plane(0, kPage / 8, kPage / 8);
    add_plane(1, kPage / 16, kPage / 16);
    add_plane(2, kPage / 16, kPage / 16);
  }
};

const PageBlocks& page_blocks() {
  static const PageBlocks p;
  return p;
}

struct PagePlanes {
  std::vector<int16_t> y = std::vector<int16_t>(kPage * kPage);
  std::vector<int16_t> co = std::vector<int16_t>(kPage * kPage / 4);
  std::vector<int16_t> cg = std::vector<int16_t>(kPage * kPage / 4);
  int16_t* plane(int p) { return p == 0 ? y.data() : p == 1 ? co.data() : cg.data(); }
};

void idct_page(const TransformImpl& impl, PagePlanes& out) {
  for (const Block& b : page_blocks().blocks) {
    const int stride = b.plane == 0 ? kPage : kPage / 2;
    int16_t* o = out.plane(b.plane) + size_t(b.by) * 8 * stride + b.bx * 8;
    if (b.nv == 0) {
      idct_dc_block(b.f[0], o, stride);
    } else {
      impl.idct_block(b.f, b.nv, b.nu, o, stride);
    }
  }
}

// Times `step`, which writes to `out`, keeping the compiler from dropping the writes.
template <class Step>
void time_steps(benchmark::State& state, const void* out, Step step) {
  for (auto _ : state) {
    step();
    benchmark::DoNotOptimize(out);
    benchmark::ClobberMemory();
  }
}

void BM_IdctPage(benchmark::State& state, const TransformImpl* impl) {
  PagePlanes planes;
  time_steps(state, planes.y.data(), [&] { idct_page(*impl, planes); });
  state.counters["blocks/page"] = double(page_blocks().blocks.size());
}

// Full-resolution chroma for the 4:4:4 path, from the decoded 4:2:0 planes.
std::vector<int16_t> full_res(const std::vector<int16_t>& c) {
  std::vector<int16_t> f(kPage * kPage);
  for (int y = 0; y < kPage; y++)
    for (int x = 0; x < kPage; x++) f[y * kPage + x] = c[(y / 2) * (kPage / 2) + x / 2];
  return f;
}

// Input and output of the colour benchmarks: the page's planes (scalar IDCT) and a page of
// `ch`-channel texels, the channels not written left at 255.
struct ColourCase {
  explicit ColourCase(int channels) : ch(channels), texels(size_t(kPage) * kPage * ch, 255) {
    idct_page(vt::dct_detail::scalar_transform(), planes);
  }
  int ch;
  PagePlanes planes;
  std::vector<uint8_t> texels;
};

void BM_Colour420Page(benchmark::State& state, const TransformImpl* impl) {
  ColourCase c(int(state.range(0)));
  time_steps(state, c.texels.data(), [&] {
    impl->ycocg420_to_rgb(c.planes.y.data(), kPage, c.planes.co.data(), c.planes.cg.data(),
                          kPage / 2, kPage, kPage, c.ch, c.texels.data());
  });
}

void BM_Colour444Page(benchmark::State& state, const TransformImpl* impl) {
  ColourCase c(int(state.range(0)));
  const std::vector<int16_t> co = full_res(c.planes.co), cg = full_res(c.planes.cg);
  time_steps(state, c.texels.data(), [&] {
    impl->ycocg_to_rgb(c.planes.y.data(), kPage, co.data(), cg.data(), kPage, kPage, kPage, c.ch,
                       c.texels.data());
  });
}

void BM_PlaneToChannel(benchmark::State& state, const TransformImpl* impl) {
  ColourCase c(int(state.range(0)));
  time_steps(state, c.texels.data(), [&] {
    impl->plane_to_channel(c.planes.y.data(), kPage, kPage, kPage, c.ch, c.ch - 1, c.texels.data());
  });
}

void BM_BackEndPage(benchmark::State& state, const TransformImpl* impl) {
  PagePlanes planes;
  std::vector<uint8_t> texels(size_t(kPage) * kPage * 3);
  time_steps(state, texels.data(), [&] {
    idct_page(*impl, planes);
    impl->ycocg420_to_rgb(planes.y.data(), kPage, planes.co.data(), planes.cg.data(), kPage / 2,
                          kPage, kPage, 3, texels.data());
  });
}

}  // namespace

int main(int argc, char** argv) {
  for (const TransformImpl& impl : vt::dct_detail::transform_impls()) {
    const std::string n = impl.name;
    benchmark::RegisterBenchmark(("BM_IdctPage/" + n).c_str(), BM_IdctPage, &impl);
    benchmark::RegisterBenchmark(("BM_Colour420Page/" + n).c_str(), BM_Colour420Page, &impl)
        ->Arg(3)
        ->Arg(4);
    benchmark::RegisterBenchmark(("BM_Colour444Page/" + n).c_str(), BM_Colour444Page, &impl)
        ->Arg(3)
        ->Arg(4);
    benchmark::RegisterBenchmark(("BM_PlaneToChannel/" + n).c_str(), BM_PlaneToChannel, &impl)
        ->Arg(1)
        ->Arg(2)
        ->Arg(4);
    benchmark::RegisterBenchmark(("BM_BackEndPage/" + n).c_str(), BM_BackEndPage, &impl);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
