// The scheduler: runs a plan's tasks (build_tasks.h) in order, each on all cores.
#include "bake/build.h"

#define XXH_STATIC_LINKING_ONLY  // XXH3_state_t on the stack
#include <xxhash.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "bake/build_plan.h"
#include "bake/build_tasks.h"
#include "bake/level_store.h"
#include "bake/paging.h"
#include "bake/row_window.h"
#include "common/parallel.h"

namespace vt {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
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

 private:
  PageFileWriter& w_;
};

// Coverage-preserving alpha (BuildOptions::alpha_coverage_reference): level 0's fraction of
// texels at or above the reference, and the next level's alpha histogram as its rows are made.
struct AlphaCoverage {
  static constexpr int kBins = 4096;
  bool active = false;
  float reference = 0;
  uint64_t covered0 = 0;
  std::vector<uint64_t> histogram = std::vector<uint64_t>(kBins);
  float scale = 1.0f;  // applied to the alpha of the level being paged

  // The alpha threshold that as large a fraction of the finished level passes as level 0, and
  // the scale that moves it onto the reference (bounded: 1/4 to 4).
  void finish_level(uint64_t level_texels, uint64_t level0_texels) {
    const double target = double(covered0) / double(level0_texels) * double(level_texels);
    uint64_t above = 0;
    int bin = kBins - 1;
    for (; bin > 0; --bin) {
      above += histogram[bin];
      if (double(above) >= target) break;
    }
    const double threshold = double(bin) / kBins;
    scale = threshold > 0 ? float(std::clamp(reference / threshold, 0.25, 4.0)) : 4.0f;
    if (covered0 == 0) scale = 1.0f;  // nothing to preserve
    std::fill(histogram.begin(), histogram.end(), 0);
  }
};

struct ErrorSum {
  double sse = 0;
  uint64_t samples = 0;
  uint32_t max_error = 0;
  RuntimeError runtime;
  HdrError hdr;
  uint64_t dct_modes[kDctModeKinds] = {};
};

// The state of one layer while its tasks run: the level being paged (read through a row
// window) and the next level being written.
class LayerRun {
 public:
  LayerRun(const BuildPlan& plan, uint32_t li, PageSink& sink, BuildSummary& sum)
      : plan_(plan),
        g_(plan.desc.geometry),
        li_(li),
        layer_(plan.layers[li]),
        sink_(sink),
        sum_(sum) {
    alpha_.active = plan.options.alpha_coverage_reference > 0 && layer_.alpha >= 0;
    alpha_.reference = plan.options.alpha_coverage_reference;
    if (plan.previous)
      previous_layer_ = layer_.copy_previous ? layer_.previous_layer
                                             : plan.previous->layer_index(layer_.spec.name);
    sum_.page_keys[li].assign(g_.total_pages(), 0);
  }

  // Makes `level` the one being paged (level 0 from the plan's source, later ones from the
  // store the previous level wrote, or BuildOptions::level_from's) and opens the next level's
  // store (none with given levels).
  Status begin_level(uint32_t level) {
    if (level == 0) {
      current_ = layer_.level0;
      VT_RETURN_IF_ERROR(take_given_levels());
    } else if (!given_.empty()) {
      current_ = given_[level].source;
      alpha_.scale = given_[level].alpha_scale;
    } else {
      current_ = std::move(next_);
      if (plan_.options.level_done) {
        VT_RETURN_IF_ERROR(plan_.options.level_done(li_, level, *current_, alpha_.scale));
      }
    }
    level_ = level;
    window_ = std::make_unique<RowWindow>(*current_, plan_.options.address);
    if (plan_.options.address == AddressMode::kWrap) {
      VT_RETURN_IF_ERROR(window_->pin(g_.payload + 2 * plan_.margin, plan_.margin));
    }
    if (level + 1 == g_.level_count() || !given_.empty()) return Status::Ok();
    const bool in_memory = layer_.level_in_memory[level + 1];
    std::unique_ptr<LevelStore> next;
    VT_ASSIGN_OR_RETURN(next,
                        LevelStore::create(g_.level_width(level + 1), g_.level_height(level + 1),
                                           layer_.work_channels, in_memory, plan_.scratch_dir,
                                           plan_.compress_scratch));
    // Levels held at once: this one (unless streamed from the source) and the next.
    const uint64_t cur = level_bytes(*current_), nxt = next->bytes();
    const bool cur_in_memory = layer_.level_in_memory[level],
               cur_streamed = level == 0 && !cur_in_memory && !current_->coverage();
    if (!in_memory) sum_.levels[level + 1].scratch = true;
    sum_.level_memory_bytes =
        std::max(sum_.level_memory_bytes, (cur_in_memory ? cur : 0) + (in_memory ? nxt : 0));
    sum_.scratch_bytes = std::max(
        sum_.scratch_bytes, (cur_in_memory || cur_streamed ? 0 : cur) + (in_memory ? 0 : nxt));
    next_ = std::move(next);
    return Status::Ok();
  }

  // A band task: the pages of page row `row`, and the rows of the next level they cover.
  // Without `encode` the pages are another shard's (BuildOptions::task_subset): only counted.
  Expected<uint64_t> run_band(uint32_t row, bool encode, uint32_t& pages, double& t_read,
                              double& t_encode, double& t_pyramid) {
    const uint32_t P = g_.payload, m = plan_.margin, l = level_;
    if (!encode && !given_.empty()) return uint64_t(0);  // another shard's, and no pyramid to feed
    auto t0 = Clock::now();
    VT_ASSIGN_OR_RETURN(RowBand band, window_->fetch(int64_t(row) * P - m, P + 2 * m));
    t_read += seconds_since(t0);
    const uint64_t key = band_key(band, row);
    if (alpha_.active && l == 0) count_level0_alpha(band, row);
    t0 = Clock::now();
    VT_ASSIGN_OR_RETURN(const std::vector<uint8_t> present, present_pages(row));
    pages = uint32_t(std::count(present.begin(), present.end(), uint8_t(1)));
    if (encode) VT_RETURN_IF_ERROR(encode_row(band, row, present));
    t_encode += seconds_since(t0);
    if (next_) {
      t0 = Clock::now();
      VT_RETURN_IF_ERROR(downsample_band(band, row));
      t_pyramid += seconds_since(t0);
    }
    return key;
  }

  // Update mode, a layer whose pages are the previous file's (LayerPlan::copy_previous): every
  // one copied, in task order.
  Status copy_previous() {
    for (uint32_t l = 0; l < g_.level_count(); ++l)
      for (uint32_t y = 0; y < g_.pages_y(l); ++y)
        for (uint32_t x = 0; x < g_.pages_x(l); ++x) {
          const PageId id{l, x, y};
          const uint64_t key = plan_.previous->key(previous_layer_, id);
          EncodedPage e;
          if (key != 0) {
            VT_ASSIGN_OR_RETURN(const bool copied, reuse(id, key, e));
            if (!copied)
              return Status(ErrorCode::kCorrupt, plan_.previous->reader().path() + ": " +
                                                     layer_.spec.name + " " + page_name(id) +
                                                     " has a key but no page");
          }
          VT_RETURN_IF_ERROR(emit(id, key != 0, key, e, true));
        }
    return Status::Ok();
  }

  // One byte per page of page row `row`: 1 = some payload texel covered (all, without a mask).
  Expected<std::vector<uint8_t>> present_pages(uint32_t row) const {
    if (const CoverageMask* coverage = current_->coverage())
      return pages_with_coverage(g_, level_, row, *coverage);
    return std::vector<uint8_t>(g_.pages_x(level_), 1);
  }

  // A level task: the level just written is complete; dilate it and settle its alpha scale.
  Status finish_level() {
    if (!next_) return Status::Ok();
    if (const CoverageMask* cov = current_->coverage()) {
      const bool in_memory =
          CoverageMask::fits_memory(next_->width(), next_->height(), plan_.options.memory_limit);
      VT_ASSIGN_OR_RETURN(std::shared_ptr<CoverageMask> half,
                          cov->downsample(in_memory, plan_.scratch_dir));
      VT_RETURN_IF_ERROR(next_->set_coverage_and_dilate(
          std::move(half), dilation_budget(plan_.options), plan_.scratch_dir));
    }
    if (alpha_.active) {
      alpha_.finish_level(uint64_t(next_->width()) * next_->height(),
                          uint64_t(g_.width) * g_.height);
    }
    return Status::Ok();
  }

  uint32_t layer() const { return li_; }
  uint32_t level() const { return level_; }

  LayerSummary summary() const {
    LayerSummary ls;
    ls.name = layer_.spec.name;
    ls.spec = layer_.spec;
    ls.max_error = error_.max_error;
    ls.runtime = error_.runtime;
    ls.hdr = error_.hdr;
    std::copy(std::begin(error_.dct_modes), std::end(error_.dct_modes), ls.dct_modes);
    ls.psnr_db = error_.samples == 0 || error_.sse == 0
                     ? std::numeric_limits<double>::infinity()
                     : 10.0 * std::log10(255.0 * 255.0 * double(error_.samples) / error_.sse);
    ls.alpha_dropped = plan_.options.layers[li_].alpha_dropped;
    if (layer_.copy_previous) {
      ls.psnr_db = std::numeric_limits<double>::quiet_NaN();  // not measured: nothing encoded
      return ls;
    }
    ls.non_finite = layer_.level0->non_finite();
    ls.clipped = layer_.level0->clipped();
    return ls;
  }

 private:
  static uint64_t level_bytes(const LevelSource& s) {
    return uint64_t(s.width()) * s.height() * s.channels() * sizeof(float);
  }

  // hash(layer's task seed, task, alpha scale, input rows): equal keys mean equal output.
  uint64_t band_key(const RowBand& band, uint32_t row) const {
    XXH3_state_t state;
    XXH3_INITSTATE(&state);  // reset_withSeed reads the state's old seed
    XXH3_64bits_reset_withSeed(&state, layer_.task_seed);
    const uint32_t id[3] = {li_, level_, row};
    XXH3_64bits_update(&state, id, sizeof id);
    XXH3_64bits_update(&state, &alpha_.scale, sizeof alpha_.scale);
    XXH3_64bits_update(&state, band.data,
                       size_t(band.rows) * band.width * band.channels * sizeof(float));
    return XXH3_64bits_digest(&state);
  }

  // BuildOptions::level_from's coarser levels, all or none, checked against the geometry.
  Status take_given_levels() {
    given_.clear();
    if (!plan_.options.level_from) return Status::Ok();
    std::vector<BuildOptions::GivenLevel> given(g_.level_count());
    uint32_t count = 0;
    for (uint32_t l = 1; l < g_.level_count(); ++l) {
      VT_ASSIGN_OR_RETURN(given[l], plan_.options.level_from(li_, l));
      const LevelSource* s = given[l].source.get();
      if (!s) continue;
      ++count;
      if (s->width() != g_.level_width(l) || s->height() != g_.level_height(l) ||
          s->channels() != layer_.work_channels) {
        return Status(ErrorCode::kInvalidArgument, layer_.spec.name + ": the given level " +
                                                       std::to_string(l) +
                                                       " is not the layer's working form");
      }
    }
    if (count == 0) return Status::Ok();
    if (count + 1 != g_.level_count()) {
      return Status(ErrorCode::kInvalidArgument, layer_.spec.name + ": " + std::to_string(count) +
                                                     " of " + std::to_string(g_.level_count() - 1) +
                                                     " coarser levels given");
    }
    given_ = std::move(given);
    return Status::Ok();
  }

  void count_level0_alpha(const RowBand& band, uint32_t row) {
    const uint32_t P = g_.payload, w = current_->width(), wc = layer_.work_channels;
    for (uint32_t y = row * P; y < std::min(current_->height(), row * P + P); ++y) {
      const float* r = band.row(y);
      for (uint32_t x = 0; x < w; ++x)
        alpha_.covered0 += r[size_t(x) * wc + layer_.alpha] >= alpha_.reference;
    }
  }

  // hash(layer's task seed, page, alpha scale, its bordered working texels): page_task_key.
  uint64_t page_key(const PageId& id, const std::vector<float>& texels) const {
    return page_task_key(layer_.task_seed, id, alpha_.scale, texels);
  }

  // The previous file's page under the same key (update mode), as an encoded page.
  Expected<bool> reuse(const PageId& id, uint64_t key, EncodedPage& out) const {
    if (previous_layer_ < 0 || plan_.previous->key(previous_layer_, id) != key) return false;
    const PageFileReader& reader = plan_.previous->reader();
    VT_ASSIGN_OR_RETURN(const PageEntry entry, reader.entry(id, uint32_t(previous_layer_)));
    out.state = entry.state;
    if (entry.state == PageState::kConstant) {
      std::copy(std::begin(entry.constant), std::end(entry.constant), out.constant);
    } else if (entry.state == PageState::kStored) {
      VT_ASSIGN_OR_RETURN(out.bytes, reader.read_stored(id, uint32_t(previous_layer_)));
    } else {
      return false;
    }
    return true;
  }

  Status encode_row(const RowBand& band, uint32_t row, const std::vector<uint8_t>& present) {
    const uint32_t px = g_.pages_x(level_), S = g_.page_size();
    const size_t page_texels = size_t(S) * S;
    std::vector<EncodedPage> encoded(px);
    std::vector<uint8_t> reused(px);
    std::vector<uint64_t> keys(px);
    std::vector<Status> errors(px);
    parallel_for(px, plan_.threads, [&](size_t x) {
      const PageId id{level_, uint32_t(x), row};
      if (!present[x]) return;
      thread_local std::vector<float> page, reference;
      thread_local std::vector<uint8_t> bytes;
      page.resize(page_texels * layer_.work_channels);
      bytes.resize(layer_.encoder->page_bytes());
      // 8-bit layers: the unclipped values, when clipped; half layers: the floats before rounding.
      const TexelType type = layer_.spec.texel_type;
      reference.resize(type == TexelType::kU8    ? bytes.size()
                       : type == TexelType::kF16 ? bytes.size() / 2
                                                 : 0);
      cut_page(g_, id, plan_.options.address, band, page.data());
      keys[x] = page_key(id, page);
      auto copied = reuse(id, keys[x], encoded[x]);
      if (!copied.ok() || *copied) {
        errors[x] = copied.status();
        reused[x] = 1;
        return;
      }
      const bool clipped = layer_.store_page(page.data(), S, alpha_.scale, bytes.data(),
                                             reference.empty() ? nullptr : reference.data());
      const bool measure = type == TexelType::kF16 || (clipped && !reference.empty());
      errors[x] =
          layer_.encoder->encode(bytes.data(), encoded[x], measure ? reference.data() : nullptr);
    });
    for (uint32_t x = 0; x < px; ++x) {
      const PageId id{level_, x, row};
      VT_RETURN_IF_ERROR(errors[x].with_context(layer_.spec.name + " " + page_name(id)));
      VT_RETURN_IF_ERROR(emit(id, present[x], keys[x], encoded[x], reused[x]));
    }
    return Status::Ok();
  }

  // A page to the sink and the summary (absent unless `present`).
  Status emit(const PageId& id, bool present, uint64_t key, const EncodedPage& e, bool reused) {
    LevelSummary& lsum = sum_.levels[id.level];
    if (!present) {
      ++lsum.absent;
      return Status::Ok();
    }
    sum_.page_keys[li_][page_key_index(g_, id)] = key;
    ++(reused ? sum_.update.reused : sum_.update.reencoded);
    if (e.state == PageState::kConstant) {
      ++lsum.constant;
      error_.sse += e.squared_error;  // a clipped constant page's error (else nothing)
      error_.samples += e.samples;
      error_.max_error = std::max(error_.max_error, e.max_error);
      error_.hdr.add(e.hdr);  // a half page's rounding
      return sink_.add_constant_page(
          id, li_, std::span<const uint8_t>(e.constant, layer_.spec.texel_bytes()));
    }
    ++lsum.stored;
    lsum.stored_bytes += e.bytes.size();
    error_.sse += e.squared_error;
    error_.samples += e.samples;
    error_.max_error = std::max(error_.max_error, e.max_error);
    error_.runtime.add(e.runtime);
    error_.hdr.add(e.hdr);
    if (layer_.spec.codec == PageCodec::kDct) ++error_.dct_modes[e.dct_mode];
    return sink_.add_page(id, li_, e.bytes);
  }

  Status downsample_band(const RowBand& band, uint32_t row) {
    const uint32_t half = g_.payload / 2;
    const uint32_t y0 = row * half, y1 = std::min(next_->height(), y0 + half);
    if (y1 <= y0) return Status::Ok();
    next_rows_.resize(size_t(y1 - y0) * next_->row_floats());
    // The level's coverage keeps the filter inside each chart (downsample_rows).
    const CoverageMask* mask = current_->coverage();
    CoverageBand coverage;
    if (mask) {
      VT_RETURN_IF_ERROR(mask->read_addressed_rows(band.y_begin, band.rows, plan_.options.address,
                                                   band_coverage_));
      coverage = {band.y_begin, band.rows, band.width, mask->height(), band_coverage_.data()};
    }
    constexpr uint32_t kRowsPerItem = 8;
    parallel_for((y1 - y0 + kRowsPerItem - 1) / kRowsPerItem, plan_.threads, [&](size_t t) {
      const uint32_t a = y0 + uint32_t(t) * kRowsPerItem, b = std::min(y1, a + kRowsPerItem);
      downsample_rows(plan_.kernel, layer_.rules, band, a, b,
                      next_rows_.data() + size_t(a - y0) * next_->row_floats(),
                      mask ? &coverage : nullptr);
    });
    VT_RETURN_IF_ERROR(next_->write_rows(y0, y1 - y0, next_rows_.data()));
    if (alpha_.active) {
      const uint32_t wc = layer_.work_channels;
      for (size_t i = size_t(layer_.alpha); i < next_rows_.size(); i += wc) {
        ++alpha_.histogram[std::clamp(int(next_rows_[i] * AlphaCoverage::kBins), 0,
                                      AlphaCoverage::kBins - 1)];
      }
    }
    return Status::Ok();
  }

  const BuildPlan& plan_;
  const PageGeometry& g_;
  const uint32_t li_;
  const LayerPlan& layer_;
  PageSink& sink_;
  BuildSummary& sum_;
  uint32_t level_ = 0;
  std::shared_ptr<LevelSource> current_;
  std::unique_ptr<LevelStore> next_;
  std::vector<BuildOptions::GivenLevel> given_;  // empty, or one per level (0 unused)
  std::unique_ptr<RowWindow> window_;
  std::vector<float> next_rows_;
  std::vector<uint8_t> band_coverage_;  // the band's coverage rows (downsample_band)
  AlphaCoverage alpha_;
  ErrorSum error_;
  int previous_layer_ = -1;  // the same layer in the previous file (update mode)
};

// One line for a layer whose 8-bit storage clipped values (LayerSummary::clipped).
std::string clip_warning(const LayerInput& in, const LayerSummary& l) {
  const ClipReport& c = l.clipped;
  const bool half = l.spec.texel_type == TexelType::kF16;
  char range[96];
  if (c.min_value < 0 && c.max_value > 1) {
    std::snprintf(range, sizeof range, "from %g to %g", double(c.min_value), double(c.max_value));
  } else if (c.max_value > 1) {
    std::snprintf(range, sizeof range, "up to %g", double(c.max_value));
  } else {
    std::snprintf(range, sizeof range, "down to %g", double(c.min_value));
  }
  const std::string origin = in.source ? in.source->origin() : "";
  return (origin.empty() ? "" : origin + ": ") + "layer '" + l.name +
         "': " + std::to_string(c.texels) + " texels (" + std::to_string(c.values) +
         " values) outside " +
         (half ? "the half-float range (+-65504; alpha [0, 1]), " : "[0, 1], ") + range +
         (half ? ", clipped by its half-float storage (--float-texels float keeps the range)"
               : std::string(", clipped by its 8-bit ") + to_string(l.spec.codec) +
                     " storage; its PSNR counts the clipping (--float-texels half or float "
                     "keeps the range)");
}

// The plan's metadata with the provenance merged in and the update record (bake/update.h).
std::string final_metadata(const BuildPlan& plan, const BuildSummary& sum) {
  UpdateRecord r;
  r.tool = VTBAKE_VERSION;
  r.plan_hash = plan.hash;
  r.settings_key = plan.settings_key;
  r.input_key = plan.options.input_key;
  for (const LayerPlan& layer : plan.layers) {
    r.layer_names.push_back(layer.spec.name);
    r.layer_inputs.push_back(layer.input_key);
  }
  r.page_keys = sum.page_keys;
  return with_update_record(merge_metadata(plan.desc.metadata_json, plan.options.provenance_json),
                            r);
}

}  // namespace

Expected<BuildSummary> summarize_unchanged(const PreviousBuild& previous) {
  const PageFileReader& reader = previous.reader();
  const PageGeometry& g = reader.geometry();
  BuildSummary sum;
  sum.geometry = g;
  sum.plan_hash = previous.record().plan_hash;
  sum.update.requested = true;
  sum.update.unchanged = true;
  sum.page_keys = previous.record().page_keys;
  for (uint32_t l = 0; l < g.level_count(); ++l) {
    LevelSummary ls;
    ls.width = g.level_width(l), ls.height = g.level_height(l);
    ls.pages_x = g.pages_x(l), ls.pages_y = g.pages_y(l);
    for (uint32_t layer = 0; layer < reader.layers().size(); ++layer)
      for (uint32_t y = 0; y < ls.pages_y; ++y)
        for (uint32_t x = 0; x < ls.pages_x; ++x) {
          VT_ASSIGN_OR_RETURN(const PageEntry e, reader.entry(PageId{l, x, y}, layer));
          if (e.state == PageState::kStored) ++ls.stored, ls.stored_bytes += e.size;
          if (e.state == PageState::kConstant) ++ls.constant;
          if (e.state == PageState::kAbsent) ++ls.absent;
        }
    sum.stored += ls.stored, sum.constant += ls.constant, sum.absent += ls.absent;
    sum.stored_bytes += ls.stored_bytes;
    sum.levels.push_back(ls);
  }
  sum.pages = sum.stored + sum.constant + sum.absent;
  sum.update.reused = sum.stored + sum.constant;
  for (const LayerSpec& spec : reader.layers()) {
    LayerSummary ls;
    ls.name = spec.name;
    ls.spec = spec;
    ls.psnr_db = std::numeric_limits<double>::quiet_NaN();  // not measured: nothing encoded
    sum.layers.push_back(ls);
  }
  sum.file_bytes = reader.file_size();
  return sum;
}

void ClipReport::add(const ClipReport& o) {
  if (!o.any()) return;
  max_value = any() ? std::max(max_value, o.max_value) : o.max_value;
  min_value = any() ? std::min(min_value, o.min_value) : o.min_value;
  texels += o.texels;
  values += o.values;
}

Expected<NonFinitePolicy> parse_non_finite_policy(const std::string& name) {
  if (name == "black") return NonFinitePolicy::kBlack;
  if (name == "clamp") return NonFinitePolicy::kClamp;
  if (name == "error") return NonFinitePolicy::kError;
  return Status(ErrorCode::kInvalidArgument,
                "unknown non-finite policy '" + name + "' (expected black, clamp or error)");
}

Expected<BuildSummary> build_pages(const BuildPlan& plan, PageSink& sink) {
  const PageGeometry& g = plan.desc.geometry;
  BuildSummary sum;
  sum.geometry = g;
  sum.plan_hash = plan.hash;
  sum.update = plan.update;
  sum.page_keys.resize(plan.layers.size());
  sum.levels.resize(g.level_count());
  for (uint32_t l = 0; l < g.level_count(); ++l) {
    LevelSummary& ls = sum.levels[l];
    ls.width = g.level_width(l), ls.height = g.level_height(l);
    ls.pages_x = g.pages_x(l), ls.pages_y = g.pages_y(l);
  }
  BuildProgress progress;
  progress.stage = "pyramid+encode";
  progress.pages_total = g.total_pages() * plan.layers.size();
  double t_read = 0, t_encode = 0, t_pyramid = 0;

  const std::vector<BuildTask> tasks = make_build_tasks(plan);
  sum.task_keys.assign(tasks.size(), 0);
  sum.task_seconds.assign(tasks.size(), 0.0);
  sum.task_pages.assign(tasks.size(), 0);
  const std::vector<uint8_t>* subset = plan.options.task_subset.get();
  if (subset && subset->size() != tasks.size()) {
    return Status(ErrorCode::kInvalidArgument, "task subset of " + std::to_string(subset->size()) +
                                                   " flags for " + std::to_string(tasks.size()) +
                                                   " tasks");
  }
  std::vector<bool> done(tasks.size());
  std::unique_ptr<LayerRun> run;
  // Layers before `end` that copy the previous file's pages (they have no tasks), in order.
  uint32_t copied_up_to = 0;
  auto copy_layers_before = [&](uint32_t end) -> Status {
    for (; copied_up_to < end; ++copied_up_to) {
      if (!plan.layers[copied_up_to].copy_previous) continue;
      LayerRun copy(plan, copied_up_to, sink, sum);
      VT_RETURN_IF_ERROR(copy.copy_previous());
      sum.layers.push_back(copy.summary());
    }
    return Status::Ok();
  };
  for (size_t i = 0; i < tasks.size(); ++i) {
    const BuildTask& t = tasks[i];
    for (uint32_t d : t.deps) {
      if (!done[d]) return Status(ErrorCode::kInternal, "build task run before its input");
    }
    const auto t_task = Clock::now();
    if (!run || run->layer() != t.layer) {
      if (run) sum.layers.push_back(run->summary());
      VT_RETURN_IF_ERROR(copy_layers_before(t.layer));
      copied_up_to = t.layer + 1;
      run = std::make_unique<LayerRun>(plan, t.layer, sink, sum);
      VT_RETURN_IF_ERROR(run->begin_level(0));
    }
    if (t.kind == BuildTask::Kind::kLevel) {
      auto t0 = Clock::now();
      VT_RETURN_IF_ERROR(run->finish_level());
      t_pyramid += seconds_since(t0);
      VT_RETURN_IF_ERROR(run->begin_level(t.level));
    } else {
      if (t.level != run->level()) VT_RETURN_IF_ERROR(run->begin_level(t.level));
      const bool encode = !subset || (*subset)[i];
      VT_ASSIGN_OR_RETURN(sum.task_keys[i], run->run_band(t.row, encode, sum.task_pages[i], t_read,
                                                          t_encode, t_pyramid));
      progress.layer = t.layer;
      progress.level = t.level;
      progress.pages_done += g.pages_x(t.level);
      if (plan.options.progress) plan.options.progress(progress);
    }
    sum.task_seconds[i] = seconds_since(t_task);
    done[i] = true;
  }
  if (run) sum.layers.push_back(run->summary());
  VT_RETURN_IF_ERROR(copy_layers_before(uint32_t(plan.layers.size())));
  for (const LevelSummary& ls : sum.levels) {
    sum.stored += ls.stored, sum.constant += ls.constant, sum.absent += ls.absent;
    sum.stored_bytes += ls.stored_bytes;
  }
  sum.pages = sum.stored + sum.constant + sum.absent;
  sum.stages = {{"read", t_read}, {"pyramid", t_pyramid}, {"encode", t_encode}};
  sum.warnings = plan.warnings;
  for (size_t li = 0; li < sum.layers.size(); ++li)
    if (sum.layers[li].clipped.any())
      sum.warnings.push_back(clip_warning(plan.options.layers[li], sum.layers[li]));
  if (plan.previous) {
    for (size_t li = 0; li < plan.layers.size(); ++li) {
      const int previous = plan.previous->layer_index(plan.layers[li].spec.name);
      sum.update.dropped += count_dropped(*plan.previous, previous, g, sum.page_keys[li]);
    }
  }
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
  auto t0 = Clock::now();
  VT_ASSIGN_OR_RETURN(BuildPlan plan, plan_build(options));
  const double t_plan = seconds_since(t0);
  if (plan.unchanged) {
    VT_ASSIGN_OR_RETURN(BuildSummary sum, summarize_unchanged(*plan.previous));
    sum.stages.insert(sum.stages.begin(), StageTime{"plan", t_plan});
    return sum;
  }
  VT_ASSIGN_OR_RETURN(auto writer, PageFileWriter::create(options.output, plan.desc));
  WriterSink sink(*writer);
  VT_ASSIGN_OR_RETURN(BuildSummary sum, build_pages(plan, sink));
  sum.stages.insert(sum.stages.begin(), StageTime{"plan", t_plan});
  writer->set_metadata_json(final_metadata(plan, sum));
  t0 = Clock::now();
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
