#include "bake/level_source.h"

#define XXH_STATIC_LINKING_ONLY  // XXH3_state_t on the stack
#include <xxhash.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "bake/build_plan.h"
#include "bake/level_store.h"
#include "common/half.h"
#include "common/parallel.h"

namespace vt {
namespace {

constexpr float kFloatMax = std::numeric_limits<float>::max();

// What converting a layer's source rows needs, copied out of its LayerPlan: a streamed level 0
// lives as long as the plan that owns it, and must not point into that plan's storage.
struct Conversion {
  explicit Conversion(const LayerPlan& p)
      : source_channels(p.source_channels),
        work_channels(p.work_channels),
        alpha(p.alpha),
        normal(p.normal),
        decode_unorm_normal(p.decode_unorm_normal),
        colour(p.colour),
        clips((p.spec.texel_type == TexelType::kU8 && !p.normal) ||
              p.spec.texel_type == TexelType::kF16),
        clip_limit(p.spec.texel_type == TexelType::kF16 ? kHalfMax : 1.0f),
        to_linear(p.to_linear) {}
  uint32_t source_channels, work_channels;
  int alpha;
  bool normal, decode_unorm_normal, colour;
  // Stored in 8 bits, values outside [0, 1] are clipped (normals never are); in half floats,
  // values beyond +-kHalfMax. Alpha is clamped to [0, 1] whatever the storage.
  bool clips;
  float clip_limit;  // 1 or kHalfMax
  std::shared_ptr<const ColorConverter> to_linear;
};

// Source rows to the layer's working form: non-finite values fixed by policy (and counted once
// per texel), colour converted to linear, alpha premultiplied, normals decoded and renormalised.
class Level0Converter {
 public:
  // `origin` names the source file for messages ("" when the texels are not a file's).
  Level0Converter(const LayerPlan& plan, const std::string& origin, uint32_t width, uint32_t height,
                  NonFinitePolicy policy, int threads)
      : conv_(plan),
        where_((origin.empty() ? "" : origin + ": ") + "layer '" + plan.spec.name + "'"),
        width_(width),
        policy_(policy),
        threads_(threads),
        counted_(height, false),
        clip_counted_(conv_.clips ? height : 0, false) {}

  const NonFiniteReport& report() const { return report_; }
  const ClipReport& clipped() const { return clipped_; }
  const Conversion& conversion() const { return conv_; }

  // Counts and reports bad values of source row y once, in raster order; with kError the first
  // bad texel seen fails the read.
  Status scan_row(uint32_t y, const float* row) {
    if (counted_[y]) return Status::Ok();
    counted_[y] = true;
    const uint32_t sc = conv_.source_channels;
    for (uint32_t x = 0; x < width_; ++x) {
      for (uint32_t c = 0; c < sc; ++c) {
        const float v = row[size_t(x) * sc + c];
        const bool bad_nf = !std::isfinite(v);
        const bool bad_neg = !bad_nf && conv_.colour && v < 0;
        if (!bad_nf && !bad_neg) continue;
        const bool first =
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
      char buf[256];
      std::snprintf(buf, sizeof buf,
                    ": %s value %g at texel (%u, %u) channel %u (--fix-nonfinite error; black "
                    "or clamp repairs it)",
                    std::isfinite(report_.first_value) ? "negative" : "non-finite",
                    double(report_.first_value), report_.first_x, report_.first_y,
                    report_.first_channel);
      return Error(ErrorCode::kInvalidArgument, where_ + buf);
    }
    return Status::Ok();
  }

  // Counts the values of row y that the layer's storage clips, once: `src` is the source row,
  // `work` the row convert() made of it.
  void count_clipped(uint32_t y, const float* src, const float* work) {
    if (!conv_.clips || clip_counted_[y]) return;
    clip_counted_[y] = true;
    const uint32_t sc = conv_.source_channels, wc = conv_.work_channels;
    const float hi = conv_.clip_limit, lo = hi == 1.0f ? 0.0f : -hi;
    auto out_of_range = [&](float v, bool& any, float lo, float hi) {
      if (!(v < lo || v > hi) || std::abs(v) >= kFloatMax) return;  // in range or non-finite
      if (clipped_.values == 0) clipped_.max_value = clipped_.min_value = v;
      clipped_.max_value = std::max(clipped_.max_value, v);
      clipped_.min_value = std::min(clipped_.min_value, v);
      ++clipped_.values;
      any = true;
    };
    for (uint32_t x = 0; x < width_; ++x) {
      const float* s = src + size_t(x) * sc;
      const float* d = work + size_t(x) * wc;
      bool any = false;
      if (conv_.colour) {
        // Linear colour as stored (unpremultiplied); negatives were fixed and reported.
        const float a = conv_.alpha >= 0 ? d[conv_.alpha] : 1.0f;
        if (a > 0)
          for (int c = 0; c < 3; ++c)
            if (d[c] < kFloatMax) out_of_range(d[c] / a, any, lo, hi);
        // The source alpha, before its clamp.
        if (conv_.alpha >= 0) out_of_range(s[sc - 1], any, 0.0f, 1.0f);
      } else {
        for (uint32_t c = 0; c < wc; ++c) out_of_range(d[c], any, lo, hi);
      }
      clipped_.texels += any;
    }
  }

  // Converts `rows` source rows into working rows, on all threads. `src` may equal `dst` when
  // the source and working channel counts are the same (each texel is read before written).
  void convert(const float* src, float* dst, uint32_t rows) const {
    const size_t in_row = size_t(width_) * conv_.source_channels;
    const size_t out_row = size_t(width_) * conv_.work_channels;
    parallel_for(rows, threads_,
                 [&](size_t k) { convert_row(src + k * in_row, dst + k * out_row); });
  }

 private:
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
    const uint32_t w = width_, sc = conv_.source_channels, wc = conv_.work_channels;
    const bool colour = conv_.colour;
    for (uint32_t x = 0; x < w; ++x) {
      const float* s = src + size_t(x) * sc;
      float* d = dst + size_t(x) * wc;
      if (conv_.normal) {
        double n[3];
        for (int c = 0; c < 3; ++c) {
          double v = c < int(sc) ? fix(s[c], false) : 0.0;
          n[c] = conv_.decode_unorm_normal ? v * 2.0 - 1.0 : v;
        }
        if (sc == 2) n[2] = std::sqrt(std::max(0.0, 1.0 - n[0] * n[0] - n[1] * n[1]));
        double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(len > 1e-30) || !std::isfinite(len)) n[0] = 0, n[1] = 0, n[2] = 1, len = 1;
        for (int c = 0; c < 3; ++c) d[c] = float(n[c] / len);
      } else if (colour) {
        if (sc <= 2) {
          float g = fix(s[0], true);
          float a = sc == 2 ? fix(s[1], true) : 0.0f;
          d[0] = d[1] = d[2] = g;
          if (sc == 2) d[3] = a;
        } else {
          for (uint32_t c = 0; c < sc; ++c) d[c] = fix(s[c], true);
        }
      } else {
        for (uint32_t c = 0; c < sc; ++c) d[c] = fix(s[c], false);
      }
    }
    if (!colour) return;
    conv_.to_linear->apply(dst, w, int(wc));
    for (uint32_t x = 0; x < w; ++x) {
      float* d = dst + size_t(x) * wc;
      for (uint32_t c = 0; c < wc; ++c) {
        // The transfer curve may map an in-range value a hair below zero or up to inf.
        if (!(d[c] >= 0)) d[c] = 0;
        if (d[c] > kFloatMax) d[c] = kFloatMax;
      }
      if (conv_.alpha >= 0) {
        float a = std::min(d[conv_.alpha], 1.0f);
        d[conv_.alpha] = a;
        for (int c = 0; c < 3; ++c) d[c] *= a;
      }
    }
  }

  const Conversion conv_;
  const std::string where_;
  uint32_t width_;
  NonFinitePolicy policy_;
  int threads_;
  std::vector<bool> counted_;
  NonFiniteReport report_;
  std::vector<bool> clip_counted_;
  ClipReport clipped_;
};

// Level 0 read from the source and converted as the build asks for rows.
class StreamedLevel0 final : public LevelSource {
 public:
  StreamedLevel0(std::shared_ptr<ImageSource> source, const LayerPlan& plan, NonFinitePolicy policy,
                 int threads, bool count)
      : source_(std::move(source)),
        converter_(plan, source_->origin(), source_->info().width, source_->info().height, policy,
                   threads),
        count_(count) {}

  uint32_t width() const override { return source_->info().width; }
  uint32_t height() const override { return source_->info().height; }
  uint32_t channels() const override { return converter_.conversion().work_channels; }
  NonFiniteReport non_finite() const override { return converter_.report(); }
  ClipReport clipped() const override { return converter_.clipped(); }

  Status read(uint32_t y0, uint32_t y1, float* out) override {
    const size_t in_row = size_t(width()) * converter_.conversion().source_channels;
    raw_.resize(size_t(y1 - y0) * in_row);
    VT_RETURN_IF_ERROR(source_->read_rows(y0, y1, raw_.data()));
    if (count_) {
      for (uint32_t y = y0; y < y1; ++y)
        VT_RETURN_IF_ERROR(converter_.scan_row(y, raw_.data() + size_t(y - y0) * in_row));
    }
    converter_.convert(raw_.data(), out, y1 - y0);
    if (count_) {
      for (uint32_t y = y0; y < y1; ++y)
        converter_.count_clipped(y, raw_.data() + size_t(y - y0) * in_row,
                                 out + size_t(y - y0) * row_floats());
    }
    return Status::Ok();
  }

 private:
  std::shared_ptr<ImageSource> source_;
  Level0Converter converter_;
  bool count_;
  std::vector<float> raw_;
};

// Level 0 converted whole, with its coverage mask, and dilated.
class HeldLevel0 final : public LevelSource {
 public:
  HeldLevel0(std::shared_ptr<LevelStore> store, NonFiniteReport report, ClipReport clipped)
      : store_(std::move(store)), report_(report), clipped_(clipped) {}
  uint32_t width() const override { return store_->width(); }
  uint32_t height() const override { return store_->height(); }
  uint32_t channels() const override { return store_->channels(); }
  Status read(uint32_t y0, uint32_t y1, float* out) override { return store_->read(y0, y1, out); }
  const CoverageMask* coverage() const override { return store_->coverage(); }
  bool in_memory() const override { return store_->in_memory(); }
  LevelStore* held_store() override { return store_.get(); }
  NonFiniteReport non_finite() const override { return report_; }
  ClipReport clipped() const override { return clipped_; }

 private:
  std::shared_ptr<LevelStore> store_;
  NonFiniteReport report_;
  ClipReport clipped_;
};

Expected<std::shared_ptr<LevelSource>> hold_level0(const LayerInput& input, const LayerPlan& plan,
                                                   const BuildOptions& options) {
  const ImageInfo& info = input.source->info();
  const uint32_t w = info.width, h = info.height, wc = plan.work_channels;
  const uint64_t bytes = uint64_t(w) * h * wc * sizeof(float);
  // Held in memory when it and the next level, for every layer (all layers' level 0 are held
  // from the plan on), fit well within the limit; else in a scratch file.
  const bool in_memory = level0_fits_memory(bytes * options.layers.size(), options.memory_limit);
  Level0Converter converter(plan, input.source->origin(), w, h, options.non_finite,
                            thread_count(options.threads));
  const size_t in_row = size_t(w) * plan.source_channels, out_row = size_t(w) * wc;
  // Scene bakes hand over their transfer buffers: converted in place, level 0 costs no copy.
  std::vector<float> texels;
  if (in_memory && input.consume_source && plan.source_channels == wc)
    texels = input.source->release_texels();
  const bool in_place = texels.size() == size_t(h) * out_row;
  // A scene bake's scratch-file layer is converted in its own file: no second copy on disk. Its
  // rows are hashed as read, so the source keeps its identity (the plan hashes it after).
  auto* stored = dynamic_cast<StoredImageSource*>(input.source.get());
  std::shared_ptr<LevelStore> own;
  if (!in_memory && input.consume_source && stored && plan.source_channels == wc)
    own = stored->scratch_store();
  XXH3_state_t own_hash;
  XXH3_64bits_reset(&own_hash);
  std::shared_ptr<LevelStore> store;
  if (in_place) {
    store = LevelStore::adopt(w, h, wc, std::move(texels));
  } else if (own) {
    store = own;
  } else {
    const std::string dir = scratch_dir_for(options);
    VT_ASSIGN_OR_RETURN(
        store, LevelStore::create(w, h, wc, in_memory, dir,
                                  !in_memory && (options.compress_scratch ||
                                                 scratch_needs_compression(
                                                     uint64_t(w) * h * wc * sizeof(float), dir))));
  }
  std::vector<float> raw, converted;
  // Chunks of a few MiB of source rows (at least one row).
  const uint32_t chunk = uint32_t(std::clamp<size_t>((size_t(16) << 20) / (out_row * 4), 1, 256));
  for (uint32_t y = 0; y < h; y += chunk) {
    const uint32_t y1 = std::min(h, y + chunk);
    float* dst = in_memory ? store->data() + size_t(y) * out_row : nullptr;
    if (!dst) converted.resize(size_t(y1 - y) * out_row), dst = converted.data();
    const float* src = dst;
    if (!in_place) {
      raw.resize(size_t(y1 - y) * in_row);
      VT_RETURN_IF_ERROR(input.source->read_rows(y, y1, raw.data()));
      src = raw.data();
      if (own) XXH3_64bits_update(&own_hash, src, raw.size() * sizeof(float));
    }
    for (uint32_t r = y; r < y1; ++r)
      VT_RETURN_IF_ERROR(converter.scan_row(r, src + size_t(r - y) * in_row));
    converter.convert(src, dst, y1 - y);
    // (Converted in place, the source alpha is already clamped: only colour is counted.)
    for (uint32_t r = y; r < y1; ++r)
      converter.count_clipped(r, src + size_t(r - y) * in_row, dst + size_t(r - y) * out_row);
    if (!in_memory) VT_RETURN_IF_ERROR(store->write_rows(y, y1 - y, dst));
  }
  if (own) stored->spent(XXH3_64bits_digest(&own_hash));
  VT_RETURN_IF_ERROR(store->set_coverage_and_dilate(input.coverage, dilation_budget(options),
                                                    scratch_dir_for(options)));
  return std::shared_ptr<LevelSource>(
      new HeldLevel0(std::move(store), converter.report(), converter.clipped()));
}

}  // namespace

Expected<std::shared_ptr<LevelSource>> open_level0(const LayerInput& input, const LayerPlan& plan,
                                                   const BuildOptions& options,
                                                   bool count_bad_values) {
  if (input.coverage) return hold_level0(input, plan, options);
  return std::shared_ptr<LevelSource>(new StreamedLevel0(
      input.source, plan, options.non_finite, thread_count(options.threads), count_bad_values));
}

}  // namespace vt
