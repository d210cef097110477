#include "bench/file_decode_bench.h"

#include <time.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "format/layer_codec.h"
#include "format/page_file.h"

namespace vt::bench {
namespace {

double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct StoredPage {
  const PageFileReader* file = nullptr;
  uint32_t layer = 0;
  std::vector<uint8_t> bytes;
};

Expected<BenchReport> run(const BenchRequest& request) {
  VT_ASSIGN_OR_RETURN(int repeats, option_int(request, "repeats", 1, 1000));
  if (request.inputs.empty())
    return Error(ErrorCode::kInvalidArgument, "decode: give one or more .vtpf files");
  std::vector<std::unique_ptr<PageFileReader>> files;
  std::vector<StoredPage> pages;
  uint64_t stored_bytes = 0, texels = 0;
  size_t largest = 0;
  for (const std::string& path : request.inputs) {
    VT_ASSIGN_OR_RETURN(auto reader, PageFileReader::open(path));
    const PageGeometry& g = reader->geometry();
    for (uint32_t layer = 0; layer < reader->layers().size(); ++layer) {
      largest = std::max(largest, reader->decoded_page_bytes(layer));
      for (uint32_t level = 0; level < g.level_count(); ++level) {
        for (uint32_t y = 0; y < g.pages_y(level); ++y) {
          for (uint32_t x = 0; x < g.pages_x(level); ++x) {
            const PageId id{level, x, y};
            VT_ASSIGN_OR_RETURN(PageEntry e, reader->entry(id, layer));
            if (e.state != PageState::kStored) continue;
            VT_ASSIGN_OR_RETURN(std::vector<uint8_t> bytes, reader->read_stored(id, layer));
            stored_bytes += bytes.size();
            texels += uint64_t(g.page_size()) * g.page_size();
            pages.push_back({reader.get(), layer, std::move(bytes)});
          }
        }
      }
    }
    files.push_back(std::move(reader));
  }
  std::vector<uint8_t> out(largest);
  std::vector<double> passes;
  for (int r = 0; r < repeats; ++r) {
    const double t0 = thread_seconds();
    for (const StoredPage& p : pages) {
      const size_t n = p.file->decoded_page_bytes(p.layer);
      VT_RETURN_IF_ERROR(
          p.file->layer_codec(p.layer).decode(p.bytes, std::span<uint8_t>(out.data(), n)));
    }
    passes.push_back(thread_seconds() - t0);
  }
  std::vector<double> sorted = passes;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  const double mtexels = median > 0 ? double(texels) / median / 1e6 : 0;
  const double us_page = pages.empty() ? 0 : median * 1e6 / double(pages.size());
  char line[256];
  std::snprintf(line, sizeof line,
                "files %zu, stored pages %zu, stored bytes %llu: decode %.1f Mtexel/s, %.2f us "
                "per page (median of %d passes, one thread)\n",
                files.size(), pages.size(), (unsigned long long)stored_bytes, mtexels, us_page,
                repeats);
  BenchReport report;
  report.text = line;
  std::snprintf(line, sizeof line,
                "{\"files\":%zu,\"pages\":%zu,\"stored_bytes\":%llu,\"mtexel_per_s\":%.3f,"
                "\"us_per_page\":%.3f,\"repeats\":%d}",
                files.size(), pages.size(), (unsigned long long)stored_bytes, mtexels, us_page,
                repeats);
  report.json = line;
  return report;
}

}  // namespace

BenchKind file_decode_bench_kind() {
  return {"decode",
          "Decode speed of whole page files (every stored page, all levels and layers), one "
          "thread, median pass",
          "Page files (.vtpf)",
          {{"repeats", "Timed passes (median reported)", "5"}},
          run};
}

}  // namespace vt::bench
