// The codec benchmark. Every figure comes from one run on one thread: the settings are timed
// over the same pages, `repeats` times, and the median pass is reported.
#include "bench/codec_bench.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bench/jpeg_anchor.h"
#include "codec/bc.h"
#include "codec/dct.h"
#include "codec/metrics.h"
#include "format/dct_page_modes.h"

#define STB_DXT_IMPLEMENTATION
#define STB_DXT_STATIC
#include <stb/stb_dxt.h>

namespace vt::bench {
namespace {

struct Page {
  std::vector<uint8_t> texels;
  int image = 0;
};

struct PageSet {
  int channels = 3;
  std::vector<Page> pages;
  int images = 0;
};

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Reads an image as 8-bit and cuts whole pages of its first `channels` channels (missing
// channels: 0, alpha 255).
Status load_pages(const std::string& path, int page, int channels, int image_id, PageSet& set) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    return Error(ErrorCode::kIo, path + ": cannot open image: " + OIIO::geterror());
  }
  const OIIO::ImageSpec spec = in->spec();
  const int w = spec.width, h = spec.height, nc = spec.nchannels;
  if (w < page || h < page || nc < 1) {
    return Error(ErrorCode::kInvalidArgument, path + ": image " + std::to_string(w) + "x" +
                                                  std::to_string(h) + " is smaller than a page");
  }
  std::vector<uint8_t> pixels(size_t(w) * h * nc);
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::UINT8, pixels.data())) {
    return Error(ErrorCode::kIo, path + ": cannot read pixels: " + in->geterror());
  }
  for (int py = 0; py + page <= h; py += page) {
    for (int px = 0; px + page <= w; px += page) {
      Page p;
      p.image = image_id;
      p.texels.resize(size_t(page) * page * channels);
      for (int y = 0; y < page; ++y) {
        for (int x = 0; x < page; ++x) {
          const uint8_t* src = &pixels[(size_t(py + y) * w + (px + x)) * nc];
          uint8_t* dst = &p.texels[(size_t(y) * page + x) * channels];
          for (int c = 0; c < channels; ++c) dst[c] = c < nc ? src[c] : (c == 3 ? 255 : 0);
        }
      }
      set.pages.push_back(std::move(p));
    }
  }
  return Status::Ok();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// Per-image and pooled PSNR over channels 0..min(3, channels)-1.
struct ErrorAccumulator {
  std::vector<double> sq;
  std::vector<double> n;
  void add(int image, const uint8_t* ref, const uint8_t* test, size_t texels, int channels) {
    if (size_t(image) >= sq.size()) sq.resize(image + 1, 0.0), n.resize(image + 1, 0.0);
    const int colour = std::min(channels, 3);
    uint64_t s = 0;
    for (size_t i = 0; i < texels; ++i) {
      for (int c = 0; c < colour; ++c) {
        const int d = int(ref[i * channels + c]) - int(test[i * channels + c]);
        s += uint64_t(d * d);
      }
    }
    sq[image] += double(s);
    n[image] += double(texels * colour);
  }
  double mean_psnr() const {
    double total = 0;
    int count = 0;
    for (size_t i = 0; i < sq.size(); ++i) {
      if (n[i] > 0) total += psnr_from_mse(sq[i] / n[i]), ++count;
    }
    return count ? total / count : 0.0;
  }
  double pooled_psnr() const {
    double s = 0, c = 0;
    for (size_t i = 0; i < sq.size(); ++i) s += sq[i], c += n[i];
    return c > 0 ? psnr_from_mse(s / c) : 0.0;
  }
};

// CPU time of this thread: on a shared machine it counts the work, not the waiting for a core.
double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Times `body` (one pass over the pages) `repeats` times; returns the median thread CPU seconds.
template <typename F>
double time_passes(int repeats, F&& body) {
  std::vector<double> t;
  for (int r = 0; r < std::max(1, repeats); ++r) {
    const double t0 = thread_seconds();
    body();
    t.push_back(std::max(1e-9, thread_seconds() - t0));
  }
  return median(t);
}

// ---- BC settings ----

struct BcSetting {
  std::string name;
  BcFormat format;
  int stb_mode = -1;  // >= 0: stb_dxt with this mode instead of vtbake's encoder
  BcQuality quality = BcQuality::kRealtime;
  bool slow = false;
};

void stb_encode(const BcSetting& s, const uint8_t* texels, int size, int channels, uint8_t* out) {
  uint8_t rgba[64];
  const bool alpha = s.format == BcFormat::kBc3;
  for (int by = 0; by < size / 4; ++by) {
    for (int bx = 0; bx < size / 4; ++bx) {
      for (int y = 0; y < 4; ++y) {
        for (int x = 0; x < 4; ++x) {
          const uint8_t* src = texels + (size_t(by * 4 + y) * size + bx * 4 + x) * channels;
          for (int c = 0; c < 4; ++c) rgba[16 * y + 4 * x + c] = c < channels ? src[c] : 255;
        }
      }
      stb_compress_dxt_block(out, rgba, alpha ? 1 : 0, s.stb_mode);
      out += alpha ? 16 : 8;
    }
  }
}

Status run_bc(const PageSet& set, const BcSetting& s, const CodecBenchOptions& o,
              CodecBenchRow& row) {
  const int size = o.page_size, ch = set.channels;
  // Slow settings run on `slow_pages` pages spread evenly over the set (every image is hit
  // when there are at least as many pages as images).
  std::vector<const Page*> pages;
  const size_t total = set.pages.size();
  const size_t count = s.slow ? std::min(total, size_t(std::max(1, o.slow_pages))) : total;
  for (size_t i = 0; i < count; ++i) pages.push_back(&set.pages[i * total / count]);
  const size_t bytes = bc_image_bytes(s.format, size, size);
  std::vector<uint8_t> blocks(bytes * count);
  Status status;
  const int repeats = s.slow ? 1 : o.repeats;
  const double enc = time_passes(repeats, [&] {
    for (size_t i = 0; i < count; ++i) {
      if (s.stb_mode >= 0) {
        stb_encode(s, pages[i]->texels.data(), size, ch, &blocks[i * bytes]);
      } else {
        Status st = bc_encode_image(s.format, s.quality, pages[i]->texels.data(), size, size, ch,
                                    &blocks[i * bytes]);
        if (!st.ok()) status = st;
      }
    }
  });
  VT_RETURN_IF_ERROR(status);
  std::vector<uint8_t> decoded(size_t(size) * size * ch * count);
  const double dec = time_passes(repeats, [&] {
    for (size_t i = 0; i < count; ++i) {
      Status st = bc_decode_image(s.format, &blocks[i * bytes], size, size, ch,
                                  &decoded[i * size_t(size) * size * ch]);
      if (!st.ok()) status = st;
    }
  });
  VT_RETURN_IF_ERROR(status);
  ErrorAccumulator acc;
  for (size_t i = 0; i < count; ++i) {
    acc.add(pages[i]->image, pages[i]->texels.data(), &decoded[i * size_t(size) * size * ch],
            size_t(size) * size, ch);
  }
  const double texels = double(count) * size * size;
  row.section = "bc";
  row.name = s.name;
  row.pages = int(count);
  row.bits_per_texel = double(bytes) * 8 / (double(size) * size);
  row.psnr = acc.mean_psnr();
  row.psnr_pooled = acc.pooled_psnr();
  row.encode_mtex_s = texels / enc / 1e6;
  row.decode_mtex_s = texels / dec / 1e6;
  row.seconds_per_mtex = enc / (texels / 1e6);
  return Status::Ok();
}

// ---- page codecs: DCT and abbreviated JPEG ----

// A page codec as the benchmark drives it: every page encoded into `coded`, timed.
struct PageCodecResult {
  std::vector<std::vector<uint8_t>> coded;
  size_t table_bytes = 0;
  double encode_s = 0;
};

// Encodes every page with `encode(texels, out) -> Status`, `repeats` times.
template <typename Encode>
Expected<PageCodecResult> encode_pages(const PageSet& set, int repeats, size_t table_bytes,
                                       Encode&& encode) {
  PageCodecResult r;
  r.table_bytes = table_bytes;
  r.coded.assign(set.pages.size(), {});
  Status status;
  r.encode_s = time_passes(repeats, [&] {
    for (size_t i = 0; i < set.pages.size(); ++i) {
      Status st = encode(set.pages[i].texels.data(), r.coded[i]);
      if (!st.ok()) status = st;
    }
  });
  VT_RETURN_IF_ERROR(status);
  return r;
}

// Fills the page-codec rows: the codec alone, and the runtime path with BC1 after it.
// `decode(coded, texels) -> Status` decodes one page.
template <typename Decode>
Status page_codec_rows(const PageSet& set, const CodecBenchOptions& o, const std::string& name,
                       const PageCodecResult& coded, Decode&& decode,
                       std::vector<CodecBenchRow>& rows) {
  const int size = o.page_size;
  const size_t page_texels = size_t(size) * size;
  std::vector<uint8_t> decoded(page_texels * 3);
  // Decodes every page `repeats` times; `after` runs on each decoded page, inside the timing.
  auto decode_all = [&](int repeats, double& seconds, auto&& after) -> Status {
    Status status;
    seconds = time_passes(repeats, [&] {
      for (size_t i = 0; i < coded.coded.size(); ++i) {
        Status st = decode(coded.coded[i], decoded.data());
        if (!st.ok()) status = st;
        after(i, static_cast<const uint8_t*>(decoded.data()));
      }
    });
    return status;
  };
  size_t bytes = coded.table_bytes;
  for (const auto& c : coded.coded) bytes += c.size();
  const double texels = double(set.pages.size()) * double(page_texels);

  ErrorAccumulator acc;
  double dec_s = 0;
  VT_RETURN_IF_ERROR(decode_all(o.repeats, dec_s, [](size_t, const uint8_t*) {}));
  // Quality, untimed: one more pass.
  double unused = 0;
  VT_RETURN_IF_ERROR(decode_all(1, unused, [&](size_t i, const uint8_t* out) {
    acc.add(set.pages[i].image, set.pages[i].texels.data(), out, page_texels, 3);
  }));

  CodecBenchRow row;
  row.section = "page";
  row.name = name;
  row.pages = int(set.pages.size());
  row.bits_per_texel = double(bytes) * 8 / texels;
  row.psnr = acc.mean_psnr();
  row.psnr_pooled = acc.pooled_psnr();
  row.encode_mtex_s = texels / coded.encode_s / 1e6;
  row.decode_mtex_s = texels / dec_s / 1e6;
  row.pages_per_s = double(set.pages.size()) / dec_s;
  row.seconds_per_mtex = coded.encode_s / (texels / 1e6);
  rows.push_back(row);

  // Runtime path: page decode + BC1 real-time encode, timed together; PSNR after BC1.
  std::vector<uint8_t> blocks(bc_image_bytes(BcFormat::kBc1, size, size));
  std::vector<uint8_t> bc_out(page_texels * 3);
  Status status;
  double rt_s = 0;
  VT_RETURN_IF_ERROR(decode_all(o.repeats, rt_s, [&](size_t, const uint8_t* out) {
    Status st =
        bc_encode_image(BcFormat::kBc1, BcQuality::kRealtime, out, size, size, 3, blocks.data());
    if (!st.ok()) status = st;
  }));
  VT_RETURN_IF_ERROR(status);
  ErrorAccumulator after;
  VT_RETURN_IF_ERROR(decode_all(1, unused, [&](size_t i, const uint8_t* out) {
    (void)bc_encode_image(BcFormat::kBc1, BcQuality::kRealtime, out, size, size, 3, blocks.data());
    (void)bc_decode_image(BcFormat::kBc1, blocks.data(), size, size, 3, bc_out.data());
    after.add(set.pages[i].image, set.pages[i].texels.data(), bc_out.data(), page_texels, 3);
  }));
  CodecBenchRow rt = row;
  rt.section = "runtime";
  rt.name = name + " + BC1 realtime";
  rt.encode_mtex_s = 0;
  rt.decode_mtex_s = texels / rt_s / 1e6;
  rt.pages_per_s = double(set.pages.size()) / rt_s;
  rt.psnr_after_bc1 = after.mean_psnr();
  rows.push_back(rt);
  return Status::Ok();
}

// `modes`: the per-page mode decision (format/dct_page_modes.h) as a bake runs it; without, every
// page in the tables' own mode.
Status run_dct(const PageSet& set, const CodecBenchOptions& o, int quality, bool modes,
               std::vector<CodecBenchRow>& rows) {
  const int size = o.page_size;
  DctSettings settings;
  settings.quality = quality;
  settings.channels = 3;
  settings.layout = DctPlaneLayout::kYCoCg420;
  // Tables are fitted to (up to) 64 pages spread over the set, as a bake fits them per layer.
  std::vector<std::span<const uint8_t>> training;
  const size_t step = std::max<size_t>(1, set.pages.size() / 64);
  for (size_t i = 0; i < set.pages.size(); i += step) training.emplace_back(set.pages[i].texels);
  VT_ASSIGN_OR_RETURN(DctTablesPtr tables, dct_make_tables(settings, size, size, training));
  VT_ASSIGN_OR_RETURN(PageCodecResult coded,
                      encode_pages(set, o.repeats, dct_serialize_tables(*tables).size(),
                                   [&](const uint8_t* texels, std::vector<uint8_t>& out) {
                                     out.clear();
                                     if (!modes)
                                       return dct_encode_page(*tables, texels, size, size, out);
                                     return dct_encode_page_modes(*tables, texels, size, 3,
                                                                  {true, 0, 3}, out, nullptr)
                                         .status();
                                   }));
  const size_t page_bytes = size_t(size) * size * 3;
  auto decode = [&](const std::vector<uint8_t>& page, uint8_t* texels) {
    return dct_decode_page_modes(*tables, page, size, {texels, page_bytes});
  };
  return page_codec_rows(set, o, "DCT q" + std::to_string(quality) + (modes ? " modes" : ""), coded,
                         decode, rows);
}

Status run_jpeg(const PageSet& set, const CodecBenchOptions& o, int quality,
                std::vector<CodecBenchRow>& rows) {
  JpegAnchorSettings settings;
  settings.page_size = o.page_size;
  settings.quality = quality;
  VT_ASSIGN_OR_RETURN(JpegPageEncoder encoder, JpegPageEncoder::create(settings));
  VT_ASSIGN_OR_RETURN(PageCodecResult coded,
                      encode_pages(set, o.repeats, encoder.tables().size(),
                                   [&](const uint8_t* texels, std::vector<uint8_t>& out) {
                                     return encoder.encode(texels, out);
                                   }));
  VT_ASSIGN_OR_RETURN(JpegPageDecoder decoder,
                      JpegPageDecoder::create(o.page_size, encoder.tables()));
  auto decode = [&](const std::vector<uint8_t>& page, uint8_t* texels) {
    return decoder.decode(page, texels);
  };
  return page_codec_rows(set, o, "JPEG q" + std::to_string(quality) + " 4:2:0 abbreviated", coded,
                         decode, rows);
}

// ---- normal maps: BC5 with the angular error ----

Status run_bc5_normals(const PageSet& set, const CodecBenchOptions& o, BcQuality q,
                       const std::string& name, std::vector<CodecBenchRow>& rows) {
  const int size = o.page_size;
  const size_t bytes = bc_image_bytes(BcFormat::kBc5, size, size);
  std::vector<uint8_t> blocks(bytes * set.pages.size());
  Status status;
  const double enc = time_passes(o.repeats, [&] {
    for (size_t i = 0; i < set.pages.size(); ++i) {
      Status st = bc_encode_image(BcFormat::kBc5, q, set.pages[i].texels.data(), size, size, 2,
                                  &blocks[i * bytes]);
      if (!st.ok()) status = st;
    }
  });
  VT_RETURN_IF_ERROR(status);
  std::vector<uint8_t> all_ref, all_out;
  ErrorAccumulator acc;
  std::vector<uint8_t> out(size_t(size) * size * 2);
  for (size_t i = 0; i < set.pages.size(); ++i) {
    VT_RETURN_IF_ERROR(
        bc_decode_image(BcFormat::kBc5, &blocks[i * bytes], size, size, 2, out.data()));
    all_ref.insert(all_ref.end(), set.pages[i].texels.begin(), set.pages[i].texels.end());
    all_out.insert(all_out.end(), out.begin(), out.end());
    acc.add(set.pages[i].image, set.pages[i].texels.data(), out.data(), size_t(size) * size, 2);
  }
  VT_ASSIGN_OR_RETURN(AngularError ang, normal_angular_error(all_ref.data(), all_out.data(), size,
                                                             int(set.pages.size()) * size, 2));
  const double texels = double(set.pages.size()) * size * size;
  CodecBenchRow row;
  row.section = "normal";
  row.name = name;
  row.pages = int(set.pages.size());
  row.bits_per_texel = 8;
  row.psnr = acc.mean_psnr();
  row.psnr_pooled = acc.pooled_psnr();
  row.encode_mtex_s = texels / enc / 1e6;
  row.seconds_per_mtex = enc / (texels / 1e6);
  row.angle_mean_deg = ang.mean_deg;
  row.angle_max_deg = ang.max_deg;
  row.angle_p99_deg = ang.p99_deg;
  rows.push_back(row);
  return Status::Ok();
}

// JPEG bits/texel at a PSNR, linear between the measured points; < 0 outside their range.
double jpeg_bits_at(const std::vector<CodecBenchRow>& rows, double psnr) {
  std::vector<std::pair<double, double>> pts;
  for (const auto& r : rows) {
    if (r.section == "page" && r.name.rfind("JPEG", 0) == 0)
      pts.emplace_back(r.psnr, r.bits_per_texel);
  }
  std::sort(pts.begin(), pts.end());
  for (size_t i = 1; i < pts.size(); ++i) {
    if (psnr >= pts[i - 1].first && psnr <= pts[i].first && pts[i].first > pts[i - 1].first) {
      const double t = (psnr - pts[i - 1].first) / (pts[i].first - pts[i - 1].first);
      return pts[i - 1].second + t * (pts[i].second - pts[i - 1].second);
    }
  }
  return -1;
}

}  // namespace

Expected<CodecBenchResult> run_codec_bench(
    const CodecBenchOptions& o, const std::function<void(const std::string&)>& progress) {
  auto say = [&](const std::string& s) {
    if (progress) progress(s);
  };
  if (o.images.empty()) return Error(ErrorCode::kInvalidArgument, "no images given");
  if (o.page_size < 8 || o.page_size % 8 != 0 || o.page_size > 1024) {
    return Error(ErrorCode::kInvalidArgument,
                 "page size " + std::to_string(o.page_size) + " is not a multiple of 8 in 8..1024");
  }
  PageSet colour, normals;
  colour.channels = 3;
  normals.channels = 2;
  for (const std::string& path : o.images) {
    const std::string base = lower(path.substr(path.find_last_of('/') + 1));
    const bool is_normal = base.find("normal") != std::string::npos;
    PageSet& set = is_normal ? normals : colour;
    VT_RETURN_IF_ERROR(load_pages(path, o.page_size, set.channels, set.images++, set));
  }
  if (o.max_pages > 0) {
    if (colour.pages.size() > size_t(o.max_pages)) colour.pages.resize(o.max_pages);
    if (normals.pages.size() > size_t(o.max_pages)) normals.pages.resize(o.max_pages);
  }
  CodecBenchResult result;
  result.colour_pages = int(colour.pages.size());
  result.normal_pages = int(normals.pages.size());

  if (!colour.pages.empty()) {
    const BcSetting bc[] = {
        {"BC1 stb_dxt normal", BcFormat::kBc1, STB_DXT_NORMAL},
        {"BC1 stb_dxt HIGHQUAL", BcFormat::kBc1, STB_DXT_HIGHQUAL},
        {"BC1 vtbake realtime", BcFormat::kBc1, -1, BcQuality::kRealtime},
        {"BC1 vtbake normal", BcFormat::kBc1, -1, BcQuality::kNormal},
        {"BC1 vtbake high (subset)", BcFormat::kBc1, -1, BcQuality::kHigh, true},
        {"BC1 vtbake realtime (subset)", BcFormat::kBc1, -1, BcQuality::kRealtime, true},
        {"BC1 stb_dxt HIGHQUAL (subset)", BcFormat::kBc1, STB_DXT_HIGHQUAL, BcQuality::kRealtime,
         true},
        {"BC3 stb_dxt normal", BcFormat::kBc3, STB_DXT_NORMAL},
        {"BC3 stb_dxt HIGHQUAL", BcFormat::kBc3, STB_DXT_HIGHQUAL},
        {"BC3 vtbake realtime", BcFormat::kBc3, -1, BcQuality::kRealtime},
        {"BC3 vtbake normal", BcFormat::kBc3, -1, BcQuality::kNormal},
        {"BC4 vtbake realtime (channel 0)", BcFormat::kBc4, -1, BcQuality::kRealtime},
        {"BC4 vtbake high (channel 0)", BcFormat::kBc4, -1, BcQuality::kHigh},
        {"BC7 vtbake realtime", BcFormat::kBc7, -1, BcQuality::kRealtime},
        {"BC7 vtbake realtime (subset)", BcFormat::kBc7, -1, BcQuality::kRealtime, true},
        {"BC7 vtbake normal (subset)", BcFormat::kBc7, -1, BcQuality::kNormal, true},
        {"BC7 vtbake high (subset)", BcFormat::kBc7, -1, BcQuality::kHigh, true},
    };
    for (const BcSetting& s : bc) {
      say(s.name);
      CodecBenchRow row;
      if (s.format == BcFormat::kBc4) {
        // BC4 measures channel 0 alone: a one-channel copy of the pages.
        PageSet one;
        one.channels = 1;
        for (const Page& p : colour.pages) {
          Page q;
          q.image = p.image;
          q.texels.resize(p.texels.size() / 3);
          for (size_t i = 0; i < q.texels.size(); ++i) q.texels[i] = p.texels[3 * i];
          one.pages.push_back(std::move(q));
        }
        VT_RETURN_IF_ERROR(run_bc(one, s, o, row));
      } else {
        VT_RETURN_IF_ERROR(run_bc(colour, s, o, row));
      }
      result.rows.push_back(row);
    }
    for (int q : o.dct_qualities) {
      say("DCT q" + std::to_string(q));
      VT_RETURN_IF_ERROR(run_dct(colour, o, q, false, result.rows));
      VT_RETURN_IF_ERROR(run_dct(colour, o, q, true, result.rows));
    }
    for (int q : o.jpeg_qualities) {
      say("JPEG q" + std::to_string(q));
      VT_RETURN_IF_ERROR(run_jpeg(colour, o, q, result.rows));
    }
    for (const auto& r : result.rows) {
      if (r.section != "page" || r.name.rfind("DCT q", 0) != 0) continue;
      if (r.name.find(" modes") != std::string::npos) continue;  // the anchor is the plain mode
      const double jb = jpeg_bits_at(result.rows, r.psnr);
      if (jb > 0)
        result.equal_psnr_bytes_ratio.emplace_back(std::stoi(r.name.substr(5)),
                                                   r.bits_per_texel / jb);
    }
  }
  if (!normals.pages.empty()) {
    say("BC5 normals");
    VT_RETURN_IF_ERROR(
        run_bc5_normals(normals, o, BcQuality::kRealtime, "BC5 vtbake realtime", result.rows));
    VT_RETURN_IF_ERROR(
        run_bc5_normals(normals, o, BcQuality::kNormal, "BC5 vtbake normal", result.rows));
    VT_RETURN_IF_ERROR(
        run_bc5_normals(normals, o, BcQuality::kHigh, "BC5 vtbake high", result.rows));
  }
  return result;
}

std::string codec_bench_text(const CodecBenchResult& r) {
  std::ostringstream s;
  char line[512];
  s << "pages: " << r.colour_pages << " colour, " << r.normal_pages
    << " normal-map (one thread; thread CPU time, median of the timed passes)\n";
  s << "PSNR: mean over images of each image's RGB PSNR (pooled-MSE PSNR in --json); "
       "(subset) rows: the slow settings and their references on the same evenly spread pages\n\n";
  std::snprintf(line, sizeof(line), "| %-40s | %5s | %6s | %8s | %8s | %8s | %9s |\n", "setting",
                "pages", "b/tex", "PSNR dB", "enc Mt/s", "dec Mt/s", "pages/s");
  s << "Block and page codecs\n" << line;
  s << "|" << std::string(42, '-')
    << "|-------|--------|----------|----------|----------|-----------|\n";
  for (const auto& row : r.rows) {
    if (row.section != "bc" && row.section != "page") continue;
    std::snprintf(line, sizeof(line), "| %-40s | %5d | %6.3f | %8.2f | %8.2f | %8.2f | %9s |\n",
                  row.name.c_str(), row.pages, row.bits_per_texel, row.psnr, row.encode_mtex_s,
                  row.decode_mtex_s,
                  row.section == "page" ? std::to_string(int(row.pages_per_s)).c_str() : "");
    s << line;
  }
  s << "\nRuntime path per 128x128 page, one core: page decode + BC1 realtime encode\n";
  std::snprintf(line, sizeof(line), "| %-48s | %6s | %13s | %9s |\n", "path", "b/tex",
                "PSNR after BC1", "pages/s");
  s << line << "|" << std::string(50, '-') << "|--------|---------------|-----------|\n";
  for (const auto& row : r.rows) {
    if (row.section != "runtime") continue;
    std::snprintf(line, sizeof(line), "| %-48s | %6.3f | %13.2f | %9.0f |\n", row.name.c_str(),
                  row.bits_per_texel, row.psnr_after_bc1, row.pages_per_s);
    s << line;
  }
  bool any_normal = false;
  for (const auto& row : r.rows) any_normal |= row.section == "normal";
  if (any_normal) {
    s << "\nNormal maps (XY), BC5: angular error after Z reconstruction\n";
    std::snprintf(line, sizeof(line), "| %-24s | %8s | %9s | %9s | %9s | %8s |\n", "setting",
                  "PSNR dB", "mean deg", "p99 deg", "max deg", "enc Mt/s");
    s << line
      << "|--------------------------|----------|-----------|-----------|-----------|----------|\n";
    for (const auto& row : r.rows) {
      if (row.section != "normal") continue;
      std::snprintf(line, sizeof(line), "| %-24s | %8.2f | %9.3f | %9.3f | %9.3f | %8.2f |\n",
                    row.name.c_str(), row.psnr, row.angle_mean_deg, row.angle_p99_deg,
                    row.angle_max_deg, row.encode_mtex_s);
      s << line;
    }
  }
  s << "\nAccuracy versus time (each knob: PSNR dB at encode seconds per Mtexel)\n";
  for (const auto& row : r.rows) {
    if (row.section == "runtime" || row.seconds_per_mtex <= 0) continue;
    if (row.section == "normal") {
      std::snprintf(line, sizeof(line), "  %-40s %7.3f deg mean angular error  %9.4f s/Mtex\n",
                    row.name.c_str(), row.angle_mean_deg, row.seconds_per_mtex);
    } else {
      std::snprintf(line, sizeof(line), "  %-40s %7.2f dB  %9.4f s/Mtex\n", row.name.c_str(),
                    row.psnr, row.seconds_per_mtex);
    }
    s << line;
  }
  if (!r.equal_psnr_bytes_ratio.empty()) {
    s << "\nEqual-PSNR bytes ratio DCT/JPEG (JPEG's RD curve interpolated at the DCT point's "
         "PSNR)\n";
    for (const auto& [q, ratio] : r.equal_psnr_bytes_ratio) {
      std::snprintf(line, sizeof(line), "  DCT q%-3d %.3f\n", q, ratio);
      s << line;
    }
  }
  return s.str();
}

std::string codec_bench_json(const CodecBenchResult& r) {
  nlohmann::json j;
  j["colour_pages"] = r.colour_pages;
  j["normal_pages"] = r.normal_pages;
  j["rows"] = nlohmann::json::array();
  for (const auto& row : r.rows) {
    nlohmann::json x;
    x["section"] = row.section;
    x["name"] = row.name;
    x["pages"] = row.pages;
    x["bits_per_texel"] = row.bits_per_texel;
    x["psnr_db"] = row.psnr;
    x["psnr_pooled_db"] = row.psnr_pooled;
    x["encode_mtexel_per_s"] = row.encode_mtex_s;
    x["decode_mtexel_per_s"] = row.decode_mtex_s;
    x["pages_per_s"] = row.pages_per_s;
    x["psnr_after_bc1_db"] = row.psnr_after_bc1;
    x["encode_seconds_per_mtexel"] = row.seconds_per_mtex;
    if (row.section == "normal") {
      x["angle_mean_deg"] = row.angle_mean_deg;
      x["angle_p99_deg"] = row.angle_p99_deg;
      x["angle_max_deg"] = row.angle_max_deg;
    }
    j["rows"].push_back(x);
  }
  j["equal_psnr_bytes_ratio_dct_over_jpeg"] = nlohmann::json::array();
  for (const auto& [q, ratio] : r.equal_psnr_bytes_ratio) {
    j["equal_psnr_bytes_ratio_dct_over_jpeg"].push_back({{"dct_quality", q}, {"ratio", ratio}});
  }
  return j.dump(2) + "\n";
}

BenchKind codec_bench_kind() {
  BenchKind k;
  k.name = "codec";
  k.description =
      "Page codecs (DCT vs abbreviated JPEG) and BC encoders (vs stb_dxt): size, PSNR, speed";
  k.inputs_help = "Images (PNG, ...) cut into pages; names containing 'normal' are normal maps";
  k.options = {
      {"page-size", "Page edge in texels", "128"},
      {"dct-qualities", "DCT qualities, comma-separated", "25,50,75,90,95"},
      {"jpeg-qualities", "JPEG qualities, comma-separated", "25,50,75,90,95"},
      {"repeats", "Timed passes per setting (median reported)", "3"},
      {"slow-pages", "Pages for the slow settings (BC1 high, BC7 normal/high)", "48"},
      {"max-pages", "Use at most this many pages per set (0 = all)", "0"},
  };
  k.run = [](const BenchRequest& req) -> Expected<BenchReport> {
    CodecBenchOptions o;
    o.images = req.inputs;
    VT_ASSIGN_OR_RETURN(o.page_size, option_int(req, "page-size", 8, 1024));
    VT_ASSIGN_OR_RETURN(o.dct_qualities, option_int_list(req, "dct-qualities", 1, 100));
    VT_ASSIGN_OR_RETURN(o.jpeg_qualities, option_int_list(req, "jpeg-qualities", 1, 100));
    VT_ASSIGN_OR_RETURN(o.repeats, option_int(req, "repeats", 1, 100));
    VT_ASSIGN_OR_RETURN(o.slow_pages, option_int(req, "slow-pages", 1, 1 << 20));
    VT_ASSIGN_OR_RETURN(o.max_pages, option_int(req, "max-pages", 0, 1 << 20));
    VT_ASSIGN_OR_RETURN(CodecBenchResult r, run_codec_bench(o, req.progress));
    return BenchReport{codec_bench_text(r), codec_bench_json(r)};
  };
  return k;
}

}  // namespace vt::bench
