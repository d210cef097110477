#include "bake/build.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include "bake/color.h"
#include "bake/level_store.h"
#include "bake/paging.h"
#include "common/parallel.h"

namespace vt {
namespace {

constexpr float kFloatMax = std::numeric_limits<float>::max();

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

bool is_colour(LayerSemantic s) {
  return s == LayerSemantic::kAlbedo || s == LayerSemantic::kEmissive;
}

// How one layer goes from its source to stored texels.
struct LayerPlan {
  LayerSpec spec;
  uint32_t source_channels = 0;
  uint32_t work_channels = 0;  // channels of the level images (normals: xyz)
  int alpha = -1;              // alpha channel in the level images, or -1
  bool normal = false;
  bool decode_unorm_normal = false;  // source normals are n * 0.5 + 0.5
  std::shared_ptr<ColorConverter> to_linear;
  std::shared_ptr<ColorConverter> to_storage;
  DownsampleRules rules;
};

Expected<LayerPlan> plan_layer(const LayerInput& in, const BuildOptions& options) {
  LayerPlan p;
  const ImageInfo& info = in.source->info();
  p.spec.semantic = in.semantic;
  p.spec.name = in.name.empty() ? to_string(in.semantic) : in.name;
  p.spec.address_mode = options.address;
  p.source_channels = info.channels;
  if (info.channels < 1 || info.channels > 4) {
    return Status(ErrorCode::kUnsupported, p.spec.name + ": 1-4 channels expected");
  }
  bool want_float = info.is_float && options.codec.codec == CodecKind::kRaw;
  if (in.semantic == LayerSemantic::kNormal) {
    if (info.channels < 2) {
      return Status(ErrorCode::kInvalidArgument, p.spec.name + ": a normal map needs 2+ channels");
    }
    p.normal = true;
    p.decode_unorm_normal = !info.is_float;
    p.work_channels = 3;
    p.spec.channels = 2;
    p.spec.texel_type = TexelType::kU8;
    p.rules.renormalize_xyz = true;
    for (int c = 0; c < 3; ++c) p.rules.min_value[c] = -1, p.rules.max_value[c] = 1;
  } else if (is_colour(in.semantic)) {
    bool has_alpha = info.channels == 2 || info.channels == 4;
    p.work_channels = has_alpha ? 4 : 3;
    p.alpha = has_alpha ? 3 : -1;
    p.spec.channels = uint8_t(p.work_channels);
    p.spec.texel_type = want_float ? TexelType::kF32 : TexelType::kU8;
    std::string src_space = in.color_space.empty() ? info.color_space : in.color_space;
    if (src_space.empty()) src_space = info.is_float ? "linear" : "sRGB";
    auto to_lin = ColorConverter::create(src_space, "linear");
    if (!to_lin.ok()) return to_lin.status().with_context(p.spec.name);
    p.to_linear = std::move(to_lin).value();
    std::string store_space = want_float ? "linear" : "sRGB";
    auto to_store = ColorConverter::create("linear", store_space);
    if (!to_store.ok()) return to_store.status().with_context(p.spec.name);
    p.to_storage = std::move(to_store).value();
    p.spec.color_space = want_float ? ColorSpace::kLinear : ColorSpace::kSrgb;
    for (uint32_t c = 0; c < p.work_channels; ++c) p.rules.min_value[c] = 0;
    if (p.alpha >= 0) p.rules.max_value[p.alpha] = 1;
  } else {
    // ORM and custom layers are data: no colour conversion.
    p.work_channels = info.channels;
    p.spec.channels = uint8_t(info.channels);
    p.spec.texel_type = want_float ? TexelType::kF32 : TexelType::kU8;
    if (!want_float) {
      for (uint32_t c = 0; c < p.work_channels; ++c)
        p.rules.min_value[c] = 0, p.rules.max_value[c] = 1;
    }
  }
  p.rules.address = options.address;
  return p;
}

// Level 0 rows from the source, converted to the layer's working form: non-finite values fixed
// by policy (and counted once per texel), colour converted to linear, alpha premultiplied,
// normals decoded and renormalised.
class Level0Reader {
 public:
  Level0Reader(ImageSource& source, const LayerPlan& plan, NonFinitePolicy policy, int threads)
      : source_(source),
        plan_(plan),
        policy_(policy),
        threads_(threads),
        counted_(source.info().height, false) {}

  uint32_t width() const { return source_.info().width; }
  uint32_t height() const { return source_.info().height; }
  const NonFiniteReport& report() const { return report_; }

  Status read(uint32_t y0, uint32_t y1, float* out) {
    const uint32_t w = width(), sc = plan_.source_channels, wc = plan_.work_channels;
    raw_.resize(size_t(y1 - y0) * w * sc);
    VT_RETURN_IF_ERROR(source_.read_rows(y0, y1, raw_.data()));
    for (uint32_t y = y0; y < y1; ++y) {
      if (!counted_[y]) VT_RETURN_IF_ERROR(scan_row(y, raw_.data() + size_t(y - y0) * w * sc));
    }
    parallel_for(y1 - y0, threads_,
                 [&](size_t k) { convert_row(raw_.data() + k * w * sc, out + k * w * wc); });
    return Status::Ok();
  }

 private:
  // Counts and reports bad values once per row, in raster order.
  Status scan_row(uint32_t y, const float* row) {
    counted_[y] = true;
    const uint32_t w = width(), sc = plan_.source_channels;
    const bool check_negative = is_colour(plan_.spec.semantic);
    for (uint32_t x = 0; x < w; ++x) {
      for (uint32_t c = 0; c < sc; ++c) {
        float v = row[size_t(x) * sc + c];
        bool bad_nf = !std::isfinite(v);
        bool bad_neg = !bad_nf && check_negative && v < 0;
        if (!bad_nf && !bad_neg) continue;
        bool first =
            !report_.any() || y < report_.first_y || (y == report_.first_y && x < report_.first_x);
        if (bad_nf) ++report_.non_finite;
        if (bad_neg) ++report_.negative;
        if (first) {
          report_.first_x = x, report_.first_y = y, report_.first_channel = c;
          report_.first_value = v;
        }
      }
    }
    if (policy_ == NonFinitePolicy::kError && report_.any()) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "%s value %g at texel (%u, %u) channel %u",
                    std::isfinite(report_.first_value) ? "negative" : "non-finite",
                    double(report_.first_value), report_.first_x, report_.first_y,
                    report_.first_channel);
      return Error(ErrorCode::kInvalidArgument, buf);
    }
    return Status::Ok();
  }

  float fix(float v, bool colour) const {
    if (std::isnan(v)) return 0.0f;
    if (std::isinf(v)) {
      if (v < 0) return colour ? 0.0f : -kFloatMax;
      return policy_ == NonFinitePolicy::kClamp ? kFloatMax : 0.0f;
    }
    if (colour && v < 0) return 0.0f;
    return v;
  }

  void convert_row(const float* src, float* dst) const {
    const uint32_t w = width(), sc = plan_.source_channels, wc = plan_.work_channels;
    const bool colour = is_colour(plan_.spec.semantic);
    for (uint32_t x = 0; x < w; ++x) {
      const float* s = src + size_t(x) * sc;
      float* d = dst + size_t(x) * wc;
      if (plan_.normal) {
        double n[3];
        for (int c = 0; c < 3; ++c) {
          double v = c < int(sc) ? fix(s[c], false) : 0.0;
          n[c] = plan_.decode_unorm_normal ? v * 2.0 - 1.0 : v;
        }
        if (sc == 2) n[2] = std::sqrt(std::max(0.0, 1.0 - n[0] * n[0] - n[1] * n[1]));
        double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(len > 1e-30) || !std::isfinite(len)) n[0] = 0, n[1] = 0, n[2] = 1, len = 1;
        for (int c = 0; c < 3; ++c) d[c] = float(n[c] / len);
      } else if (colour) {
        if (sc <= 2) {
          float g = fix(s[0], true);
          d[0] = d[1] = d[2] = g;
          if (sc == 2) d[3] = fix(s[1], true);
        } else {
          for (uint32_t c = 0; c < sc; ++c) d[c] = fix(s[c], true);
        }
      } else {
        for (uint32_t c = 0; c < sc; ++c) d[c] = fix(s[c], false);
      }
    }
    if (colour) {
      plan_.to_linear->apply(dst, w, int(wc));
      for (uint32_t x = 0; x < w; ++x) {
        float* d = dst + size_t(x) * wc;
        for (uint32_t c = 0; c < wc; ++c) {
          // The transfer curve may map an in-range value a hair below zero or up to inf.
          if (!(d[c] >= 0)) d[c] = 0;
          if (d[c] > kFloatMax) d[c] = kFloatMax;
        }
        if (plan_.alpha >= 0) {
          float a = std::min(d[plan_.alpha], 1.0f);
          d[plan_.alpha] = a;
          for (int c = 0; c < 3; ++c) d[c] *= a;
        }
      }
    }
  }

  ImageSource& source_;
  const LayerPlan& plan_;
  NonFinitePolicy policy_;
  int threads_;
  std::vector<bool> counted_;
  std::vector<float> raw_;
  NonFiniteReport report_;
};

// Serves addressed bands of a level read strictly top to bottom: keeps a window of recent rows
// so overlapping bands never re-read, and for wrap pins the rows that the first and last bands
// read across the edge.
class RowWindow {
 public:
  using Reader = std::function<Status(uint32_t y0, uint32_t y1, float* out)>;
  RowWindow(uint32_t width, uint32_t height, uint32_t channels, AddressMode mode, Reader reader)
      : w_(width), h_(height), ch_(channels), mode_(mode), reader_(std::move(reader)) {}

  size_t row_floats() const { return size_t(w_) * ch_; }

  // Wrap: rows [0, top) and [h - bottom, h) are read once up front.
  Status pin(uint32_t top, uint32_t bottom) {
    top = std::min(top, h_);
    bottom = std::min(bottom, h_ - top);
    pin_top_ = top;
    pin_bottom_ = bottom;
    pinned_top_.resize(size_t(top) * row_floats());
    pinned_bottom_.resize(size_t(bottom) * row_floats());
    if (bottom > 0) VT_RETURN_IF_ERROR(reader_(h_ - bottom, h_, pinned_bottom_.data()));
    if (top > 0) VT_RETURN_IF_ERROR(reader_(0, top, pinned_top_.data()));
    return Status::Ok();
  }

  // Rows [y_begin, y_begin + rows) of the level, addressed.
  Expected<RowBand> fetch(int64_t y_begin, uint32_t rows) {
    int64_t a = std::clamp<int64_t>(y_begin, 0, h_ - 1);
    int64_t b = std::clamp<int64_t>(y_begin + rows, a + 1, h_);  // real rows [a, b) needed
    // Drop rows above a; read rows up to b.
    if (a > lo_) {
      int64_t drop = std::min<int64_t>(a, hi_) - lo_;
      if (drop > 0) {
        window_.erase(window_.begin(), window_.begin() + drop * row_floats());
      }
      lo_ = a;
      hi_ = std::max(hi_, lo_);
    }
    if (b > hi_) {
      int64_t from = std::max(hi_, a);
      size_t old = window_.size();
      window_.resize(old + size_t(b - from) * row_floats());
      VT_RETURN_IF_ERROR(reader_(uint32_t(from), uint32_t(b), window_.data() + old));
      hi_ = b;
    }
    band_.resize(size_t(rows) * row_floats());
    for (uint32_t k = 0; k < rows; ++k) {
      int64_t y = address_texel(y_begin + k, h_, mode_);
      const float* src = nullptr;
      if (y >= lo_ && y < hi_) {
        src = window_.data() + size_t(y - lo_) * row_floats();
      } else if (y < pin_top_) {
        src = pinned_top_.data() + size_t(y) * row_floats();
      } else if (y >= int64_t(h_) - pin_bottom_) {
        src = pinned_bottom_.data() + size_t(y - (h_ - pin_bottom_)) * row_floats();
      } else {
        return Status(ErrorCode::kInternal, "row window: row " + std::to_string(y) + " missing");
      }
      std::memcpy(band_.data() + k * row_floats(), src, row_floats() * sizeof(float));
    }
    return RowBand{y_begin, rows, w_, ch_, band_.data()};
  }

  uint64_t bytes() const {
    return (window_.capacity() + band_.capacity() + pinned_top_.capacity() +
            pinned_bottom_.capacity()) *
           sizeof(float);
  }

 private:
  uint32_t w_, h_, ch_;
  AddressMode mode_;
  Reader reader_;
  int64_t lo_ = 0, hi_ = 0;
  std::vector<float> window_;
  std::vector<float> band_;
  int64_t pin_top_ = 0, pin_bottom_ = 0;
  std::vector<float> pinned_top_, pinned_bottom_;
};

// Linear working texels of a page to the layer's stored bytes.
void store_page(const LayerPlan& plan, float alpha_scale, float* texels, size_t count,
                uint8_t* out) {
  const uint32_t wc = plan.work_channels;
  if (plan.alpha >= 0) {
    for (size_t i = 0; i < count; ++i) {
      float* t = texels + i * wc;
      float a = t[plan.alpha];
      for (int c = 0; c < 3; ++c) t[c] = a > 0 ? std::min(t[c] / a, kFloatMax) : 0.0f;
      if (alpha_scale != 1.0f) t[plan.alpha] = std::min(1.0f, a * alpha_scale);
    }
  }
  if (plan.spec.texel_type == TexelType::kF32) {
    if (plan.to_storage) plan.to_storage->apply(texels, count, int(wc));
    std::memcpy(out, texels, count * wc * sizeof(float));
    return;
  }
  if (plan.to_storage) {
    plan.to_storage->apply_to_u8(texels, count, int(wc), out);
    return;
  }
  auto q = [](float v) -> uint8_t {
    if (!(v > 0)) return 0;
    if (v >= 1) return 255;
    return uint8_t(v * 255.0f + 0.5f);
  };
  if (plan.normal) {
    for (size_t i = 0; i < count; ++i) {
      out[i * 2 + 0] = q(texels[i * 3 + 0] * 0.5f + 0.5f);
      out[i * 2 + 1] = q(texels[i * 3 + 1] * 0.5f + 0.5f);
    }
    return;
  }
  for (size_t i = 0; i < count * wc; ++i) out[i] = q(texels[i]);
}

class WriterSink final : public PageSink {
 public:
  explicit WriterSink(PageFileWriter& w) : w_(w) {}
  Status add_page(const PageId& id, uint32_t layer, std::span<const uint8_t> data) override {
    return w_.add_page(id, layer, data);
  }
  Status add_constant_page(const PageId& id, uint32_t layer,
                           std::span<const uint8_t> texel) override {
    return w_.add_constant_page(id, layer, texel);
  }
  Status set_codec_tables(uint32_t layer, std::span<const uint8_t> tables) override {
    return w_.set_codec_tables(layer, tables);
  }

 private:
  PageFileWriter& w_;
};

std::string scratch_dir_for(const BuildOptions& o) {
  if (!o.scratch_dir.empty()) return o.scratch_dir;
  std::filesystem::path p(o.output);
  std::string dir = p.parent_path().string();
  return dir.empty() ? "." : dir;
}

struct Accum {
  double sse = 0;
  uint64_t samples = 0;
  uint32_t max_error = 0;
};

}  // namespace

Expected<NonFinitePolicy> parse_non_finite_policy(const std::string& name) {
  if (name == "black") return NonFinitePolicy::kBlack;
  if (name == "clamp") return NonFinitePolicy::kClamp;
  if (name == "error") return NonFinitePolicy::kError;
  return Status(ErrorCode::kInvalidArgument,
                "unknown non-finite policy '" + name + "' (expected black, clamp or error)");
}

Expected<PageFileDesc> plan_build(const BuildOptions& options) {
  if (options.layers.empty() || options.layers.size() > 16) {
    return Status(ErrorCode::kInvalidArgument, "a build needs 1 to 16 layers");
  }
  PageFileDesc desc;
  const ImageInfo* first = nullptr;
  nlohmann::json sources = nlohmann::json::array();
  for (size_t i = 0; i < options.layers.size(); ++i) {
    const LayerInput& in = options.layers[i];
    if (!in.source) return Status(ErrorCode::kInvalidArgument, "layer without a source");
    const ImageInfo& info = in.source->info();
    if (!first) first = &info;
    if (info.width != first->width || info.height != first->height) {
      return Status(ErrorCode::kInvalidArgument,
                    "layer " + std::to_string(i) + " is " + std::to_string(info.width) + "x" +
                        std::to_string(info.height) + ", layer 0 is " +
                        std::to_string(first->width) + "x" + std::to_string(first->height));
    }
    if (in.coverage && in.coverage->size() != size_t(info.width) * info.height) {
      return Status(ErrorCode::kInvalidArgument,
                    "layer " + std::to_string(i) + ": coverage mask size differs from image size");
    }
    VT_ASSIGN_OR_RETURN(LayerPlan plan, plan_layer(in, options));
    for (const LayerSpec& other : desc.layers) {
      if (other.name == plan.spec.name) {
        return Status(ErrorCode::kInvalidArgument, "two layers named '" + plan.spec.name + "'");
      }
    }
    desc.layers.push_back(plan.spec);
    sources.push_back({{"layer", plan.spec.name}, {"color_space", in.color_space}});
  }
  desc.geometry.width = first->width;
  desc.geometry.height = first->height;
  desc.geometry.payload = options.payload;
  desc.geometry.border = options.border;
  VT_RETURN_IF_ERROR(desc.geometry.validate());
  for (LayerSpec& spec : desc.layers) {
    auto enc = PageEncoder::create(spec, options.codec, desc.geometry.page_size());
    if (!enc.ok()) return enc.status();
  }
  nlohmann::json meta = nlohmann::json::parse(options.metadata_json, nullptr, false);
  if (meta.is_discarded() || !meta.is_object()) meta = nlohmann::json::object();
  meta["build"] = {
      {"filter", to_string(options.filter)},        {"address", to_string(options.address)},
      {"codec", int(options.codec.codec)},          {"dct_quality", options.codec.dct_quality},
      {"dct_adaptive", options.codec.dct_adaptive}, {"layers", sources}};
  desc.metadata_json = meta.dump();
  return desc;
}

Expected<BuildSummary> build_pages(const BuildOptions& options, const PageFileDesc& desc,
                                   PageSink& sink) {
  const PageGeometry& g = desc.geometry;
  const int threads = thread_count(options.threads);
  const uint32_t P = g.payload, S = g.page_size();
  const uint32_t levels = g.level_count();
  const DownsampleKernel kernel = make_downsample_kernel(options.filter);
  const uint32_t margin = std::max<uint32_t>(g.border, uint32_t(kernel.reach()));
  const std::string scratch = scratch_dir_for(options);

  BuildSummary sum;
  sum.geometry = g;
  sum.levels.resize(levels);
  for (uint32_t l = 0; l < levels; ++l) {
    LevelSummary& ls = sum.levels[l];
    ls.width = g.level_width(l), ls.height = g.level_height(l);
    ls.pages_x = g.pages_x(l), ls.pages_y = g.pages_y(l);
  }
  BuildProgress progress;
  progress.pages_total = g.total_pages() * options.layers.size();
  double t_pyramid = 0, t_encode = 0, t_read = 0;

  for (uint32_t li = 0; li < options.layers.size(); ++li) {
    const LayerInput& in = options.layers[li];
    VT_ASSIGN_OR_RETURN(LayerPlan plan, plan_layer(in, options));
    plan.spec = desc.layers[li];
    LayerSpec spec_copy = plan.spec;
    VT_ASSIGN_OR_RETURN(PageEncoder encoder, PageEncoder::create(spec_copy, options.codec, S));
    const uint32_t wc = plan.work_channels;
    const bool covered_all = !in.coverage;
    Level0Reader level0(*in.source, plan, options.non_finite, threads);

    // Working-set estimate (bands, windows, page buffers) so that level storage gets the rest.
    // DCT tables are trained on up to 256 of the layer's own pages or 16 MiB of their texels
    // (all of level 0 for a 2K layer), held uncoded until then, a chunk of a row at a time.
    const size_t training_pages =
        std::clamp<size_t>((size_t(16) << 20) / encoder.page_bytes(), 1, 256);
    constexpr uint32_t kTrainingChunk = 32;
    const uint64_t training_hold =
        encoder.wants_training() ? (training_pages + kTrainingChunk) * encoder.page_bytes() : 0;
    auto working_set = [&](uint32_t width) {
      uint64_t row = uint64_t(width) * wc * sizeof(float);
      uint64_t band_rows = P + 2 * margin;
      // Window, band, read buffer and the allocator's slack on them; 64 MiB for the libraries,
      // the writer's index and thread stacks (measured: ~190 MiB at 16K wide RGB).
      uint64_t ws = row * band_rows * 4 + (uint64_t(64) << 20);
      if (options.address == AddressMode::kWrap) ws += row * (band_rows + margin);
      ws += uint64_t(threads) * (row / 2 * 2 * (16 + kernel.taps()));  // downsample doubles
      ws += row / 2 * (P / 2);                                         // next level's rows
      ws += uint64_t(threads) * S * S * (wc * 4 + 16) * 3;             // page buffers
      ws += uint64_t(g.pages_x(0)) * S * S * 4;                        // encoded pages of a row
      ws += training_hold;
      return ws;
    };

    std::unique_ptr<LevelStore> current;  // level l's texels (l >= 1, or 0 with coverage)
    std::vector<uint8_t> coverage;        // level l's coverage mask (coverage layers)
    if (!covered_all) {
      uint64_t bytes = uint64_t(g.width) * g.height * wc * sizeof(float);
      if (bytes * 5 / 4 * 2 > options.memory_limit) {
        return Status(ErrorCode::kResourceLimit,
                      plan.spec.name +
                          ": a layer with a coverage mask keeps its levels in "
                          "memory; " +
                          std::to_string(bytes >> 20) +
                          " MiB per level does not fit the memory limit");
      }
      auto t0 = Clock::now();
      VT_ASSIGN_OR_RETURN(current, LevelStore::create(g.width, g.height, wc, true, scratch));
      const uint32_t chunk = 256;
      for (uint32_t y = 0; y < g.height; y += chunk) {
        uint32_t y1 = std::min(g.height, y + chunk);
        VT_RETURN_IF_ERROR(level0.read(y, y1, current->data() + size_t(y) * current->row_floats()));
      }
      coverage = *in.coverage;
      pull_push(current->data(), coverage.data(), g.width, g.height, wc);
      t_read += seconds_since(t0);
    }

    Accum acc;
    auto emit = [&](const PageId& id, const EncodedPage& e) -> Status {
      LevelSummary& lsum = sum.levels[id.level];
      if (e.state == PageState::kConstant) {
        ++lsum.constant;
        return sink.add_constant_page(
            id, li, std::span<const uint8_t>(e.constant, plan.spec.texel_bytes()));
      }
      ++lsum.stored;
      lsum.stored_bytes += e.bytes.size();
      acc.sse += e.squared_error;
      acc.samples += e.samples;
      acc.max_error = std::max(acc.max_error, e.max_error);
      return sink.add_page(id, li, e.bytes);
    };
    // DCT tables are trained on the layer's first non-constant level-0 pages: those pages wait,
    // uncoded, until enough are found or level 0 ends, and are then coded with the trained
    // tables like every later page.
    std::vector<std::pair<PageId, std::vector<uint8_t>>> waiting;
    auto train_and_flush = [&]() -> Status {
      std::vector<std::span<const uint8_t>> spans;
      for (const auto& w : waiting) spans.emplace_back(w.second);
      VT_ASSIGN_OR_RETURN(std::vector<uint8_t> tables, encoder.train(spans));
      VT_RETURN_IF_ERROR(sink.set_codec_tables(li, tables));
      plan.spec.codec_tables = std::move(tables);
      std::vector<EncodedPage> coded(waiting.size());
      std::vector<Status> errors(waiting.size());
      parallel_for(waiting.size(), threads, [&](size_t i) {
        errors[i] = encoder.encode(waiting[i].second.data(), coded[i]);
      });
      for (size_t i = 0; i < waiting.size(); ++i) {
        VT_RETURN_IF_ERROR(errors[i]);
        VT_RETURN_IF_ERROR(emit(waiting[i].first, coded[i]));
      }
      waiting.clear();
      return Status::Ok();
    };
    // Coverage-preserving alpha: level 0's fraction of texels at or above the reference, and a
    // histogram of the next level's alpha gathered as its rows are made.
    const float alpha_ref = options.alpha_coverage_reference;
    const bool keep_coverage = alpha_ref > 0 && plan.alpha >= 0;
    constexpr int kAlphaBins = 4096;
    std::vector<uint64_t> alpha_hist(kAlphaBins);
    uint64_t covered0 = 0;
    float alpha_scale = 1.0f;
    for (uint32_t l = 0; l < levels; ++l) {
      const uint32_t lw = g.level_width(l), lh = g.level_height(l);
      const uint32_t px = g.pages_x(l), py = g.pages_y(l);
      const bool last = l + 1 == levels;
      RowWindow::Reader reader;
      if (current) {
        LevelStore* store = current.get();
        reader = [store](uint32_t y0, uint32_t y1, float* out) {
          return store->read_rows(y0, y1 - y0, out);
        };
      } else {
        reader = [&level0](uint32_t y0, uint32_t y1, float* out) {
          return level0.read(y0, y1, out);
        };
      }
      RowWindow window(lw, lh, wc, options.address, reader);
      if (options.address == AddressMode::kWrap) {
        VT_RETURN_IF_ERROR(window.pin(P + 2 * margin, margin));
      }

      // The next level: in memory if it and this one fit in what the working set leaves.
      std::unique_ptr<LevelStore> next;
      if (!last) {
        uint32_t nw = g.level_width(l + 1), nh = g.level_height(l + 1);
        uint64_t next_bytes = uint64_t(nw) * nh * wc * sizeof(float);
        uint64_t cur_bytes = current && current->in_memory() ? current->bytes() : 0;
        uint64_t ws = working_set(lw);
        bool in_memory = !covered_all || (ws < options.memory_limit &&
                                          cur_bytes + next_bytes <= options.memory_limit - ws);
        VT_ASSIGN_OR_RETURN(next, LevelStore::create(nw, nh, wc, in_memory, scratch));
        if (!in_memory) sum.levels[l + 1].scratch = true;
        sum.level_memory_bytes =
            std::max(sum.level_memory_bytes, cur_bytes + (in_memory ? next_bytes : 0));
        uint64_t scratch_now = (current && !current->in_memory() ? current->bytes() : 0) +
                               (in_memory ? 0 : next_bytes);
        sum.scratch_bytes = std::max(sum.scratch_bytes, scratch_now);
      }
      std::vector<float> next_rows;
      std::vector<EncodedPage> encoded(px);
      std::vector<uint8_t> present(px);
      std::vector<std::vector<uint8_t>> held(px);  // texels of pages waiting for training
      const size_t page_texels = size_t(S) * S;

      for (uint32_t r = 0; r < py; ++r) {
        auto t0 = Clock::now();
        int64_t band_begin = int64_t(r) * P - margin;
        VT_ASSIGN_OR_RETURN(RowBand band, window.fetch(band_begin, P + 2 * margin));
        t_read += seconds_since(t0);
        if (keep_coverage && l == 0) {
          for (uint32_t y = r * P; y < std::min(lh, r * P + P); ++y) {
            const float* row = band.row(y);
            for (uint32_t x = 0; x < lw; ++x)
              covered0 += row[size_t(x) * wc + plan.alpha] >= alpha_ref;
          }
        }

        // Pages of this row, encoded in parallel; while the tables wait for training, in
        // chunks, so that at most a training set and a chunk of uncoded pages are held.
        t0 = Clock::now();
        std::vector<Status> errors(px);
        for (uint32_t x0 = 0; x0 < px;) {
          const bool training = encoder.wants_training();
          const uint32_t x1 = training ? std::min(px, x0 + kTrainingChunk) : px;
          parallel_for(x1 - x0, threads, [&](size_t i) {
            const uint32_t x = x0 + uint32_t(i);
            PageId id{l, x, r};
            present[x] = covered_all || page_has_coverage(g, id, coverage.data());
            if (!present[x]) return;
            thread_local std::vector<float> page;
            thread_local std::vector<uint8_t> bytes;
            page.resize(page_texels * wc);
            bytes.resize(encoder.page_bytes());
            cut_page(g, id, options.address, band, page.data());
            store_page(plan, alpha_scale, page.data(), page_texels, bytes.data());
            if (training && !encoder.is_constant(bytes.data())) {
              held[x] = bytes;
            } else {
              errors[x] = encoder.encode(bytes.data(), encoded[x]);
            }
          });
          for (uint32_t x = x0; x < x1; ++x) {
            PageId id{l, x, r};
            VT_RETURN_IF_ERROR(errors[x].with_context(plan.spec.name + " page (" +
                                                      std::to_string(l) + ", " + std::to_string(x) +
                                                      ", " + std::to_string(r) + ")"));
            if (!present[x]) {
              ++sum.levels[l].absent;
            } else if (!held[x].empty()) {
              waiting.emplace_back(id, std::move(held[x]));
              held[x].clear();
            } else {
              VT_RETURN_IF_ERROR(emit(id, encoded[x]));
            }
          }
          if (training && (waiting.size() >= training_pages || (x1 == px && r + 1 == py))) {
            VT_RETURN_IF_ERROR(train_and_flush());
          }
          x0 = x1;
        }
        t_encode += seconds_since(t0);

        // This band's share of the next level.
        if (!last) {
          t0 = Clock::now();
          uint32_t y0 = r * (P / 2);
          uint32_t y1 = std::min(next->height(), y0 + P / 2);
          if (y1 > y0) {
            next_rows.resize(size_t(y1 - y0) * next->row_floats());
            constexpr uint32_t kRowsPerTask = 8;
            size_t tasks = (y1 - y0 + kRowsPerTask - 1) / kRowsPerTask;
            parallel_for(tasks, threads, [&](size_t t) {
              uint32_t a = y0 + uint32_t(t) * kRowsPerTask;
              uint32_t b = std::min(y1, a + kRowsPerTask);
              downsample_rows(kernel, plan.rules, band, a, b,
                              next_rows.data() + size_t(a - y0) * next->row_floats());
            });
            VT_RETURN_IF_ERROR(next->write_rows(y0, y1 - y0, next_rows.data()));
            if (keep_coverage) {
              for (size_t i = size_t(plan.alpha); i < next_rows.size(); i += wc) {
                ++alpha_hist[std::clamp(int(next_rows[i] * kAlphaBins), 0, kAlphaBins - 1)];
              }
            }
          }
          t_pyramid += seconds_since(t0);
        }
        progress.stage = "pyramid+encode";
        progress.layer = li;
        progress.level = l;
        progress.pages_done += px;
        if (options.progress) options.progress(progress);
      }
      if (!last) {
        if (!covered_all) {
          auto t0 = Clock::now();
          coverage = downsample_coverage(coverage.data(), lw, lh);
          pull_push(next->data(), coverage.data(), next->width(), next->height(), wc);
          t_pyramid += seconds_since(t0);
        }
        if (keep_coverage) {
          // The alpha threshold that as large a fraction of the next level passes as level 0,
          // and the scale that moves it onto the reference (bounded: 1/4 to 4).
          uint64_t n = uint64_t(next->width()) * next->height();
          double target = double(covered0) / (double(g.width) * g.height) * double(n);
          uint64_t above = 0;
          int bin = kAlphaBins - 1;
          for (; bin > 0; --bin) {
            above += alpha_hist[bin];
            if (double(above) >= target) break;
          }
          double threshold = double(bin) / kAlphaBins;
          alpha_scale = threshold > 0 ? float(std::clamp(alpha_ref / threshold, 0.25, 4.0)) : 4.0f;
          if (covered0 == 0) alpha_scale = 1.0f;  // nothing to preserve
          std::fill(alpha_hist.begin(), alpha_hist.end(), 0);
        }
        current = std::move(next);
      }
    }

    LayerSummary ls;
    ls.name = plan.spec.name;
    ls.spec = plan.spec;
    ls.max_error = acc.max_error;
    ls.psnr_db = acc.samples == 0 || acc.sse == 0
                     ? std::numeric_limits<double>::infinity()
                     : 10.0 * std::log10(255.0 * 255.0 * double(acc.samples) / acc.sse);
    ls.non_finite = level0.report();
    ls.alpha_dropped = options.layers[li].alpha_dropped;
    sum.layers.push_back(std::move(ls));
  }
  for (const LevelSummary& ls : sum.levels) {
    sum.stored += ls.stored, sum.constant += ls.constant, sum.absent += ls.absent;
    sum.stored_bytes += ls.stored_bytes;
  }
  sum.pages = sum.stored + sum.constant + sum.absent;
  sum.stages = {{"read", t_read}, {"pyramid", t_pyramid}, {"encode", t_encode}};
  return sum;
}

Status drop_opaque_alpha(BuildOptions& options) {
  for (LayerInput& in : options.layers) {
    if (in.semantic != LayerSemantic::kAlbedo || in.alpha_dropped || !in.source) continue;
    const uint32_t ch = in.source->info().channels;
    if (ch != 2 && ch != 4) continue;
    VT_ASSIGN_OR_RETURN(bool opaque, channel_is_opaque(*in.source, ch - 1));
    if (!opaque) continue;
    in.source = std::make_shared<DropChannelSource>(in.source, ch - 1);
    in.alpha_dropped = true;
  }
  return Status();
}

Expected<BuildSummary> build_page_file(const BuildOptions& opts) {
  if (opts.output.empty()) return Status(ErrorCode::kInvalidArgument, "no output path");
  BuildOptions options = opts;
  VT_RETURN_IF_ERROR(drop_opaque_alpha(options));
  VT_ASSIGN_OR_RETURN(PageFileDesc desc, plan_build(options));
  VT_ASSIGN_OR_RETURN(auto writer, PageFileWriter::create(options.output, desc));
  WriterSink sink(*writer);
  VT_ASSIGN_OR_RETURN(BuildSummary sum, build_pages(options, desc, sink));
  auto t0 = Clock::now();
  if (options.progress) {
    BuildProgress p;
    p.stage = "finish";
    p.pages_done = p.pages_total = sum.pages;
    options.progress(p);
  }
  VT_RETURN_IF_ERROR(writer->finish().with_context(options.output));
  sum.stages.push_back({"finish", seconds_since(t0)});
  std::error_code ec;
  sum.file_bytes = std::filesystem::file_size(options.output, ec);
  return sum;
}

}  // namespace vt
