// Page DCT codec against libjpeg-turbo abbreviated per-page streams (one shared table set, the
// strongest JPEG a page store can use), on 128x128 pages cut from real images.
//
//   dct_bench --report [KODAK_DIR [TEXTURE_DIR]]   rate-distortion and speed table (markdown)
//   dct_bench --speed [KODAK_DIR]                   decode speed against JPEG, interleaved
//   dct_bench --runtime [KODAK_DIR]                 DCT decode + BC1 real-time, pages/s
//   dct_bench --transcode [ROUNDS [BASIS_BC1_DIR [SET]]]  issue 22: decode vs JPEG and DCT + BC1
//                                       on Kodak, PBR maps (and game textures: env
//                                       DCT_BENCH_GAME_TEXTURES=DIR), interleaved (SET: a
//                                       name's part)
//   dct_bench --profile [PASSES [SET [decode]]]  one set's DCT + BC1 transcode (or decode)
//                                           alone, PASSES times (a loop for perf)
//   dct_bench [google benchmark flags]             per-page decode / encode timings
//
// Report: bits per texel, PSNR (RGB, per page), single-thread encode / decode Mtexel/s (median
// of 5 passes over all pages), bytes ratio against JPEG at equal PSNR (log-rate interpolated),
// and the runtime path DCT decode + BC1 (real-time level, bc_encode_image) in pages/s.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/jpeg_anchor.h"
#include "codec/bc.h"
#include "codec/dct.h"

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

namespace {

using namespace vt;
using bench::JpegPageDecoder;
using bench::JpegPageEncoder;
using Page = std::vector<uint8_t>;
constexpr int kPage = 128;

std::string g_kodak_dir = "/work/shared/testdata/images/kodak";
std::string g_texture_dir = "/work/shared/testdata/images/textures";

// Thread CPU time: the benchmark machine is shared, and wall time would count other work.
double now_s() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// Cuts an image into whole 128x128 pages of `channels` channels (the first ones of the file).
std::vector<Page> load_pages(const std::string& path, int channels, int max_pages = 1 << 30) {
  int w, h, c;
  uint8_t* img = stbi_load(path.c_str(), &w, &h, &c, 4);
  std::vector<Page> pages;
  if (!img) return pages;
  for (int py = 0; py + kPage <= h; py += kPage) {
    for (int px = 0; px + kPage <= w && int(pages.size()) < max_pages; px += kPage) {
      Page p(size_t(kPage) * kPage * channels);
      for (int y = 0; y < kPage; y++)
        for (int x = 0; x < kPage; x++)
          for (int ch = 0; ch < channels; ch++)
            p[(size_t(y) * kPage + x) * channels + ch] =
                img[(size_t(py + y) * w + px + x) * 4 + ch];
      pages.push_back(std::move(p));
    }
  }
  stbi_image_free(img);
  return pages;
}

std::vector<std::string> list_pngs(const std::string& dir, const std::string& contains = "") {
  std::vector<std::string> files;
  if (!std::filesystem::is_directory(dir)) return files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() == ".png" && name.find(contains) != std::string::npos) {
      files.push_back(e.path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

double squared_error(const Page& a, const Page& b) {
  double se = 0;
  for (size_t i = 0; i < a.size(); i++) {
    const double d = double(a[i]) - double(b[i]);
    se += d * d;
  }
  return se;
}

double psnr_from(double se, double samples) {
  return se == 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 * samples / se);
}

template <class F>
double median_seconds(int runs, F&& f) {
  std::vector<double> t;
  for (int r = 0; r < runs; r++) {
    const double t0 = now_s();
    f();
    t.push_back(now_s() - t0);
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// ---- libjpeg-turbo abbreviated streams (bench/jpeg_anchor.h) ----

struct JpegCoded {
  std::vector<uint8_t> tables;  // tables-only stream, shared by every page
  std::vector<std::vector<uint8_t>> pages;
};

[[noreturn]] void die(const Status& status) {
  std::fprintf(stderr, "%s\n", status.message().c_str());
  std::exit(1);
}

JpegCoded jpeg_encode(const std::vector<Page>& pages, int quality, bool subsample) {
  auto encoder =
      JpegPageEncoder::create({.page_size = kPage, .quality = quality, .subsample = subsample});
  if (!encoder.ok()) die(encoder.status());
  JpegCoded out;
  out.tables = encoder->tables();
  out.pages.resize(pages.size());
  for (size_t i = 0; i < pages.size(); i++) {
    Status st = encoder->encode(pages[i].data(), out.pages[i]);
    if (!st.ok()) die(st);
  }
  return out;
}

JpegPageDecoder jpeg_decoder(const std::vector<uint8_t>& tables) {
  auto decoder = JpegPageDecoder::create(kPage, tables);
  if (!decoder.ok()) die(decoder.status());
  return std::move(decoder).value();
}

// ---- measurements ----

struct Point {
  std::string codec;
  std::string setting;
  double bpt = 0;
  double psnr = 0;
  double enc_mtex = 0;
  double dec_mtex = 0;
  size_t table_bytes = 0;
};

Point measure_jpeg(const std::vector<Page>& pages, int quality, bool subsample) {
  Point pt;
  pt.codec = "libjpeg-turbo abbreviated";
  pt.setting = "q" + std::to_string(quality) + (subsample ? " 4:2:0" : " 4:4:4");
  JpegCoded coded;
  const double enc = median_seconds(3, [&] { coded = jpeg_encode(pages, quality, subsample); });
  pt.table_bytes = coded.tables.size();
  JpegPageDecoder dec = jpeg_decoder(coded.tables);
  Page out(size_t(kPage) * kPage * 3);
  double se = 0, bytes = 0;
  for (size_t i = 0; i < pages.size(); i++) {
    (void)dec.decode(coded.pages[i], out.data());
    se += squared_error(pages[i], out);
    bytes += double(coded.pages[i].size());
  }
  const double d = median_seconds(5, [&] {
    for (const auto& c : coded.pages) (void)dec.decode(c, out.data());
  });
  const double texels = double(pages.size()) * kPage * kPage;
  pt.bpt = bytes * 8 / texels;
  pt.psnr = psnr_from(se, texels * 3);
  pt.enc_mtex = texels / enc / 1e6;
  pt.dec_mtex = texels / d / 1e6;
  return pt;
}

// Tables trained two-fold: pages of even-numbered images are coded with tables trained on the
// odd ones and vice versa, so no page is coded with tables that saw it.
struct Folds {
  std::vector<Page> pages[2];
};

Point measure_dct(const Folds& folds, const DctSettings& s, bool trained, int channels_measured,
                  std::vector<std::vector<uint8_t>>* coded_out = nullptr,
                  DctTablesPtr* tables_out = nullptr) {
  Point pt;
  pt.codec = trained ? "vtbake DCT (trained tables)" : "vtbake DCT (untrained tables)";
  const char* names[] = {"planes", "YCoCg", "YCoCg 4:2:0"};
  pt.setting = "q" + std::to_string(s.quality) + " " + names[int(s.layout)];
  double se = 0, bytes = 0, texels = 0, enc_s = 0, dec_s = 0;
  for (int f = 0; f < 2; f++) {
    const auto& pages = folds.pages[f];
    if (pages.empty()) continue;
    std::vector<std::span<const uint8_t>> training;
    if (trained) {
      for (const Page& p : folds.pages[1 - f]) training.push_back(p);
    }
    auto tables = dct_make_tables(s, kPage, kPage, training);
    if (!tables.ok()) die(tables.status());
    pt.table_bytes = dct_serialize_tables(**tables).size();
    std::vector<std::vector<uint8_t>> coded(pages.size());
    enc_s += median_seconds(3, [&] {
      for (size_t i = 0; i < pages.size(); i++) {
        (void)dct_encode_page(**tables, pages[i].data(), kPage, kPage, coded[i]);
      }
    });
    Page out(pages[0].size());
    for (size_t i = 0; i < pages.size(); i++) {
      if (!dct_decode_page(**tables, coded[i], kPage, kPage, out.data()).ok()) std::exit(2);
      for (size_t j = 0; j < out.size(); j++) {
        if (int(j % s.channels) >= channels_measured) continue;
        const double d = double(out[j]) - double(pages[i][j]);
        se += d * d;
      }
      bytes += double(coded[i].size());
    }
    dec_s += median_seconds(5, [&] {
      for (const auto& c : coded) (void)dct_decode_page(**tables, c, kPage, kPage, out.data());
    });
    texels += double(pages.size()) * kPage * kPage;
    if (coded_out && f == 0) *coded_out = std::move(coded);
    if (tables_out && f == 0) *tables_out = std::move(tables).value();
  }
  pt.bpt = bytes * 8 / texels;
  pt.psnr = psnr_from(se, texels * channels_measured);
  pt.enc_mtex = texels / enc_s / 1e6;
  pt.dec_mtex = texels / dec_s / 1e6;
  return pt;
}

// Bits per texel of a rate-distortion curve at `psnr`, interpolating log(rate) linearly
// between the measured points; negative when `psnr` lies outside the curve.
double rate_at(std::vector<Point> curve, double psnr) {
  std::sort(curve.begin(), curve.end(),
            [](const Point& a, const Point& b) { return a.psnr < b.psnr; });
  for (size_t i = 1; i < curve.size(); i++) {
    const Point &a = curve[i - 1], &b = curve[i];
    if (psnr >= a.psnr && psnr <= b.psnr && b.psnr > a.psnr) {
      const double t = (psnr - a.psnr) / (b.psnr - a.psnr);
      return std::exp(std::log(a.bpt) + t * (std::log(b.bpt) - std::log(a.bpt)));
    }
  }
  return -1;
}

void print_points(const std::vector<Point>& pts) {
  std::printf(
      "| codec | setting | bits/texel | PSNR dB | encode Mtex/s | decode Mtex/s | decode pages/s | "
      "tables B |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const Point& p : pts) {
    std::printf("| %s | %s | %.3f | %.2f | %.1f | %.1f | %.0f | %zu |\n", p.codec.c_str(),
                p.setting.c_str(), p.bpt, p.psnr, p.enc_mtex, p.dec_mtex,
                p.dec_mtex * 1e6 / (kPage * kPage), p.table_bytes);
  }
}

void print_ratios(const char* title, const std::vector<Point>& dct,
                  const std::vector<Point>& jpeg) {
  std::printf(
      "\n%s: bits at equal PSNR\n\n| PSNR dB | DCT bits/texel | JPEG bits/texel | ratio "
      "|\n|---|---|---|---|\n",
      title);
  for (double db = 30; db <= 42; db += 1) {
    const double a = rate_at(dct, db), b = rate_at(jpeg, db);
    if (a > 0 && b > 0) std::printf("| %.0f | %.3f | %.3f | %.3f |\n", db, a, b, a / b);
  }
}

// DCT decode + BC1 real-time encode per page, one core, on the first fold of pages.
void runtime_path(const Folds& kodak) {
  std::printf(
      "\n## Runtime path on Kodak pages (one core)\n\n| path | bits/texel | PSNR after "
      "decode dB | PSNR after BC1 dB | pages/s |\n|---|---|---|---|---|\n");
  for (int q : {40, 50, 75}) {
    DctSettings s;
    s.quality = q;
    s.channels = 3;
    s.layout = DctPlaneLayout::kYCoCg420;
    std::vector<std::vector<uint8_t>> coded;
    DctTablesPtr tables;
    const Point pt = measure_dct(kodak, s, true, 3, &coded, &tables);
    const auto& pages = kodak.pages[0];
    Page rgb(size_t(kPage) * kPage * 3);
    std::vector<uint8_t> bc(bc_image_bytes(BcFormat::kBc1, kPage, kPage));
    Page bc_rgb(rgb.size());
    // The runtime transcode: decode the page, encode it to BC1 at the real-time level (the
    // batched path bc_encode_image takes), and, outside the timing, measure after BC1.
    auto transcode = [&](size_t i, const Page* check, double* se) {
      (void)dct_decode_page(*tables, coded[i], kPage, kPage, rgb.data());
      (void)bc_encode_image(BcFormat::kBc1, BcQuality::kRealtime, rgb.data(), kPage, kPage, 3,
                            bc.data());
      if (check) {
        (void)bc_decode_image(BcFormat::kBc1, bc.data(), kPage, kPage, 3, bc_rgb.data());
        *se += squared_error(*check, bc_rgb);
      }
    };
    double se = 0, se_dec = 0, bytes = 0;
    for (size_t i = 0; i < pages.size(); i++) {
      transcode(i, &pages[i], &se);
      se_dec += squared_error(pages[i], rgb);
      bytes += double(coded[i].size());
    }
    const double t = median_seconds(5, [&] {
      for (size_t i = 0; i < pages.size(); i++) transcode(i, nullptr, nullptr);
    });
    const double samples = double(pages.size()) * kPage * kPage * 3;
    std::printf("| DCT q%d 4:2:0 + BC1 real-time | %.3f | %.2f | %.2f | %.0f |\n", q,
                bytes * 8 / (samples / 3), psnr_from(se_dec, samples), psnr_from(se, samples),
                double(pages.size()) / t);
    (void)pt;
  }
}

int report() {
  // ---- Kodak: photographs, RGB ----
  Folds kodak;
  std::vector<Page> all;
  const auto files = list_pngs(g_kodak_dir);
  for (size_t i = 0; i < files.size(); i++) {
    for (Page& p : load_pages(files[i], 3)) {
      all.push_back(p);
      kodak.pages[i % 2].push_back(std::move(p));
    }
  }
  if (all.empty()) {
    std::fprintf(stderr, "no images in %s\n", g_kodak_dir.c_str());
    return 1;
  }
  std::printf("## Kodak (%zu images, %zu pages of 128x128)\n\n", files.size(), all.size());
  std::vector<Point> jpeg420, jpeg444, dct420, dct444, points;
  for (int q : {30, 40, 50, 60, 75, 85, 90, 95}) jpeg420.push_back(measure_jpeg(all, q, true));
  for (int q : {50, 75, 90, 95}) jpeg444.push_back(measure_jpeg(all, q, false));
  for (int q : {20, 30, 40, 50, 60, 75, 90}) {
    DctSettings s;
    s.quality = q;
    s.channels = 3;
    s.layout = DctPlaneLayout::kYCoCg420;
    dct420.push_back(measure_dct(kodak, s, true, 3));
    s.layout = DctPlaneLayout::kYCoCg;
    dct444.push_back(measure_dct(kodak, s, true, 3));
  }
  for (int q : {50, 75}) {
    DctSettings s;
    s.quality = q;
    s.channels = 3;
    s.layout = DctPlaneLayout::kYCoCg420;
    points.push_back(measure_dct(kodak, s, false, 3));
  }
  std::vector<Point> table;
  table.insert(table.end(), jpeg420.begin(), jpeg420.end());
  table.insert(table.end(), jpeg444.begin(), jpeg444.end());
  table.insert(table.end(), dct420.begin(), dct420.end());
  table.insert(table.end(), dct444.begin(), dct444.end());
  table.insert(table.end(), points.begin(), points.end());
  print_points(table);
  std::vector<Point> jpeg_best = jpeg420;  // lower envelope: JPEG's best subsampling per rate
  jpeg_best.insert(jpeg_best.end(), jpeg444.begin(), jpeg444.end());
  print_ratios("DCT 4:2:0 vs JPEG 4:2:0", dct420, jpeg420);
  print_ratios("DCT full-res chroma vs JPEG 4:4:4", dct444, jpeg444);

  runtime_path(kodak);

  // ---- PBR textures: colour maps as RGB, normal maps as XY planes, packed maps as planes ----
  std::printf("\n## PBR textures (%s, first 64 pages of each map)\n\n", g_texture_dir.c_str());
  std::vector<Point> tex;
  struct Kind {
    const char* contains;
    int channels;
    DctPlaneLayout layout;
    int measured;
  };
  const Kind kinds[] = {{"baseColor", 3, DctPlaneLayout::kYCoCg420, 3},
                        {"normal", 2, DctPlaneLayout::kPlanes, 2},
                        {"oughness", 3, DctPlaneLayout::kPlanes, 3}};
  for (const Kind& k : kinds) {
    for (const auto& file : list_pngs(g_texture_dir, k.contains)) {
      Folds f;
      auto pages = load_pages(file, k.channels, 64);
      for (size_t i = 0; i < pages.size(); i++) f.pages[i % 2].push_back(pages[i]);
      for (int q : {50, 75, 90}) {
        DctSettings s;
        s.quality = q;
        s.channels = k.channels;
        s.layout = k.layout;
        Point pt = measure_dct(f, s, true, k.measured);
        pt.codec = std::filesystem::path(file).stem().string();
        tex.push_back(pt);
      }
      if (k.channels == 3) {
        std::vector<Page> rgb(pages.begin(), pages.end());
        for (int q : {50, 75, 90}) {
          Point pt = measure_jpeg(rgb, q, k.layout == DctPlaneLayout::kYCoCg420);
          pt.codec = std::filesystem::path(file).stem().string() + " JPEG";
          tex.push_back(pt);
        }
      }
    }
  }
  print_points(tex);
  return 0;
}

// Decode speed side by side: DCT and JPEG passes over the same pages alternate, so load from
// other processes hits both alike; medians of thread CPU time over `rounds`.
int speed(int rounds) {
  std::vector<Page> pages;
  for (const auto& f : list_pngs(g_kodak_dir)) {
    for (Page& p : load_pages(f, 3)) pages.push_back(std::move(p));
  }
  if (pages.empty()) return 1;
  std::printf(
      "| pair | DCT bits/texel | DCT PSNR | DCT decode pages/s | JPEG bits/texel | JPEG PSNR | "
      "JPEG decode pages/s | DCT / JPEG speed |\n|---|---|---|---|---|---|---|---|\n");
  const int pairs[][2] = {{40, 50}, {50, 75}, {75, 90}};
  for (const auto& pr : pairs) {
    DctSettings s;
    s.quality = pr[0];
    s.channels = 3;
    s.layout = DctPlaneLayout::kYCoCg420;
    std::vector<std::span<const uint8_t>> training;
    for (size_t i = 0; i < pages.size(); i += 2) training.push_back(pages[i]);
    auto tables = dct_make_tables(s, kPage, kPage, training);
    std::vector<std::vector<uint8_t>> coded(pages.size());
    double dbytes = 0, dse = 0;
    Page out(pages[0].size());
    for (size_t i = 0; i < pages.size(); i++) {
      (void)dct_encode_page(**tables, pages[i].data(), kPage, kPage, coded[i]);
      (void)dct_decode_page(**tables, coded[i], kPage, kPage, out.data());
      dbytes += double(coded[i].size());
      dse += squared_error(pages[i], out);
    }
    const JpegCoded jc = jpeg_encode(pages, pr[1], true);
    JpegPageDecoder jd = jpeg_decoder(jc.tables);
    double jbytes = 0, jse = 0;
    for (size_t i = 0; i < pages.size(); i++) {
      (void)jd.decode(jc.pages[i], out.data());
      jbytes += double(jc.pages[i].size());
      jse += squared_error(pages[i], out);
    }
    std::vector<double> td, tj;
    for (int r = 0; r < rounds; r++) {
      double t0 = now_s();
      for (const auto& c : coded) (void)dct_decode_page(**tables, c, kPage, kPage, out.data());
      double t1 = now_s();
      for (const auto& c : jc.pages) (void)jd.decode(c, out.data());
      double t2 = now_s();
      td.push_back(t1 - t0);
      tj.push_back(t2 - t1);
    }
    std::sort(td.begin(), td.end());
    std::sort(tj.begin(), tj.end());
    const double n = double(pages.size()), texels = n * kPage * kPage;
    const double dps = n / td[td.size() / 2], jps = n / tj[tj.size() / 2];
    std::printf(
        "| DCT q%d 4:2:0 / JPEG q%d 4:2:0 | %.3f | %.2f | %.0f | %.3f | %.2f | %.0f | %.2f |\n",
        pr[0], pr[1], dbytes * 8 / texels, psnr_from(dse, texels * 3), dps, jbytes * 8 / texels,
        psnr_from(jse, texels * 3), jps, dps / jps);
  }
  return 0;
}

// ---- Issue 22: the runtime transcode side by side ----

// A page set for the transcode run: its pages, DCT q50 4:2:0 pages coded with tables trained on
// the other fold (`training`), and JPEG q75 4:2:0 abbreviated pages (about DCT q50's PSNR).
struct TranscodeSet {
  std::string name;
  std::vector<Page> pages;
  DctTablesPtr tables;
  std::vector<std::vector<uint8_t>> dct;
  JpegCoded jpeg;
  double dct_bpt = 0, jpeg_bpt = 0, dct_psnr = 0, jpeg_psnr = 0, bc1_psnr = 0;
};

TranscodeSet make_transcode_set(std::string name, std::vector<Page> pages,
                                const std::vector<Page>& training_pages) {
  TranscodeSet set;
  set.name = std::move(name);
  set.pages = std::move(pages);
  DctSettings s;
  s.quality = 50;
  s.channels = 3;
  s.layout = DctPlaneLayout::kYCoCg420;
  std::vector<std::span<const uint8_t>> training(training_pages.begin(), training_pages.end());
  auto tables = dct_make_tables(s, kPage, kPage, training);
  if (!tables.ok()) die(tables.status());
  set.tables = std::move(tables).value();
  set.dct.resize(set.pages.size());
  set.jpeg = jpeg_encode(set.pages, 75, true);
  JpegPageDecoder jd = jpeg_decoder(set.jpeg.tables);
  Page out(set.pages[0].size()), bc_rgb(out.size());
  std::vector<uint8_t> bc(bc_image_bytes(BcFormat::kBc1, kPage, kPage));
  double db = 0, jb = 0, dse = 0, jse = 0, bse = 0;
  for (size_t i = 0; i < set.pages.size(); i++) {
    (void)dct_encode_page(*set.tables, set.pages[i].data(), kPage, kPage, set.dct[i]);
    if (!dct_decode_page(*set.tables, set.dct[i], kPage, kPage, out.data()).ok()) std::exit(2);
    dse += squared_error(set.pages[i], out);
    (void)bc_encode_image(BcFormat::kBc1, BcQuality::kRealtime, out.data(), kPage, kPage, 3,
                          bc.data());
    (void)bc_decode_image(BcFormat::kBc1, bc.data(), kPage, kPage, 3, bc_rgb.data());
    bse += squared_error(set.pages[i], bc_rgb);
    (void)jd.decode(set.jpeg.pages[i], out.data());
    jse += squared_error(set.pages[i], out);
    db += double(set.dct[i].size());
    jb += double(set.jpeg.pages[i].size());
  }
  const double texels = double(set.pages.size()) * kPage * kPage;
  set.dct_bpt = db * 8 / texels, set.jpeg_bpt = jb * 8 / texels;
  set.dct_psnr = psnr_from(dse, texels * 3), set.jpeg_psnr = psnr_from(jse, texels * 3);
  set.bc1_psnr = psnr_from(bse, texels * 3);
  return set;
}

// PSNR against `pages` of Basis's BC1 output unpacked to PNG: `files[i]` is page i.
double basis_bc1_psnr(const std::vector<Page>& pages, const std::vector<std::string>& files) {
  double se = 0;
  for (size_t i = 0; i < pages.size(); i++) {
    int w, h, c;
    uint8_t* img = stbi_load(files[i].c_str(), &w, &h, &c, 3);
    if (!img || w != kPage || h != kPage) {
      std::fprintf(stderr, "bad Basis output %s\n", files[i].c_str());
      std::exit(1);
    }
    se += squared_error(pages[i], Page(img, img + size_t(kPage) * kPage * 3));
    stbi_image_free(img);
  }
  return psnr_from(se, double(pages.size()) * kPage * kPage * 3);
}

// The page sets of --transcode and --profile (Kodak fold 0; PBR colour maps; PBR normal and ORM
// maps read as RGB; game textures when DCT_BENCH_GAME_TEXTURES names a folder), each coded with
// tables trained on its other fold; `only` (part of a set's name) keeps that set alone. With
// `basis_dir`, the Basis BC1 files of Kodak fold 0's pages.
std::vector<TranscodeSet> load_transcode_sets(const std::string& only, const std::string& basis_dir,
                                              std::vector<std::string>* basis_files) {
  auto wanted = [&](const char* name) {
    return only.empty() || std::strstr(name, only.c_str()) != nullptr;
  };
  std::vector<Page> folds[2];
  const auto files = wanted("Kodak fold 0") ? list_pngs(g_kodak_dir) : std::vector<std::string>{};
  for (size_t i = 0; i < files.size(); i++) {
    auto pages = load_pages(files[i], 3);
    for (size_t p = 0; p < pages.size() && i % 2 == 0 && !basis_dir.empty(); p++) {
      char name[64];
      std::snprintf(name, sizeof name, "_unpacked_rgb_BC1_RGB_%04zu.png", p);
      basis_files->push_back(basis_dir + "/" + std::filesystem::path(files[i]).stem().string() +
                             name);
    }
    for (Page& p : pages) folds[i % 2].push_back(std::move(p));
  }
  // Game textures: colour maps, and the other maps (normal, ORM) read as RGB pages too.
  std::vector<Page> tex[2], other[2];
  const bool textures = wanted("PBR baseColor maps") || wanted("PBR normal + ORM maps");
  for (const auto& f : textures ? list_pngs(g_texture_dir) : std::vector<std::string>{}) {
    auto pages = load_pages(f, 3);
    auto& to = f.find("baseColor") != std::string::npos ? tex : other;
    for (size_t i = 0; i < pages.size(); i++) to[i % 2].push_back(std::move(pages[i]));
  }
  // Game data (DCT_BENCH_GAME_TEXTURES: a folder, e.g. supertuxkart-data's unpacked
  // share/games/supertuxkart/data): every PNG and JPEG under it, its first four pages each.
  std::vector<Page> game[2];
  const char* game_dir = std::getenv("DCT_BENCH_GAME_TEXTURES");
  if (game_dir != nullptr && wanted("game textures") && std::filesystem::is_directory(game_dir)) {
    std::vector<std::string> images;
    for (const auto& e : std::filesystem::recursive_directory_iterator(game_dir)) {
      std::string ext = e.path().extension().string();
      for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
      if (e.is_regular_file() && (ext == ".png" || ext == ".jpg" || ext == ".jpeg"))
        images.push_back(e.path().string());
    }
    std::sort(images.begin(), images.end());
    size_t n = 0;
    for (const auto& f : images)
      for (Page& p : load_pages(f, 3, 4)) game[n++ % 2].push_back(std::move(p));
  }
  std::vector<TranscodeSet> sets;
  auto add = [&](const char* name, std::vector<Page>(&f)[2]) {
    if (!f[0].empty() && wanted(name))
      sets.push_back(make_transcode_set(name, std::move(f[0]), f[1]));
  };
  add("Kodak fold 0", folds);
  add("PBR baseColor maps", tex);
  add("PBR normal + ORM maps", other);
  add("game textures", game);
  return sets;
}

// `dct_bench --transcode ROUNDS [BASIS_BC1_DIR [SET]]`: per page set (Kodak fold 0, 288 pages:
// the pages bench/transcode_vs_basis.sh gives Basis; the PBR colour maps; the PBR normal and ORM
// maps, read as RGB; game textures, see load_transcode_sets), DCT decode, JPEG decode and DCT
// decode + BC1 real-time, passes alternating, medians of thread CPU time over ROUNDS. Both codecs
// code the same RGB pages at about equal PSNR: DCT q50 4:2:0 (tables trained on the other fold),
// JPEG q75 4:2:0. With BASIS_BC1_DIR (kodimNN_unpacked_rgb_BC1_RGB_PPPP.png from `basisu -unpack`)
// also Basis's PSNR after BC1 on the same Kodak pages. SET (part of a set's name) runs that set
// alone: see the note on libjpeg-turbo's speed below.
int transcode(int rounds, const std::string& basis_dir, const std::string& only) {
  std::vector<std::string> basis_files;
  const std::vector<TranscodeSet> sets = load_transcode_sets(only, basis_dir, &basis_files);
  if (sets.empty()) return 1;
  const bool with_basis = !basis_files.empty() && sets[0].name == "Kodak fold 0";
  const double basis_psnr = with_basis ? basis_bc1_psnr(sets[0].pages, basis_files) : 0;

  std::printf(
      "| pages | n | DCT q50 b/t | DCT PSNR | JPEG q75 b/t | JPEG PSNR | DCT decode pages/s | "
      "JPEG decode pages/s | DCT / JPEG | DCT + BC1 pages/s | PSNR after BC1 |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const TranscodeSet& set : sets) {
    Page out(set.pages[0].size());
    std::vector<uint8_t> bc(bc_image_bytes(BcFormat::kBc1, kPage, kPage));
    JpegPageDecoder jd = jpeg_decoder(set.jpeg.tables);
    // libjpeg-turbo's speed here is bimodal with where malloc puts its per-image buffers (its
    // AVX2 fancy upsampler's stores stall in some layouts): the same binary and pages give
    // 15,000 or 21,800 Kodak pages/s depending on what was allocated before. Aligning our
    // buffers does not move it; compare ratios across builds with care (docs/BENCHMARKS.md).
    std::vector<double> td, tj, tt;
    for (int r = 0; r < rounds; r++) {
      const double t0 = now_s();
      for (const auto& c : set.dct) (void)dct_decode_page(*set.tables, c, kPage, kPage, out.data());
      const double t1 = now_s();
      for (const auto& c : set.jpeg.pages) (void)jd.decode(c, out.data());
      const double t2 = now_s();
      for (const auto& c : set.dct) {
        (void)dct_decode_page(*set.tables, c, kPage, kPage, out.data());
        (void)bc_encode_image(BcFormat::kBc1, BcQuality::kRealtime, out.data(), kPage, kPage, 3,
                              bc.data());
      }
      const double t3 = now_s();
      td.push_back(t1 - t0), tj.push_back(t2 - t1), tt.push_back(t3 - t2);
    }
    for (auto* v : {&td, &tj, &tt}) std::sort(v->begin(), v->end());
    const double n = double(set.pages.size());
    const double dps = n / td[td.size() / 2], jps = n / tj[tj.size() / 2];
    std::printf("| %s | %zu | %.3f | %.2f | %.3f | %.2f | %.0f | %.0f | %.2f | %.0f | %.2f |\n",
                set.name.c_str(), set.pages.size(), set.dct_bpt, set.dct_psnr, set.jpeg_bpt,
                set.jpeg_psnr, dps, jps, dps / jps, n / tt[tt.size() / 2], set.bc1_psnr);
  }
  // The other runtime formats' real-time encoders on the first set's pages (the texels a
  // transcode hands them): BC3 and BC7 with alpha taken from G (content, not a constant),
  // BC4 from R, BC5 from R and G; pages/s per core and PSNR over the channels coded.
  struct Fmt {
    const char* name;
    BcFormat format;
    int channels;
  };
  const Fmt fmts[] = {{"BC1 (RGB)", BcFormat::kBc1, 3},
                      {"BC3 (RGBA, alpha = G)", BcFormat::kBc3, 4},
                      {"BC4 (R)", BcFormat::kBc4, 1},
                      {"BC5 (RG)", BcFormat::kBc5, 2},
                      {"BC7 (RGBA, alpha = G)", BcFormat::kBc7, 4}};
  constexpr size_t kFmts = sizeof(fmts) / sizeof(fmts[0]);
  const TranscodeSet& first = sets[0];
  std::printf("\n| %s: real-time encoder | pages/s | PSNR dB |\n|---|---|---|\n",
              first.name.c_str());
  std::vector<std::vector<Page>> inputs;
  for (const Fmt& f : fmts) {
    std::vector<Page> in;
    for (const Page& p : first.pages) {
      Page q(size_t(kPage) * kPage * f.channels);
      for (size_t t = 0; t < size_t(kPage) * kPage; t++)
        for (int c = 0; c < f.channels; c++) q[t * f.channels + c] = p[t * 3 + (c == 3 ? 1 : c)];
      in.push_back(std::move(q));
    }
    inputs.push_back(std::move(in));
  }
  std::vector<std::vector<double>> times(kFmts);
  std::vector<uint8_t> blocks(bc_image_bytes(BcFormat::kBc7, kPage, kPage));
  for (int r = 0; r < rounds; r++) {
    for (size_t fi = 0; fi < kFmts; fi++) {
      const double t0 = now_s();
      for (const Page& p : inputs[fi])
        (void)bc_encode_image(fmts[fi].format, BcQuality::kRealtime, p.data(), kPage, kPage,
                              fmts[fi].channels, blocks.data());
      times[fi].push_back(now_s() - t0);
    }
  }
  for (size_t fi = 0; fi < kFmts; fi++) {
    double se = 0;
    Page back(inputs[fi][0].size());
    for (const Page& p : inputs[fi]) {
      (void)bc_encode_image(fmts[fi].format, BcQuality::kRealtime, p.data(), kPage, kPage,
                            fmts[fi].channels, blocks.data());
      (void)bc_decode_image(fmts[fi].format, blocks.data(), kPage, kPage, fmts[fi].channels,
                            back.data());
      se += squared_error(p, back);
    }
    std::sort(times[fi].begin(), times[fi].end());
    std::printf("| %s | %.0f | %.2f |\n", fmts[fi].name,
                double(inputs[fi].size()) / times[fi][times[fi].size() / 2],
                psnr_from(se, double(inputs[fi].size()) * kPage * kPage * fmts[fi].channels));
  }
  if (with_basis) std::printf("\nBasis ETC1S -> BC1 PSNR on Kodak fold 0: %.2f\n", basis_psnr);
  return 0;
}

// `dct_bench --profile PASSES [SET [decode]]`: the transcode loop of --transcode's row for SET
// (default Kodak) and nothing else timed, so that a profiler's shares are the runtime path's;
// with "decode", the passes decode only.
int profile(int passes, const std::string& only, bool decode_only) {
  const std::vector<TranscodeSet> sets =
      load_transcode_sets(only.empty() ? "Kodak" : only, "", nullptr);
  if (sets.empty()) return 1;
  const TranscodeSet& set = sets[0];
  Page out(set.pages[0].size());
  std::vector<uint8_t> bc(bc_image_bytes(BcFormat::kBc1, kPage, kPage));
  // FNV-1a over every decoded page and its BC1 bytes: builds that must not change an output
  // print the same digest.
  uint64_t digest = 0xcbf29ce484222325ull;
  auto hash = [&](const std::vector<uint8_t>& v) {
    for (uint8_t b : v) digest = (digest ^ b) * 0x100000001b3ull;
  };
  for (const auto& c : set.dct) {
    (void)dct_decode_page(*set.tables, c, kPage, kPage, out.data());
    (void)bc_encode_image(BcFormat::kBc1, BcQuality::kRealtime, out.data(), kPage, kPage, 3,
                          bc.data());
    hash(out), hash(bc);
  }
  double decode = 0, both = 0;
  for (int r = 0; r < passes; r++) {
    const double t0 = now_s();
    for (const auto& c : set.dct) (void)dct_decode_page(*set.tables, c, kPage, kPage, out.data());
    const double t1 = now_s();
    for (size_t i = 0; i < set.dct.size() && !decode_only; i++) {
      (void)dct_decode_page(*set.tables, set.dct[i], kPage, kPage, out.data());
      (void)bc_encode_image(BcFormat::kBc1, BcQuality::kRealtime, out.data(), kPage, kPage, 3,
                            bc.data());
    }
    decode += t1 - t0, both += now_s() - t1;
  }
  const double n = double(set.pages.size()) * passes;
  std::printf("%s: decode %.0f pages/s, decode + BC1 %.0f pages/s, output digest %016llx\n",
              set.name.c_str(), n / decode, decode_only ? 0.0 : n / both,
              (unsigned long long)digest);
  return 0;
}

// ---- Google Benchmark timings: one page at a time ----

struct Fixture {
  std::vector<Page> pages;
  Fixture() {
    for (const auto& f : list_pngs(g_kodak_dir)) {
      for (Page& p : load_pages(f, 3)) pages.push_back(std::move(p));
      if (pages.size() >= 96) break;
    }
  }
};
Fixture& fixture() {
  static Fixture f;
  return f;
}

void BM_DctDecode(benchmark::State& state) {
  const auto& pages = fixture().pages;
  if (pages.empty()) return state.SkipWithError("no Kodak images");
  DctSettings s;
  s.quality = int(state.range(0));
  s.layout = DctPlaneLayout(state.range(1));
  std::vector<std::span<const uint8_t>> training(pages.begin(), pages.end());
  auto tables = dct_make_tables(s, kPage, kPage, training);
  std::vector<std::vector<uint8_t>> coded(pages.size());
  for (size_t i = 0; i < pages.size(); i++) {
    (void)dct_encode_page(**tables, pages[i].data(), kPage, kPage, coded[i]);
  }
  Page out(pages[0].size());
  size_t i = 0;
  for (auto _ : state) {
    (void)dct_decode_page(**tables, coded[i], kPage, kPage, out.data());
    benchmark::DoNotOptimize(out.data());
    i = (i + 1) % coded.size();
  }
  state.counters["pages/s"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DctDecode)->Args({50, 2})->Args({75, 2})->Args({90, 2})->Args({75, 1});

void BM_DctEncode(benchmark::State& state) {
  const auto& pages = fixture().pages;
  if (pages.empty()) return state.SkipWithError("no Kodak images");
  DctSettings s;
  s.quality = int(state.range(0));
  auto tables = dct_make_tables(s, kPage, kPage);
  std::vector<uint8_t> coded;
  size_t i = 0;
  for (auto _ : state) {
    (void)dct_encode_page(**tables, pages[i].data(), kPage, kPage, coded);
    benchmark::DoNotOptimize(coded.data());
    i = (i + 1) % pages.size();
  }
  state.counters["pages/s"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DctEncode)->Arg(75);

void BM_JpegDecode(benchmark::State& state) {
  const auto& pages = fixture().pages;
  if (pages.empty()) return state.SkipWithError("no Kodak images");
  const JpegCoded coded = jpeg_encode(pages, int(state.range(0)), true);
  JpegPageDecoder dec = jpeg_decoder(coded.tables);
  Page out(pages[0].size());
  size_t i = 0;
  for (auto _ : state) {
    (void)dec.decode(coded.pages[i], out.data());
    benchmark::DoNotOptimize(out.data());
    i = (i + 1) % coded.pages.size();
  }
  state.counters["pages/s"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_JpegDecode)->Arg(50)->Arg(75);

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::strcmp(argv[1], "--report") == 0) {
    if (argc > 2) g_kodak_dir = argv[2];
    if (argc > 3) g_texture_dir = argv[3];
    return report();
  }
  if (argc > 1 && std::strcmp(argv[1], "--runtime") == 0) {
    if (argc > 2) g_kodak_dir = argv[2];
    Folds kodak;
    const auto files = list_pngs(g_kodak_dir);
    for (size_t i = 0; i < files.size(); i++) {
      for (Page& p : load_pages(files[i], 3)) kodak.pages[i % 2].push_back(std::move(p));
    }
    runtime_path(kodak);
    return 0;
  }
  if (argc > 1 && std::strcmp(argv[1], "--transcode") == 0) {
    return transcode(argc > 2 ? std::atoi(argv[2]) : 7, argc > 3 ? argv[3] : "",
                     argc > 4 ? argv[4] : "");
  }
  if (argc > 1 && std::strcmp(argv[1], "--profile") == 0)
    return profile(argc > 2 ? std::atoi(argv[2]) : 100, argc > 3 ? argv[3] : "",
                   argc > 4 && std::strcmp(argv[4], "decode") == 0);
  if (argc > 1 && std::strcmp(argv[1], "--speed") == 0) {
    if (argc > 2) g_kodak_dir = argv[2];
    return speed(7);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
