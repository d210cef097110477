// The BC6H bench (see bc6h_bench.h).
#include "bench/bc6h_bench.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "codec/bc.h"
#include "codec/bc6h.h"
#include "codec/hdr_metrics.h"
#include "common/half.h"
#include "format/zstd_frame.h"

namespace vt::bench {
namespace {

struct HdrPage {
  std::vector<uint16_t> rgb;  // page^2 texels of 3 halves
};

struct HdrSet {
  std::string name;
  std::vector<HdrPage> pages;
  int width = 0, height = 0;  // the image the pages were cut from (0 for the synthetic set)
};

// Cuts an image (first three channels, half floats) into whole pages.
Expected<HdrSet> load_image(const std::string& path, int page) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return Error(ErrorCode::kIo, path + ": " + OIIO::geterror());
  const OIIO::ImageSpec spec = in->spec();
  std::vector<float> px(size_t(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()))
    return Error(ErrorCode::kIo, path + ": " + in->geterror());
  HdrSet set;
  set.name = path.substr(path.find_last_of('/') + 1);
  set.width = spec.width;
  set.height = spec.height;
  for (int py = 0; py + page <= spec.height; py += page) {
    for (int px0 = 0; px0 + page <= spec.width; px0 += page) {
      HdrPage p;
      p.rgb.resize(size_t(page) * page * 3);
      for (int y = 0; y < page; ++y)
        for (int x = 0; x < page; ++x)
          for (int c = 0; c < 3; ++c) {
            const int sc = std::min(c, spec.nchannels - 1);
            p.rgb[(size_t(y) * page + x) * 3 + c] = float_to_half(
                px[(size_t(py + y) * spec.width + size_t(px0 + x)) * spec.nchannels + sc]);
          }
      set.pages.push_back(std::move(p));
    }
  }
  if (set.pages.empty()) return Error(ErrorCode::kInvalidArgument, path + ": smaller than a page");
  return set;
}

// Synthetic HDR: exponential ramps over 2^-10..2^16 with sine modulation, noise and edges.
HdrSet synthetic(int page, int count) {
  HdrSet set;
  set.name = "synthetic";
  uint32_t s = 12345;
  auto rnd = [&] {
    s ^= s << 13, s ^= s >> 17, s ^= s << 5;
    return double(s % 10001) / 10000.0;
  };
  for (int k = 0; k < count; ++k) {
    HdrPage p;
    p.rgb.resize(size_t(page) * page * 3);
    const double l0 = -10.0 + 26.0 * k / std::max(1, count - 1) - 3.0;
    for (int y = 0; y < page; ++y)
      for (int x = 0; x < page; ++x)
        for (int c = 0; c < 3; ++c) {
          double v = std::exp2(l0 + 6.0 * x / page) *
                     (0.55 + 0.45 * std::sin(0.05 * y + 1.3 * c + k)) * (0.98 + 0.04 * rnd());
          if (((x / 24) + (y / 24)) % 5 == 0) v *= 0.2;
          p.rgb[(size_t(y) * page + x) * 3 + c] = float_to_half(float(std::min(v, 60000.0)));
        }
    set.pages.push_back(std::move(p));
  }
  return set;
}

Expected<std::vector<uint8_t>> read_blocks(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error(ErrorCode::kIo, path + ": cannot open");
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

double thread_seconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Row {
  std::string set, level;
  int pages = 0;
  double encode_mtex_s = 0, decode_mtex_s = 0;
  double raw_zstd_bpt = 0, bc6h_zstd_bpt = 0;  // stored bits per texel: half + zstd, BC6H + zstd
  HdrError err;
  int modes[15] = {};
};

// `reference`: another encoder's blocks of the whole image (row-major, set.width / 4 blocks a
// row), cut into the same pages and scored instead of encoding (no encode time).
Row run_level(const HdrSet& set, int page, BcQuality q, int repeats, int max_pages,
              const std::vector<uint8_t>* reference = nullptr, const std::string& name = "") {
  Row r;
  r.set = set.name;
  r.level = reference                   ? name
            : q == BcQuality::kRealtime ? "realtime"
            : q == BcQuality::kNormal   ? "normal"
                                        : "high";
  const int n =
      max_pages > 0 ? std::min<int>(max_pages, int(set.pages.size())) : int(set.pages.size());
  r.pages = n;
  const size_t bytes = bc_image_bytes(BcFormat::kBc6hUf16, page, page);
  std::vector<uint8_t> blocks(bytes * size_t(n));
  std::vector<double> enc, dec;
  std::vector<uint16_t> back(size_t(page) * page * 3);
  if (reference) {
    // Pages in load_image's order: rows of pages, left to right.
    const int per_row = set.width / page, image_blocks_x = set.width / 4, page_blocks = page / 4;
    for (int i = 0; i < n; ++i) {
      const int px = (i % per_row) * page_blocks, py = (i / per_row) * page_blocks;
      for (int y = 0; y < page_blocks; ++y)
        std::memcpy(&blocks[size_t(i) * bytes + size_t(y) * size_t(page_blocks) * 16],
                    reference->data() + (size_t(py + y) * size_t(image_blocks_x) + size_t(px)) * 16,
                    size_t(page_blocks) * 16);
    }
  }
  for (int pass = 0; pass < repeats; ++pass) {
    double t0 = thread_seconds();
    if (!reference)
      for (int i = 0; i < n; ++i)
        (void)bc6h_encode_image(false, q, set.pages[size_t(i)].rgb.data(), page, page, 3,
                                &blocks[size_t(i) * bytes]);
    enc.push_back(reference ? 0.0 : thread_seconds() - t0);
    t0 = thread_seconds();
    for (int i = 0; i < n; ++i)
      (void)bc6h_decode_image(false, &blocks[size_t(i) * bytes], page, page, 3, back.data());
    dec.push_back(thread_seconds() - t0);
  }
  std::sort(enc.begin(), enc.end());
  std::sort(dec.begin(), dec.end());
  const double texels = double(n) * page * page;
  r.encode_mtex_s = reference ? 0 : texels / std::max(1e-9, enc[enc.size() / 2]) / 1e6;
  r.decode_mtex_s = texels / std::max(1e-9, dec[dec.size() / 2]) / 1e6;
  size_t raw_bytes = 0, bc_bytes = 0;
  std::vector<uint8_t> z;
  for (int i = 0; i < n; ++i) {
    const auto& rgb = set.pages[size_t(i)].rgb;
    (void)zstd_compress(
        std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(rgb.data()), rgb.size() * 2), 3,
        z);
    raw_bytes += z.size();
    (void)zstd_compress(std::span<const uint8_t>(&blocks[size_t(i) * bytes], bytes), 3, z);
    bc_bytes += z.size();
  }
  r.raw_zstd_bpt = 8.0 * double(raw_bytes) / texels;
  r.bc6h_zstd_bpt = 8.0 * double(bc_bytes) / texels;
  for (int i = 0; i < n; ++i) {
    (void)bc6h_decode_image(false, &blocks[size_t(i) * bytes], page, page, 3, back.data());
    add_hdr_error(set.pages[size_t(i)].rgb.data(), back.data(), size_t(page) * page, 3, 3, r.err);
    for (size_t b = 0; b < bytes; b += 16)
      ++r.modes[bc6h_block_mode(&blocks[size_t(i) * bytes + b])];
  }
  return r;
}

// kHigh against the reference search (bc6h_encode_block_reference) on `count` blocks spread
// evenly over the set's pages: both levels' error on the same blocks, and their speed.
struct SearchRow {
  int blocks = 0;
  HdrError high, search;
  double high_mtex_s = 0, search_mtex_s = 0;
};

SearchRow run_search(const HdrSet& set, int page, int count) {
  SearchRow r;
  const int per_page = (page / 4) * (page / 4);
  const int64_t total = int64_t(set.pages.size()) * per_page;
  count = int(std::min<int64_t>(count, total));
  r.blocks = count;
  double th = 0, ts = 0;
  for (int k = 0; k < count; ++k) {
    const int64_t at = total * k / count;  // evenly spread
    const auto& rgb = set.pages[size_t(at / per_page)].rgb;
    const int bi = int(at % per_page), bx = bi % (page / 4), by = bi / (page / 4);
    uint16_t src[48], back[48];
    for (int t = 0; t < 16; ++t)
      for (int c = 0; c < 3; ++c)
        src[3 * t + c] =
            rgb[(size_t(by * 4 + t / 4) * size_t(page) + size_t(bx * 4 + t % 4)) * 3 + size_t(c)];
    uint8_t block[16];
    double t0 = thread_seconds();
    bc6h_encode_block(src, false, BcQuality::kHigh, block);
    th += thread_seconds() - t0;
    bc6h_decode_block(block, false, back);
    add_hdr_error(src, back, 16, 3, 3, r.high);
    t0 = thread_seconds();
    bc6h_encode_block_reference(src, false, block);
    ts += thread_seconds() - t0;
    bc6h_decode_block(block, false, back);
    add_hdr_error(src, back, 16, 3, 3, r.search);
  }
  r.high_mtex_s = 16.0 * count / std::max(1e-9, th) / 1e6;
  r.search_mtex_s = 16.0 * count / std::max(1e-9, ts) / 1e6;
  return r;
}

}  // namespace

BenchKind bc6h_bench_kind() {
  BenchKind k;
  k.name = "bc6h";
  k.description =
      "BC6H (unsigned) encoder levels on HDR pages: Mtexel/s per core, log2 error and tone-mapped "
      "PSNR after BC6H, modes used";
  k.inputs_help = "EXR/HDR images (none: a synthetic HDR set)";
  k.options = {{"page-size", "Page edge in texels", "128"},
               {"repeats", "Timed passes per level (median)", "3"},
               {"high-pages", "Pages per image for the slow levels (normal, high); 0 = all", "8"},
               {"reference-blocks",
                "Folder of another encoder's BC6H blocks, NAME.bc6h per input NAME.exr (raw, "
                "row-major): scored as one more level on the same pages",
                ""},
               {"reference-name", "Name of that level in the report", "reference"},
               {"search-blocks",
                "Blocks per image (spread over its pages) encoded at high and by the reference "
                "search (all modes and partitions, wide endpoint steps); 0 = none",
                "0"}};
  k.run = [](const BenchRequest& req) -> Expected<BenchReport> {
    VT_ASSIGN_OR_RETURN(int page, option_int(req, "page-size", 4, 4096));
    if (page % 4) return Error(ErrorCode::kInvalidArgument, "--page-size: a multiple of 4");
    VT_ASSIGN_OR_RETURN(int repeats, option_int(req, "repeats", 1, 100));
    VT_ASSIGN_OR_RETURN(int slow_pages, option_int(req, "high-pages", 0, 1 << 20));
    std::vector<HdrSet> sets;
    for (const std::string& path : req.inputs) {
      VT_ASSIGN_OR_RETURN(HdrSet s, load_image(path, page));
      sets.push_back(std::move(s));
    }
    if (sets.empty()) sets.push_back(synthetic(page, 16));
    std::ostringstream text;
    nlohmann::json json = nlohmann::json::array();
    char line[320];
    text << "BC6H unsigned, pages of " << page << "x" << page
         << ", one thread (thread CPU time, median of " << repeats
         << "); error vs the half-float page: log2(1+x) mean/max, tone-mapped PSNR "
            "(srgb(x/(1+x)), peak 1), largest relative error\n";
    text << "  set                 level     pages  enc Mtex/s  dec Mtex/s  log2 mean  log2 max  "
            "TM PSNR dB  half+zstd b/t  bc6h+zstd b/t  modes (1-14)\n";
    VT_ASSIGN_OR_RETURN(int search_blocks, option_int(req, "search-blocks", 0, 1 << 20));
    const std::string ref_dir = req.values.at("reference-blocks");
    const std::string ref_name = req.values.at("reference-name");
    const int levels = ref_dir.empty() ? 3 : 4;
    HdrError total[4], search_high, search_ref;
    for (const HdrSet& s : sets) {
      std::vector<uint8_t> ref;
      if (!ref_dir.empty()) {
        if (s.width == 0)
          return Error(ErrorCode::kInvalidArgument, "--reference-blocks: no images");
        const std::string stem = s.name.substr(0, s.name.find_last_of('.'));
        VT_ASSIGN_OR_RETURN(ref, read_blocks(ref_dir + "/" + stem + ".bc6h"));
        if (s.width % page || s.height % page ||
            ref.size() != bc_image_bytes(BcFormat::kBc6hUf16, s.width, s.height))
          return Error(ErrorCode::kInvalidArgument,
                       ref_dir + "/" + stem + ".bc6h: not the BC6H blocks of a " +
                           std::to_string(s.width) + "x" + std::to_string(s.height) +
                           " image cut into whole pages");
      }
      for (int level = 0; level < levels; ++level) {
        const BcQuality q = level == 3 ? BcQuality::kHigh : BcQuality(level);
        if (req.progress) req.progress(s.name + " " + std::to_string(level));
        const int cap = q == BcQuality::kRealtime ? 0 : slow_pages;
        const Row r = level == 3
                          ? run_level(s, page, q, 1, cap, &ref, ref_name)
                          : run_level(s, page, q, q == BcQuality::kRealtime ? repeats : 1, cap);
        total[level].add(r.err);
        std::string modes;
        for (int m = 1; m <= 14; ++m)
          if (r.modes[m]) modes += std::to_string(m) + ":" + std::to_string(r.modes[m]) + " ";
        std::snprintf(
            line, sizeof line,
            "  %-19s %-9s %5d  %10.2f  %10.1f  %9.5f  %8.4f  %10.2f  %13.2f  %13.2f  %s\n",
            r.set.c_str(), r.level.c_str(), r.pages, r.encode_mtex_s, r.decode_mtex_s,
            r.err.log_abs_mean(), r.err.log_abs_max, r.err.tonemapped_psnr_db(), r.raw_zstd_bpt,
            r.bc6h_zstd_bpt, modes.c_str());
        text << line;
        json.push_back({{"set", r.set},
                        {"level", r.level},
                        {"pages", r.pages},
                        {"encode_mtexel_s", r.encode_mtex_s},
                        {"decode_mtexel_s", r.decode_mtex_s},
                        {"log2_error_mean", r.err.log_abs_mean()},
                        {"log2_error_max", r.err.log_abs_max},
                        {"tonemapped_psnr_db", r.err.tonemapped_psnr_db()},
                        {"relative_error_max", r.err.relative_max},
                        {"half_zstd_bits_per_texel", r.raw_zstd_bpt},
                        {"bc6h_zstd_bits_per_texel", r.bc6h_zstd_bpt}});
      }
      if (search_blocks > 0) {
        if (req.progress) req.progress(s.name + " search");
        const SearchRow sr = run_search(s, page, search_blocks);
        search_high.add(sr.high);
        search_ref.add(sr.search);
        std::snprintf(line, sizeof line,
                      "  %-19s %-9s %5d blocks: high %.2f dB TM / log2 mean %.5f (%.3f Mtex/s), "
                      "search %.2f dB / %.5f (%.4f Mtex/s)\n",
                      s.name.c_str(), "sample", sr.blocks, sr.high.tonemapped_psnr_db(),
                      sr.high.log_abs_mean(), sr.high_mtex_s, sr.search.tonemapped_psnr_db(),
                      sr.search.log_abs_mean(), sr.search_mtex_s);
        text << line;
        json.push_back({{"set", s.name},
                        {"level", "search-sample"},
                        {"blocks", sr.blocks},
                        {"high_tonemapped_psnr_db", sr.high.tonemapped_psnr_db()},
                        {"high_log2_error_mean", sr.high.log_abs_mean()},
                        {"search_tonemapped_psnr_db", sr.search.tonemapped_psnr_db()},
                        {"search_log2_error_mean", sr.search.log_abs_mean()},
                        {"high_mtexel_s", sr.high_mtex_s},
                        {"search_mtexel_s", sr.search_mtex_s}});
      }
    }
    if (sets.size() > 1) {
      const std::string names[4] = {"realtime", "normal", "high", ref_name};
      for (int q = 0; q < levels; ++q) {
        std::snprintf(line, sizeof line, "  %-19s %-9s %5s  %10s  %10s  %9.5f  %8.4f  %10.2f\n",
                      "all (pooled)", names[q].c_str(), "", "", "", total[q].log_abs_mean(),
                      total[q].log_abs_max, total[q].tonemapped_psnr_db());
        text << line;
      }
    }
    if (search_blocks > 0 && sets.size() > 1) {
      std::snprintf(
          line, sizeof line,
          "  %-19s %-9s pooled: high %.2f dB TM / log2 mean %.5f, search %.2f dB / %.5f\n",
          "all (pooled)", "sample", search_high.tonemapped_psnr_db(), search_high.log_abs_mean(),
          search_ref.tonemapped_psnr_db(), search_ref.log_abs_mean());
      text << line;
    }
    return BenchReport{text.str(), json.dump(2)};
  };
  return k;
}

}  // namespace vt::bench
