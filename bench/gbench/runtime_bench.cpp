// Runtime benchmarks (docs/BENCHMARKS.md): pages per second from page file to BC-ready
// upload buffer (1 and 2 loader threads, per stored codec), feedback resolve time for a
// 1920x1080 buffer, and page-table update time per mapped page.
//
// Page content is procedural (smooth gradients plus fine noise, roughly photo-like for the
// DCT); the files are written once to $TMPDIR at start-up.
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <unistd.h>
#include <zstd.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <random>

#include "codec/bc.h"
#include "codec/dct.h"
#include "format/page_file.h"
#include "runtime/feedback.h"
#include "runtime/page_loader.h"
#include "runtime/page_source.h"
#include "runtime/page_table.h"
#include "runtime/streamer.h"

namespace vt {
namespace {

constexpr uint32_t kPagesPerSide = 16;  // 16 x 16 pages of 128² at level 0 (1920² texels)

std::vector<uint8_t> content(const PageId& id, uint32_t size, uint32_t channels) {
  std::vector<uint8_t> t(size_t(size) * size * channels);
  std::mt19937 rng(id.x * 131 + id.y * 7 + id.level);
  for (uint32_t y = 0; y < size; ++y)
    for (uint32_t x = 0; x < size; ++x)
      for (uint32_t c = 0; c < channels; ++c) {
        const double v = 128 + 70 * std::sin(0.05 * x + 0.031 * y * (c + 1) + id.x) +
                         30 * std::cos(0.21 * (x - y) + id.y + c) + double(rng() % 17) - 8;
        t[(size_t(y) * size + x) * channels + c] = uint8_t(std::clamp(v, 0.0, 255.0));
      }
  return t;
}

std::vector<uint8_t> zstd(const std::vector<uint8_t>& in) {
  std::vector<uint8_t> out(ZSTD_compressBound(in.size()));
  out.resize(ZSTD_compress(out.data(), out.size(), in.data(), in.size(), 3));
  return out;
}

enum Kind { kDctToBc1, kBc1Zstd, kRawToRgba8, kRawToBc1 };
const char* kKindNames[] = {"dct_q75_to_bc1", "bc1_zstd_passthrough", "raw_zstd_to_rgba8",
                            "raw_zstd_to_bc1"};

std::string make_file(Kind kind) {
  PageGeometry g;
  g.width = g.height = kPagesPerSide * 120;
  PageFileDesc desc;
  desc.geometry = g;
  LayerSpec layer;
  layer.name = "albedo";
  layer.channels = 3;
  const uint32_t ps = g.page_size();
  DctTablesPtr tables;
  switch (kind) {
    case kDctToBc1: {
      layer.codec = PageCodec::kDct;
      layer.runtime_format = RuntimeFormat::kBc1;
      DctSettings s;  // q75, YCoCg 4:2:0
      std::vector<std::vector<uint8_t>> train;
      std::vector<std::span<const uint8_t>> spans;
      for (uint32_t i = 0; i < 4; ++i) train.push_back(content({0, i, i}, ps, 3));
      for (auto& t : train) spans.push_back(t);
      tables = std::move(dct_make_tables(s, int(ps), int(ps), spans)).value();
      layer.codec_tables = dct_serialize_tables(*tables);
      break;
    }
    case kBc1Zstd:
      layer.codec = PageCodec::kBcZstd;
      layer.runtime_format = RuntimeFormat::kBc1;
      break;
    case kRawToRgba8:
      layer.codec = PageCodec::kRawZstd;
      layer.runtime_format = RuntimeFormat::kRgba8;
      break;
    case kRawToBc1:
      layer.codec = PageCodec::kRawZstd;
      layer.runtime_format = RuntimeFormat::kBc1;
      break;
  }
  desc.layers = {layer};
  const auto dir = std::filesystem::temp_directory_path() /
                   ("vtbake_runtime_bench_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / (std::string(kKindNames[kind]) + ".vtpf")).string();
  auto w = std::move(PageFileWriter::create(path, desc)).value();
  for (uint32_t l = 0; l < g.level_count(); ++l)
    for (uint32_t y = 0; y < g.pages_y(l); ++y)
      for (uint32_t x = 0; x < g.pages_x(l); ++x) {
        const PageId id{l, x, y};
        const auto texels = content(id, ps, 3);
        std::vector<uint8_t> data;
        if (kind == kDctToBc1) {
          (void)dct_encode_page(*tables, texels.data(), int(ps), int(ps), data);
        } else if (kind == kBc1Zstd) {
          std::vector<uint8_t> blocks(bc_image_bytes(BcFormat::kBc1, int(ps), int(ps)));
          (void)bc_encode_image(BcFormat::kBc1, BcQuality::kNormal, texels.data(), int(ps), int(ps),
                                3, blocks.data());
          data = zstd(blocks);
        } else {
          data = zstd(texels);
        }
        (void)w->add_page(id, 0, data);
      }
  (void)w->finish();
  return path;
}

std::shared_ptr<const PageSource> source_for(Kind kind) {
  static std::map<int, std::shared_ptr<const PageSource>> cache;
  auto& s = cache[kind];
  if (!s) {
    auto reader = PageFileReader::open(make_file(kind));
    if (!reader.ok()) return nullptr;
    s = std::move(make_page_file_source(std::shared_ptr<const PageFileReader>(std::move(*reader))))
            .value();
  }
  return s;
}

double process_cpu_seconds() {
  rusage u;
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// All 256 level-0 pages through the loader per iteration; reports pages/s (wall clock) and
// pages per CPU second of the whole process (all worker threads): on a shared machine the
// latter shows the work per page and the locking overhead of more threads, the former what
// the machine happened to give.
void BM_LoadPages(benchmark::State& state) {
  const Kind kind = Kind(state.range(0));
  const uint32_t threads = uint32_t(state.range(1));
  auto src = source_for(kind);
  if (!src) {
    state.SkipWithError("cannot build the page file");
    return;
  }
  LoaderOptions o;
  o.threads = threads;
  o.max_in_flight = kPagesPerSide * kPagesPerSide;
  auto loader = std::move(PageLoader::create(src, o)).value();
  std::vector<LoadedPage> done;
  int64_t pages = 0;
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    for (uint32_t y = 0; y < kPagesPerSide; ++y)
      for (uint32_t x = 0; x < kPagesPerSide; ++x) loader->request({0, x, y}, {0, 1});
    loader->wait_idle();
    done.clear();
    loader->collect(done);
    for (auto& p : done)
      if (!p.status.ok()) state.SkipWithError(p.status.message().c_str());
    pages += int64_t(done.size());
  }
  state.counters["pages_per_s"] = benchmark::Counter(double(pages), benchmark::Counter::kIsRate);
  state.counters["pages_per_cpu_s"] = double(pages) / std::max(process_cpu_seconds() - cpu0, 1e-9);
  state.SetLabel(kKindNames[kind]);
}
BENCHMARK(BM_LoadPages)
    ->ArgsProduct({{kDctToBc1, kBc1Zstd, kRawToRgba8, kRawToBc1}, {1, 2}})
    ->ArgNames({"kind", "threads"})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// A presence-only source of 512 x 512 pages at level 0 (61,440² texels) for the resolver.
class GridSource final : public PageSource {
 public:
  GridSource() {
    g_.width = g_.height = kSide * 120;
    levels_ = g_.level_count();
  }
  const PageGeometry& geometry() const override { return g_; }
  uint32_t layer_count() const override { return 1; }
  RuntimeFormat upload_format(uint32_t) const override { return RuntimeFormat::kRgba8; }
  size_t upload_bytes(uint32_t) const override { return 4; }
  // Every page: a bounds test as cheap as the page file's presence bit (PageFileSource keeps
  // its level sizes), not PageGeometry::contains's walk down the levels.
  bool present(const PageId& id) const override {
    return id.level < levels_ && id.x < (kSide >> id.level) && id.y < (kSide >> id.level);
  }
  Status load(const PageId&, uint32_t, std::span<uint8_t>) const override { return {}; }

 private:
  static constexpr uint32_t kSide = 512;  // pages at level 0, a power of two
  PageGeometry g_;
  uint32_t levels_ = 0;
};

// A ground plane seen by a camera 1.7 m above it (focal length 1000 px, horizon at 1/3 of the
// height, sky = background); the texture covers 100 m x 100 m and repeats. The level is the
// trilinear LOD (log2 of the larger texel footprint per pixel), as the feedback pass writes it.
std::vector<uint32_t> ground_plane_feedback(const PageGeometry& g, uint32_t w, uint32_t h) {
  std::vector<uint32_t> fb(size_t(w) * h, kFeedbackNone);
  const double cam = 1.7, f = 1000.0, horizon = h / 3.0, size_m = 100.0;
  for (uint32_t y = 0; y < h; ++y) {
    const double dy = y + 0.5 - horizon;
    if (dy <= 0) continue;
    const double z = cam * f / dy;
    const double dudx = g.width / size_m * z / f;               // texels per pixel, across
    const double dvdy = g.height / size_m * z * z / (cam * f);  // texels per pixel, along
    const double lod = std::log2(std::max({dudx, dvdy, 1.0}));
    const uint32_t level = uint32_t(std::min(lod, double(g.level_count() - 1)));
    const double v = z / size_m;
    for (uint32_t x = 0; x < w; ++x) {
      const double u = (x + 0.5 - w / 2.0) * z / f / size_m + 0.5;
      const double uu = u - std::floor(u), vv = v - std::floor(v);
      const uint32_t px =
          std::min(uint32_t(uu * g.level_width(level) / g.payload), g.pages_x(level) - 1);
      const uint32_t py =
          std::min(uint32_t(vv * g.level_height(level) / g.payload), g.pages_y(level) - 1);
      fb[size_t(y) * w + x] = feedback_pack(level, px, py);
    }
  }
  return fb;
}

void BM_ResolveFeedback1080p(benchmark::State& state) {
  GridSource src;
  FeedbackResolver resolver(src);
  std::vector<uint32_t> fb = ground_plane_feedback(src.geometry(), 1920, 1080);
  const char* labels[] = {"ground_plane", "atlas_16px_tiles", "random_no_runs"};
  if (state.range(0) == 1) {
    // Many small charts: 16 x 16-pixel tiles, each a random page of levels 0-2 (~8,000
    // distinct values, runs of 16 pixels).
    std::mt19937 rng(1);
    std::vector<uint32_t> tiles(120 * 68);
    for (auto& t : tiles) t = feedback_pack(rng() % 3, rng() % 128, rng() % 128);
    for (uint32_t y = 0; y < 1080; ++y)
      for (uint32_t x = 0; x < 1920; ++x) fb[size_t(y) * 1920 + x] = tiles[(y / 16) * 120 + x / 16];
  } else if (state.range(0) == 2) {
    // Pathological: no runs at all, 16,384 distinct values in random order.
    std::mt19937 rng(1);
    for (auto& v : fb) v = feedback_pack(rng() % 2, rng() % 128, rng() % 64);
  }
  std::vector<PageRequest> out;
  ResolveStats st;
  for (auto _ : state) {
    st = resolver.resolve(fb, 0, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["unique_values"] = st.unique_values;
  state.counters["pages_out"] = double(out.size());
  state.SetLabel(labels[state.range(0)]);
}
BENCHMARK(BM_ResolveFeedback1080p)->DenseRange(0, 2)->Unit(benchmark::kMicrosecond);

// Map + unmap of random leaf pages at `level` under a resident root, in a 512 x 512-page
// table: the per-page cost of keeping the table current.
void BM_PageTableMapUnmap(benchmark::State& state) {
  GridSource src;
  const PageGeometry& g = src.geometry();
  PageTable table(g);
  table.map({g.level_count() - 1, 0, 0}, 0, 0);
  const uint32_t level = uint32_t(state.range(0));
  std::mt19937 rng(2);
  std::vector<PageId> ids(4096);
  for (auto& id : ids)
    id = {level, uint32_t(rng() % g.pages_x(level)), uint32_t(rng() % g.pages_y(level))};
  size_t i = 0;
  for (auto _ : state) {
    const PageId& id = ids[i++ & 4095];
    table.map(id, 1, 2);
    table.unmap(id);
  }
  state.SetItemsProcessed(state.iterations() * 2);
}
BENCHMARK(BM_PageTableMapUnmap)->Arg(0)->Arg(2)->Arg(4)->Unit(benchmark::kNanosecond);

// Steady state of one frame: resolve the 1080p ground-plane buffer, refresh LRU ages, nothing
// to load (every needed page resident in a 32 x 32-slot cache). The per-frame CPU cost the
// engine pays on its render thread besides the resolve.
void BM_StreamerUpdateSteady1080p(benchmark::State& state) {
  auto src = std::make_shared<GridSource>();
  StreamerOptions o;
  o.max_in_flight = 256;
  auto s = std::move(Streamer::create(src, o)).value();
  const auto fb = ground_plane_feedback(src->geometry(), 1920, 1080);
  for (int f = 0; f < 50; ++f) {
    s->update(fb);
    s->take_uploads();
    s->wait_idle();
  }
  FrameStats st;
  for (auto _ : state) st = s->update(fb);
  state.counters["needed"] = st.needed;
  state.counters["hits"] = st.resident_hits;
}
BENCHMARK(BM_StreamerUpdateSteady1080p)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace vt

BENCHMARK_MAIN();
