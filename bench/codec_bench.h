// `vtbake-bench codec`: accuracy versus time of the page and block codecs on real images cut
// into pages. For every setting: bits per texel, PSNR, single-threaded encode and decode speed;
// for the page codecs also the runtime path (page decode + BC1 encode) in pages/s per core and
// the PSNR after BC1. Compared in the same run with libjpeg-turbo (per-page abbreviated streams
// sharing one table set) and stb_dxt (BC1/BC3).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "bench/registry.h"
#include "common/status.h"

namespace vt::bench {

struct CodecBenchOptions {
  std::vector<std::string> images;  // read with OpenImageIO; names containing "normal" are
                                    // normal maps (BC5 + angular error), the rest colour
  int page_size = 128;
  std::vector<int> dct_qualities = {25, 50, 75, 90, 95};
  std::vector<int> jpeg_qualities = {25, 50, 75, 90, 95};
  int repeats = 3;      // timed passes per setting; the median is reported
  int slow_pages = 48;  // pages used for settings slower than ~1 Mtexel/s
  int max_pages = 0;    // 0 = every page of every image
};

struct CodecBenchRow {
  std::string section;  // "page", "runtime", "bc", "normal"
  std::string name;     // e.g. "BC1 vtbake realtime", "DCT q75"
  int pages = 0;
  double bits_per_texel = 0;
  double psnr = 0;           // mean over images of each image's PSNR (RGB)
  double psnr_pooled = 0;    // PSNR of the MSE pooled over every page
  double encode_mtex_s = 0;  // 0 when not measured
  double decode_mtex_s = 0;
  double pages_per_s = 0;     // runtime rows: page decode + BC1 encode
  double psnr_after_bc1 = 0;  // runtime rows
  double angle_mean_deg = 0, angle_max_deg = 0, angle_p99_deg = 0;  // normal rows
  double seconds_per_mtex = 0;  // encode time, for the accuracy-versus-time summary
};

struct CodecBenchResult {
  int colour_pages = 0, normal_pages = 0;
  std::vector<CodecBenchRow> rows;
  // DCT bytes / JPEG bytes at equal PSNR, per DCT quality inside JPEG's PSNR range.
  std::vector<std::pair<int, double>> equal_psnr_bytes_ratio;
};

Expected<CodecBenchResult> run_codec_bench(
    const CodecBenchOptions& options, const std::function<void(const std::string&)>& progress = {});
std::string codec_bench_text(const CodecBenchResult& result);
std::string codec_bench_json(const CodecBenchResult& result);

BenchKind codec_bench_kind();

}  // namespace vt::bench
