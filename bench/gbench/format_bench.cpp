// Page-file throughput: the writer (pages/s into a finished, fsync'ed file) and the reader
// (read_stored and read_texels for raw and raw+zstd pages, 1 and 2 threads).
// Reproduce: build/release/bench/format_bench --benchmark_repetitions=5
//            --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <unistd.h>
#include <zstd.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "format/page_file.h"

namespace {

constexpr uint32_t kPagesX = 16, kPagesY = 16;  // level 0: 16x16 pages of 128x128 RGBA8
constexpr uint32_t kPageSize = 128;

vt::PageGeometry geometry() {
  return {kPagesX * 120, kPagesY * 120, 120, 4};
}

// A photo-like page: smooth gradients plus noise, so zstd saves about what it would on albedo.
std::vector<uint8_t> make_texels(uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<uint8_t> t(kPageSize * kPageSize * 4);
  const float fx = 0.02f + (seed % 7) * 0.01f, fy = 0.03f + (seed % 5) * 0.01f;
  for (uint32_t y = 0; y < kPageSize; ++y)
    for (uint32_t x = 0; x < kPageSize; ++x)
      for (uint32_t c = 0; c < 4; ++c) {
        float v = 128 + 90 * std::sin(fx * x * (c + 1) + fy * y) + float(rng() % 9) - 4;
        t[(y * kPageSize + x) * 4 + c] = c == 3 ? 255 : uint8_t(std::clamp(v, 0.f, 255.f));
      }
  return t;
}

struct Pages {
  std::vector<vt::PageId> ids;               // every page of every level
  std::vector<std::vector<uint8_t>> raw, z;  // per page: raw texels and their zstd frame
};

const Pages& pages() {
  static const Pages p = [] {
    Pages p;
    const vt::PageGeometry g = geometry();
    for (uint32_t l = 0; l < g.level_count(); ++l)
      for (uint32_t y = 0; y < g.pages_y(l); ++y)
        for (uint32_t x = 0; x < g.pages_x(l); ++x) {
          p.ids.push_back({l, x, y});
          p.raw.push_back(make_texels(uint32_t(p.ids.size())));
          std::vector<uint8_t> z(ZSTD_compressBound(p.raw.back().size()));
          z.resize(ZSTD_compress(z.data(), z.size(), p.raw.back().data(), p.raw.back().size(), 3));
          p.z.push_back(std::move(z));
        }
    return p;
  }();
  return p;
}

vt::PageFileDesc desc() {
  vt::PageFileDesc d;
  d.geometry = geometry();
  vt::LayerSpec raw;
  raw.name = "raw";
  raw.codec = vt::PageCodec::kRaw;
  vt::LayerSpec z;
  z.name = "zstd";
  z.codec = vt::PageCodec::kRawZstd;
  d.layers = {raw, z};
  return d;
}

std::string bench_dir() {
  static const std::string dir = [] {
    auto d = std::filesystem::temp_directory_path() /
             ("vtbake_format_bench_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d.string();
  }();
  return dir;
}

// Writes every page of both layers with `threads` threads.
vt::Status write(const std::string& path, int threads) {
  const Pages& p = pages();
  auto w = vt::PageFileWriter::create(path, desc());
  if (!w.ok()) return w.status();
  std::vector<std::thread> pool;
  std::vector<vt::Status> status(threads);
  for (int t = 0; t < threads; ++t)
    pool.emplace_back([&, t] {
      for (size_t i = t; i < p.ids.size(); i += threads) {
        vt::Status a = (*w)->add_page(p.ids[i], 0, p.raw[i]);
        vt::Status b = (*w)->add_page(p.ids[i], 1, p.z[i]);
        if (!a.ok()) status[t] = a;
        if (!b.ok()) status[t] = b;
      }
    });
  for (auto& th : pool) th.join();
  for (auto& s : status)
    if (!s.ok()) return s;
  return (*w)->finish();
}

const vt::PageFileReader& reader() {
  static std::unique_ptr<vt::PageFileReader> r = [] {
    const std::string path = bench_dir() + "/read.vtpf";
    vt::Status s = write(path, 2);
    if (!s.ok()) {
      std::fprintf(stderr, "%s\n", s.message().c_str());
      std::abort();
    }
    return std::move(vt::PageFileReader::open(path)).value();
  }();
  return *r;
}

void BM_Write(benchmark::State& state) {
  const int threads = int(state.range(0));
  pages();
  const std::string path = bench_dir() + "/write.vtpf";
  for (auto _ : state) {
    vt::Status s = write(path, threads);
    if (!s.ok()) state.SkipWithError(s.message().c_str());
  }
  const Pages& p = pages();
  uint64_t bytes = 0;
  for (size_t i = 0; i < p.ids.size(); ++i) bytes += p.raw[i].size() + p.z[i].size();
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(p.ids.size()) * 2);
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(bytes));
}
BENCHMARK(BM_Write)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// Each thread walks every page; items are pages, so items_per_second is pages/s in total.
void read_loop(benchmark::State& state, uint32_t layer, bool texels) {
  const vt::PageFileReader& r = reader();
  const Pages& p = pages();
  std::vector<uint8_t> out(r.decoded_page_bytes(layer));
  size_t i = size_t(state.thread_index()) * 7;
  int64_t bytes = 0;
  for (auto _ : state) {
    const vt::PageId& id = p.ids[i++ % p.ids.size()];
    if (texels) {
      vt::Status s = r.read_texels(id, layer, out);
      if (!s.ok()) state.SkipWithError(s.message().c_str());
      bytes += int64_t(out.size());
    } else {
      auto b = r.read_stored(id, layer);
      if (!b.ok()) state.SkipWithError(b.status().message().c_str());
      bytes += int64_t(b->size());
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()));
  state.SetBytesProcessed(bytes);
}

void BM_ReadStoredRaw(benchmark::State& state) {
  read_loop(state, 0, false);
}
void BM_ReadStoredZstd(benchmark::State& state) {
  read_loop(state, 1, false);
}
void BM_ReadTexelsRaw(benchmark::State& state) {
  read_loop(state, 0, true);
}
void BM_ReadTexelsZstd(benchmark::State& state) {
  read_loop(state, 1, true);
}
BENCHMARK(BM_ReadStoredRaw)->Threads(1)->Threads(2)->UseRealTime();
BENCHMARK(BM_ReadStoredZstd)->Threads(1)->Threads(2)->UseRealTime();
BENCHMARK(BM_ReadTexelsRaw)->Threads(1)->Threads(2)->UseRealTime();
BENCHMARK(BM_ReadTexelsZstd)->Threads(1)->Threads(2)->UseRealTime();

void BM_Open(benchmark::State& state) {
  const std::string path = reader().path();
  for (auto _ : state) {
    auto r = vt::PageFileReader::open(path);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_Open)->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::error_code ec;
  std::filesystem::remove_all(bench_dir(), ec);
  return 0;
}
