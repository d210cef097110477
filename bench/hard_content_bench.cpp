// The hard-content benchmark (see hard_content_bench.h).
#include "bench/hard_content_bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <nlohmann/json.hpp>
#include <sstream>

#include "codec/dct.h"
#include "codec/runtime_error.h"
#include "common/hash.h"
#include "format/dct_page_modes.h"
#include "format/zstd_frame.h"

namespace vt::bench {
namespace {

constexpr int kPagesPerCase = 6;

struct Case {
  std::string name;
  int channels = 3;
  DctPlaneLayout layout = DctPlaneLayout::kYCoCg420;
  BcFormat bc = BcFormat::kBc1;
  bool normal = false;
  std::vector<std::vector<uint8_t>> pages;
};

// The top `n` (<= 31) of Lcg64::next()'s 31 random bits: 0 .. 2^n - 1. (next() is s >> 33:
// its bit 31 is always 0, so `next() >> 31` is always 0 and a shift of 32 or more is undefined;
// GCC folded the first version's 64-bit shifts to 0, which made text/UI a blank panel and
// pixel art black.)
uint32_t bits(Lcg64& rng, int n) {
  return rng.next() >> (31 - n);
}

void put(std::vector<uint8_t>& p, int size, int ch, int x, int y, const uint8_t* v) {
  std::copy(v, v + ch, &p[(size_t(y) * size + x) * ch]);
}

// Each generator fills page `i` (size x size, `ch` channels) from its own seed.
std::vector<uint8_t> checker(int size, int i) {
  std::vector<uint8_t> p(size_t(size) * size * 3);
  const int cell = 4 << (i % 3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const bool red = ((x + i) / cell + y / cell) % 2 == 0;
      const uint8_t v[3] = {uint8_t(red ? 255 : 0), 0, uint8_t(red ? 0 : 255)};
      put(p, size, 3, x, y, v);
    }
  return p;
}

// Dark strokes on light panels, coloured UI boxes with one-texel borders.
std::vector<uint8_t> text_atlas(int size, int i) {
  Lcg64 rng{uint64_t(100 + i)};
  std::vector<uint8_t> p(size_t(size) * size * 3, 235);
  for (int b = 0; b < 3; ++b) {
    const int x0 = int(bits(rng, 6)), y0 = int(bits(rng, 6));
    const int w = 24 + int(bits(rng, 5)), h = 12 + int(bits(rng, 4));
    const uint8_t fill[3] = {uint8_t(bits(rng, 8)), uint8_t(bits(rng, 8)), uint8_t(bits(rng, 8))};
    const uint8_t edge[3] = {20, 20, 20};
    for (int y = y0; y < std::min(size, y0 + h); ++y)
      for (int x = x0; x < std::min(size, x0 + w); ++x)
        put(p, size, 3, x, y,
            y == y0 || x == x0 || y == y0 + h - 1 || x == x0 + w - 1 ? edge : fill);
  }
  for (int cy = 2; cy + 8 <= size; cy += 10)
    for (int cx = 2; cx + 6 <= size; cx += 7) {
      if (bits(rng, 2) == 0) continue;  // spaces, one in four
      const uint8_t ink[3] = {15, 15, uint8_t(40 * (i % 3))};
      for (int s = 0; s < 3; ++s) {
        const bool horizontal = bits(rng, 1);
        const int o = int(bits(rng, 3)) % (horizontal ? 8 : 6);
        for (int k = 0; k < (horizontal ? 6 : 8); ++k)
          put(p, size, 3, horizontal ? cx + k : cx + o, horizontal ? cy + o : cy + k, ink);
      }
    }
  return p;
}

// Saturated shapes with alpha 0 or 255 on a transparent background.
std::vector<uint8_t> decal(int size, int i) {
  std::vector<uint8_t> p(size_t(size) * size * 4, 0);
  const double cx = size * (0.4 + 0.05 * i), cy = size * 0.5, r = size * 0.3;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double dx = x - cx, dy = y - cy;
      const bool star = std::hypot(dx, dy) < r * (0.6 + 0.4 * std::cos(5 * std::atan2(dy, dx)));
      const bool stripe = ((x + y + 3 * i) / 6) % 2 == 0;
      const uint8_t v[4] = {uint8_t(star ? (stripe ? 250 : 30) : 0),
                            uint8_t(star ? (stripe ? 40 : 200) : 0), uint8_t(star ? 20 : 0),
                            uint8_t(star ? 255 : 0)};
      put(p, size, 4, x, y, v);
    }
  return p;
}

// 16-colour saturated palette, 4x4 texel "pixels".
std::vector<uint8_t> pixel_art(int size, int i) {
  Lcg64 rng{uint64_t(200 + i)};
  uint8_t palette[16][3];
  for (auto& c : palette)
    for (int k = 0; k < 3; ++k) c[k] = bits(rng, 1) ? 255 : uint8_t(bits(rng, 2) * 60);
  std::vector<uint8_t> p(size_t(size) * size * 3);
  std::vector<int> cells(size_t(size / 4) * (size / 4));
  for (size_t k = 0; k < cells.size(); ++k)
    cells[k] = (k > 0 && bits(rng, 2) != 0) ? cells[k - 1] : int(bits(rng, 4));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      put(p, size, 3, x, y, palette[cells[size_t(y / 4) * (size / 4) + x / 4]]);
  return p;
}

// Fully saturated hue sweeps.
std::vector<uint8_t> saturated_gradient(int size, int i) {
  std::vector<uint8_t> p(size_t(size) * size * 3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double h = std::fmod((x + y * (i % 2 ? 0.5 : 0.0)) * 6.0 / size + i, 6.0);
      const double f = h - std::floor(h);
      double rgb[3];
      switch (int(h)) {
        case 0:
          rgb[0] = 1, rgb[1] = f, rgb[2] = 0;
          break;
        case 1:
          rgb[0] = 1 - f, rgb[1] = 1, rgb[2] = 0;
          break;
        case 2:
          rgb[0] = 0, rgb[1] = 1, rgb[2] = f;
          break;
        case 3:
          rgb[0] = 0, rgb[1] = 1 - f, rgb[2] = 1;
          break;
        case 4:
          rgb[0] = f, rgb[1] = 0, rgb[2] = 1;
          break;
        default:
          rgb[0] = 1, rgb[1] = 0, rgb[2] = 1 - f;
          break;
      }
      const uint8_t v[3] = {uint8_t(255 * rgb[0] + 0.5), uint8_t(255 * rgb[1] + 0.5),
                            uint8_t(255 * rgb[2] + 0.5)};
      put(p, size, 3, x, y, v);
    }
  return p;
}

// Tangent-space XY of pyramids and bevels: the normal flips across each crease.
std::vector<uint8_t> crease_normals(int size, int i) {
  std::vector<uint8_t> p(size_t(size) * size * 2);
  const int tile = 16 << (i % 2);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const int lx = x % tile - tile / 2, ly = y % tile - tile / 2;
      const double slope = 0.35 + 0.1 * (i % 3);
      double nx = 0, ny = 0;
      if (std::abs(lx) > std::abs(ly))
        nx = lx > 0 ? slope : -slope;
      else
        ny = ly > 0 ? slope : -slope;
      const uint8_t v[2] = {uint8_t(std::lround((nx + 1) * 127.5)),
                            uint8_t(std::lround((ny + 1) * 127.5))};
      put(p, size, 2, x, y, v);
    }
  return p;
}

std::vector<Case> make_cases(int size) {
  std::vector<Case> cases = {
      {"checker", 3, DctPlaneLayout::kYCoCg420, BcFormat::kBc1, false, {}},
      {"text/UI atlas", 3, DctPlaneLayout::kYCoCg420, BcFormat::kBc1, false, {}},
      {"hard-alpha decal", 4, DctPlaneLayout::kYCoCg420, BcFormat::kBc3, false, {}},
      {"pixel art", 3, DctPlaneLayout::kYCoCg420, BcFormat::kBc1, false, {}},
      {"saturated gradient", 3, DctPlaneLayout::kYCoCg420, BcFormat::kBc1, false, {}},
      {"crease normals", 2, DctPlaneLayout::kPlanes, BcFormat::kBc5, true, {}},
  };
  using Gen = std::vector<uint8_t> (*)(int, int);
  const Gen gens[] = {checker, text_atlas, decal, pixel_art, saturated_gradient, crease_normals};
  for (size_t c = 0; c < cases.size(); ++c)
    for (int i = 0; i < kPagesPerCase; ++i) cases[c].pages.push_back(gens[c](size, i));
  return cases;
}

double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Row {
  std::string setting;
  size_t bytes = 0;        // the pages' (a file holds the tables once per layer)
  size_t table_bytes = 0;  // the layer's trained DCT tables
  double stored_psnr = 0;
  RuntimeError runtime;
  double worst_page_over_lossless = 0;  // largest page bytes / its lossless bytes
  double encode_ms_per_page = 0;
  uint64_t modes[kDctModeKinds] = {};
};

double psnr(double sse, double n) {
  return sse <= 0 ? INFINITY : 10 * std::log10(255.0 * 255.0 * n / sse);
}

// `quality` 0: the lossless reference (raw + zstd, then BC).
Expected<Row> run_setting(const Case& c, int size, int quality, bool modes) {
  Row row;
  std::unique_ptr<DctTables, DctTablesDeleter> tables;
  if (quality > 0) {
    std::vector<std::span<const uint8_t>> training(c.pages.begin(), c.pages.end());
    VT_ASSIGN_OR_RETURN(tables,
                        dct_make_tables({quality, c.channels, c.layout}, size, size, training));
    row.table_bytes = dct_serialize_tables(*tables).size();
  }
  row.setting =
      quality == 0 ? "lossless + BC" : "DCT q" + std::to_string(quality) + (modes ? " modes" : "");
  double sse = 0, n = 0, seconds = 0;
  const size_t page_bytes = size_t(size) * size * c.channels;
  std::vector<uint8_t> out, decoded(page_bytes), lossless;
  for (const auto& page : c.pages) {
    VT_RETURN_IF_ERROR(zstd_compress(page, 3, lossless));
    const double t0 = thread_seconds();
    uint8_t mode = kDctModeLossless;
    if (quality > 0) {
      VT_ASSIGN_OR_RETURN(mode, dct_encode_page_modes(*tables, page.data(), size, c.channels,
                                                      {modes, 0, 3}, out, decoded.data()));
    } else {
      out.assign(1, kDctPageLossless);
      out.insert(out.end(), lossless.begin(), lossless.end());
      decoded = page;
    }
    seconds += thread_seconds() - t0;
    ++row.modes[mode];
    row.bytes += out.size();
    row.worst_page_over_lossless =
        std::max(row.worst_page_over_lossless, double(out.size()) / double(lossless.size() + 1));
    for (size_t k = 0; k < page_bytes; ++k) {
      const double d = double(page[k]) - decoded[k];
      sse += d * d;
    }
    n += double(page_bytes);
    RuntimeError r;
    VT_RETURN_IF_ERROR(measure_runtime_error(c.bc, c.normal, page.data(), decoded.data(), nullptr,
                                             size, c.channels, r));
    row.runtime.add(r);
  }
  row.stored_psnr = psnr(sse, n);
  row.encode_ms_per_page = 1e3 * seconds / double(c.pages.size());
  return row;
}

std::string fmt_db(double v) {
  char b[32];
  if (std::isfinite(v)) {
    std::snprintf(b, sizeof b, "%.2f", v);
  } else {
    std::snprintf(b, sizeof b, "exact");
  }
  return b;
}

}  // namespace

BenchKind hard_content_bench_kind() {
  BenchKind k;
  k.name = "hard";
  k.description =
      "The DCT page codec on synthetic hard content (checker, text/UI, decals, pixel art, "
      "saturated gradients, crease normals): bytes and error after the runtime BC format, with "
      "and without the per-page mode decision, beside lossless-then-BC";
  k.inputs_help = "none (the cases are generated)";
  k.options = {
      {"page-size", "Page edge in texels", "128"},
      {"qualities", "DCT qualities, comma-separated", "50,75,90,100"},
  };
  k.run = [](const BenchRequest& req) -> Expected<BenchReport> {
    VT_ASSIGN_OR_RETURN(int size, option_int(req, "page-size", 8, 1024));
    if (size % 8) return Error(ErrorCode::kInvalidArgument, "--page-size: a multiple of 8");
    VT_ASSIGN_OR_RETURN(std::vector<int> qualities, option_int_list(req, "qualities", 1, 100));
    std::ostringstream text;
    nlohmann::json json = nlohmann::json::array();
    char line[256];
    text << "pages of " << size << "x" << size << ", " << kPagesPerCase
         << " per case; one thread; bytes: the pages' (the layer's tables, stored once per file, "
            "in --json); runtime = decoded, BC realtime encoded, BC decoded\n";
    for (const Case& c : make_cases(size)) {
      if (req.progress) req.progress(c.name);
      text << "\n"
           << c.name << " (" << c.channels << " ch, runtime "
           << (c.bc == BcFormat::kBc1   ? "BC1"
               : c.bc == BcFormat::kBc3 ? "BC3"
                                        : "BC5")
           << ")\n";
      text << "  setting            bytes   stored dB  runtime dB  max err"
           << (c.normal ? "  deg mean/p99/max  " : "  ") << "worst/lossless  ms/page  modes\n";
      std::vector<std::pair<int, bool>> settings = {{0, false}};
      for (int q : qualities) settings.push_back({q, false}), settings.push_back({q, true});
      for (auto [q, modes] : settings) {
        VT_ASSIGN_OR_RETURN(Row r, run_setting(c, size, q, modes));
        std::string mode_text;
        for (int m = 0; m < kDctModeKinds; ++m)
          if (r.modes[m])
            mode_text += std::to_string(r.modes[m]) + " " + dct_mode_name(uint8_t(m)) + " ";
        std::snprintf(line, sizeof line, "  %-16s %8zu  %9s  %10s  %7u", r.setting.c_str(), r.bytes,
                      fmt_db(r.stored_psnr).c_str(), fmt_db(r.runtime.psnr_db()).c_str(),
                      r.runtime.max_error);
        text << line;
        if (c.normal) {
          std::snprintf(line, sizeof line, "  %5.2f/%5.2f/%5.2f  ", r.runtime.angle_mean_deg(),
                        r.runtime.angle_p99_deg(), r.runtime.angle_max_deg);
          text << line;
        } else {
          text << "  ";
        }
        std::snprintf(line, sizeof line, "%14.3f  %7.3f  %s\n", r.worst_page_over_lossless,
                      r.encode_ms_per_page, mode_text.c_str());
        text << line;
        nlohmann::json j = {{"case", c.name},
                            {"setting", r.setting},
                            {"bytes", r.bytes},
                            {"table_bytes", r.table_bytes},
                            {"worst_page_over_lossless", r.worst_page_over_lossless},
                            {"encode_ms_per_page", r.encode_ms_per_page},
                            {"runtime_max_error", r.runtime.max_error}};
        j["stored_psnr_db"] =
            std::isfinite(r.stored_psnr) ? nlohmann::json(r.stored_psnr) : nullptr;
        const double rp = r.runtime.psnr_db();
        j["runtime_psnr_db"] = std::isfinite(rp) ? nlohmann::json(rp) : nullptr;
        if (c.normal)
          j["runtime_normal_error_deg"] = {{"mean", r.runtime.angle_mean_deg()},
                                           {"p99", r.runtime.angle_p99_deg()},
                                           {"max", r.runtime.angle_max_deg}};
        json.push_back(j);
      }
    }
    return BenchReport{text.str(), json.dump(2)};
  };
  return k;
}

}  // namespace vt::bench
