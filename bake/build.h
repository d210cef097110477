// The build pipeline: level-0 texels of one or more layers in, a page file out, as three steps.
// The plan (build_plan.h) decides everything up front: each layer's conversion to linear working
// space and its encoder with DCT tables trained on the layer's own pages, the file's final
// header, where each level lives. The tasks (build_tasks.h) cut the work into page rows of a
// level: filter the mip pyramid (pyramid.h), dilate uncovered texels (pull-push), cut bordered
// pages (paging.h), encode them (page_encoder.h) on all cores. build_pages runs the tasks and
// streams the pages to a sink. Memory stays within BuildOptions::memory_limit: level 0 is read
// in bands of page rows and never held whole (unless a coverage mask asks for pull-push),
// coarser levels too large for the budget live in scratch files beside the output. The output
// bytes do not depend on the thread count.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bake/coverage_mask.h"
#include "bake/image_source.h"
#include "bake/page_encoder.h"
#include "bake/pyramid.h"
#include "bake/update.h"
#include "common/status.h"
#include "format/dct_page_modes.h"
#include "format/page_file.h"

namespace vt {

class ColorConfig;
class LevelSource;

// What happens to NaN/Inf inputs, and to negative values in colour layers.
enum class NonFinitePolicy : uint8_t {
  kBlack = 0,  // NaN, Inf and negatives become 0
  kClamp = 1,  // NaN and negatives become 0, +Inf the largest float
  kError = 2,  // the build fails naming the first bad texel
};
Expected<NonFinitePolicy> parse_non_finite_policy(const std::string& name);

struct LayerInput {
  LayerSemantic semantic = LayerSemantic::kAlbedo;
  std::string name;  // "" = the semantic's name
  // Normal maps: the source holds xyz (or xy) in [0, 1] as n * 0.5 + 0.5 unless float.
  std::shared_ptr<ImageSource> source;
  // Colour layers: "" = ColorConfig::texture_space of the source's metadata
  // (ImageInfo::color_space): sRGB for 8/16-bit data and the working space for float data.
  std::string color_space;
  // Optional level-0 coverage (the image's size); null = all covered. With a mask, every level
  // is dilated by pull-push and pages with no covered payload texel are absent.
  std::shared_ptr<const CoverageMask> coverage;
  bool alpha_dropped = false;  // set by drop_opaque_alpha: the source's alpha was all 1
  // The build may take an in-memory source's texels (ImageSource::release_texels) as its
  // level 0 and convert them in place instead of copying them; the source is empty afterwards.
  bool consume_source = false;
};

// Progress of the running build, reported from the calling thread after every page row.
struct BuildProgress {
  const char* stage = "";  // "pyramid+encode", "finish"
  uint32_t layer = 0;
  uint32_t level = 0;
  uint64_t pages_done = 0;  // over all layers and levels
  uint64_t pages_total = 0;
};

struct BuildOptions {
  std::vector<LayerInput> layers;  // 1..16, all the same size
  std::string output;              // the .vtpf path
  PageEncoderOptions codec;
  uint32_t payload = 120;
  uint32_t border = 4;
  MipFilter filter = MipFilter::kKaiser;
  AddressMode address = AddressMode::kClamp;
  uint64_t memory_limit = uint64_t(2) << 30;
  int threads = 0;  // 0 = all cores
  NonFinitePolicy non_finite = NonFinitePolicy::kBlack;
  // Coverage-preserving alpha (alpha-tested foliage, fences): when > 0, each level's alpha is
  // scaled so that the fraction of texels with alpha >= this reference matches level 0's.
  float alpha_coverage_reference = 0;
  std::string scratch_dir;  // "" = the output's directory
  // Scratch levels compressed in chunks whatever their size (else where
  // scratch_needs_compression says: bake/level_store.h).
  bool compress_scratch = false;
  // Colour spaces of the colour layers (LayerInput::color_space, metadata) are this config's;
  // its scene_linear role is the working space. Null = the built-in config (bake/color.h).
  std::shared_ptr<const ColorConfig> color_config;
  std::string metadata_json = "{}";
  // Recorded in the metadata but outside the plan hash and the task keys (source paths: the
  // same inputs reached by another path give the same keys).
  std::string provenance_json = "{}";
  // Update mode (bake/update.h). With `update`, the previous output (update_from, "" = output)
  // has its pages whose task key is unchanged copied, and its DCT tables pinned unless
  // retrain_tables is set or they fit the new pages worse than kRetrainFitBound. With the same
  // plan as the previous file nothing is written. tables_from: a page file whose DCT tables the
  // layers of the same name use instead of training. input_key: the caller's key of what it
  // derived the layers from, recorded for its own unchanged check (a scene bake's scene).
  bool update = false;
  std::string update_from;
  std::string tables_from;
  bool retrain_tables = false;
  uint64_t input_key = 0;
  // Sharding over a build farm (bake/shard.h): when set, one flag per task of make_build_tasks.
  // A band task not flagged encodes and emits none of its pages (they are another shard's); it
  // still reads its rows, computes its key and writes its share of the next level, unless the
  // coarser levels are given (level_from): then it does nothing.
  std::shared_ptr<const std::vector<uint8_t>> task_subset;
  // Sharding: the levels of layer i in their working form as a farm's plan job wrote them (level 0
  // converted and dilated as open_level0 gives it; each coarser level dilated as the pyramid makes
  // it, with the alpha scale its pages are stored with), so that a shard reads its pages' rows
  // instead of redoing the pyramid. A null source = made here as usual; the coarser levels are
  // given all or none.
  struct GivenLevel {
    std::shared_ptr<LevelSource> source;
    float alpha_scale = 1.0f;
  };
  std::function<Expected<GivenLevel>(size_t layer, uint32_t level)> level_from;
  // The plan job's side: each coarser level (1, 2, ...) of layer i once it is complete, before its
  // pages are cut.
  std::function<Status(size_t layer, uint32_t level, LevelSource& texels, float alpha_scale)>
      level_done;
  std::function<void(const BuildProgress&)> progress;
};

struct NonFiniteReport {
  uint64_t non_finite = 0;  // NaN or Inf channel values
  uint64_t negative = 0;    // negative channel values in colour layers
  bool any() const { return non_finite + negative > 0; }
  // The first bad texel in raster order.
  uint32_t first_x = 0, first_y = 0, first_channel = 0;
  float first_value = 0;
};

// Level-0 texels with a value outside what the layer stores: [0, 1] in an 8-bit layer (an HDR
// or out-of-range float source), +-65504 in a half-float one; the stored texels clip them.
// Colour layers count the linear colour before the transfer curve and alpha (always [0, 1]) as
// given; data layers (ORM, custom) every channel; normal layers never clip, nor do 32-bit float
// layers. Non-finite values are NonFiniteReport's, not counted here.
struct ClipReport {
  uint64_t texels = 0;  // texels with at least one channel out of range
  uint64_t values = 0;  // channel values out of range
  float max_value = 0;  // the largest and smallest out-of-range values (0 when none)
  float min_value = 0;
  bool any() const { return texels > 0; }
  void add(const ClipReport& o);
};

struct LevelSummary {
  uint32_t width = 0, height = 0, pages_x = 0, pages_y = 0;
  uint64_t stored = 0, constant = 0, absent = 0;  // over all layers
  uint64_t stored_bytes = 0;
  bool scratch = false;  // held in a scratch file (for at least one layer)
};

struct LayerSummary {
  std::string name;
  LayerSpec spec;      // as written (codec, runtime format, channels, texel type)
  double psnr_db = 0;  // stored pages vs unencoded texels; infinite when lossless
  uint32_t max_error = 0;
  // After the runtime BC format (codec/runtime_error.h; no samples without a BC format), and
  // the stored pages per DCT page mode (format/dct_page_modes.h).
  RuntimeError runtime;
  uint64_t dct_modes[kDctModeKinds] = {};
  // Half-float layers: the stored pages' HDR error (raw halves or BC6H blocks) against the float
  // values they were rounded from (psnr_db is then infinite: 8-bit figures do not apply).
  HdrError hdr;
  NonFiniteReport non_finite;
  // Out-of-range values the storage clipped. In an 8-bit layer psnr_db, max_error and the
  // runtime figures are then measured against the unclipped values (clipping counts as error;
  // a colour's under alpha times that alpha, as it composites: LayerPlan::store_page).
  ClipReport clipped;
  bool alpha_dropped = false;  // the input's alpha was opaque everywhere and is not stored
};

struct StageTime {
  std::string name;
  double seconds = 0;
};

struct BuildSummary {
  PageGeometry geometry;
  std::vector<LevelSummary> levels;
  std::vector<LayerSummary> layers;
  uint64_t pages = 0, stored = 0, constant = 0, absent = 0;
  uint64_t stored_bytes = 0;
  uint64_t file_bytes = 0;
  uint64_t scratch_bytes = 0;       // largest scratch file use at any time
  uint64_t level_memory_bytes = 0;  // largest in-memory level storage at any time
  std::vector<StageTime> stages;
  uint64_t plan_hash = 0;           // BuildPlan::hash
  std::vector<uint64_t> task_keys;  // per task of make_build_tasks (0 for level tasks)
  // Per task: its wall time (s) and, for band tasks, its pages with some coverage (those it
  // encodes or would encode): the cost figures of a farm's task graph (bake/shard.h).
  std::vector<double> task_seconds;
  std::vector<uint32_t> task_pages;
  // What the build could not honour, e.g. a memory limit below its floor (BuildPlan), and one
  // line per layer whose values were clipped (LayerSummary::clipped).
  std::vector<std::string> warnings;
  // page_keys[layer][page_key_index(id)]: each page's task key (0 = absent), as recorded.
  std::vector<std::vector<uint64_t>> page_keys;
  UpdateSummary update;
};

// Receives the pages of a build; PageFileWriter is the usual one, tests collect them.
class PageSink {
 public:
  virtual ~PageSink() = default;
  virtual Status add_page(const PageId& id, uint32_t layer, std::span<const uint8_t> data) = 0;
  virtual Status add_constant_page(const PageId& id, uint32_t layer,
                                   std::span<const uint8_t> texel) = 0;
};

struct BuildPlan;  // build_plan.h: plan_build(options)

// Runs the plan's tasks into `sink` (for a file: a writer created with plan.desc). The plan's
// level-0 sources are read once and consumed: run a plan once.
Expected<BuildSummary> build_pages(const BuildPlan& plan, PageSink& sink);

// Alpha is kept only where some texel is not opaque: for every albedo layer whose source has
// alpha (2 or 4 channels), reads the source once in bounded bands and, when every alpha is
// >= 1, replaces the source by one without the alpha channel (so the layer is RGB, BC1 rather
// than BC3) and sets LayerInput::alpha_dropped. Runs before plan_build.
Status drop_opaque_alpha(BuildOptions& options);

// The summary of an update that found nothing changed: the previous file's pages, all reused.
Expected<BuildSummary> summarize_unchanged(const PreviousBuild& previous);

// drop_opaque_alpha + plan_build + a PageFileWriter at options.output + build_pages + finish.
// Nothing is left under options.output on failure.
Expected<BuildSummary> build_page_file(const BuildOptions& options);

}  // namespace vt
