#include "bake/build_plan.h"

#define XXH_STATIC_LINKING_ONLY  // XXH3_state_t on the stack
#include <xxhash.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>

#include "bake/level_source.h"
#include "bake/level_store.h"
#include "bake/paging.h"
#include "bake/pyramid.h"
#include "bake/row_window.h"
#include "common/half.h"
#include "common/parallel.h"

#ifndef VTBAKE_VERSION
#define VTBAKE_VERSION "unknown"
#endif

namespace vt {
namespace {

constexpr float kFloatMax = std::numeric_limits<float>::max();

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
  // Float sources keep floats when asked (PageEncoderOptions::float_texels), else 8 bits.
  TexelType float_type = TexelType::kU8;
  if (info.is_float) {
    switch (options.codec.float_texels) {
      case FloatTexels::kAuto:
        if (options.codec.codec == CodecKind::kRaw) float_type = TexelType::kF32;
        break;
      case FloatTexels::kHalf:
        float_type = TexelType::kF16;
        break;
      case FloatTexels::kFloat:
        float_type = TexelType::kF32;
        break;
    }
  }
  // Lighting (and lit albedo) is HDR by nature: half float unless 32-bit float is asked.
  if (is_light(in.semantic) && info.is_float && float_type == TexelType::kU8)
    float_type = TexelType::kF16;
  const bool want_float = float_type != TexelType::kU8;
  if (in.semantic == LayerSemantic::kNormal) {
    if (info.channels < 2) {
      return Status(ErrorCode::kInvalidArgument, p.spec.name + ": a normal map needs 2+ channels");
    }
    p.normal = true;
    p.decode_unorm_normal = !info.is_float;
    p.work_channels = 3;
    p.spec.channels = 2;
    p.spec.texel_type = TexelType::kU8;
  } else if (is_colour(in.semantic)) {
    const bool has_alpha = info.channels == 2 || info.channels == 4;
    p.colour = true;
    p.work_channels = has_alpha ? 4 : 3;
    p.alpha = has_alpha ? 3 : -1;
    p.spec.channels = uint8_t(p.work_channels);
    p.spec.texel_type = float_type;
    const ColorConfig& colours =
        options.color_config ? *options.color_config : *ColorConfig::builtin();
    const std::string src_space = in.color_space.empty()
                                      ? colours.texture_space("", info.color_space, info.is_float)
                                      : in.color_space;
    auto to_lin = colours.converter(src_space, colours.working_space());
    if (!to_lin.ok()) return to_lin.status().with_context(p.spec.name);
    p.to_linear = std::move(to_lin).value();
    // Stored 8-bit texels carry the sRGB curve over the working space's values.
    auto to_store = ColorConverter::create("linear", want_float ? "linear" : "sRGB");
    if (!to_store.ok()) return to_store.status().with_context(p.spec.name);
    p.to_storage = std::move(to_store).value();
    p.spec.color_space = want_float ? ColorSpace::kLinear : ColorSpace::kSrgb;
  } else {
    // ORM and custom layers are data: no colour conversion.
    p.work_channels = info.channels;
    p.spec.channels = uint8_t(info.channels);
    p.spec.texel_type = float_type;
  }
  p.rules = downsample_rules_for(p.spec, p.work_channels);
  return p;
}

Status check_inputs(const BuildOptions& options) {
  if (options.layers.empty() || options.layers.size() > 16) {
    return Status(ErrorCode::kInvalidArgument, "a build needs 1 to 16 layers");
  }
  const ImageInfo* first = nullptr;
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
    if (in.coverage &&
        (in.coverage->width() != info.width || in.coverage->height() != info.height)) {
      return Status(ErrorCode::kInvalidArgument,
                    "layer " + std::to_string(i) + ": coverage mask size differs from image size");
    }
  }
  return Status::Ok();
}

// Which level-0 pages DCT tables are trained on: with at most `limit` present pages, all of
// them; otherwise pages spread evenly over at least 16 page rows spread evenly down the level
// (and over each row), so that a random-access source reads only those bands.
Expected<std::vector<PageId>> training_pages(const PageGeometry& g, const CoverageMask* coverage,
                                             size_t limit) {
  const uint32_t px = g.pages_x(0), py = g.pages_y(0);
  std::vector<std::vector<PageId>> rows(py);
  size_t present = 0;
  for (uint32_t y = 0; y < py; ++y) {
    std::vector<uint8_t> covered(px, 1);
    if (coverage) {
      VT_ASSIGN_OR_RETURN(covered, pages_with_coverage(g, 0, y, *coverage));
    }
    for (uint32_t x = 0; x < px; ++x)
      if (covered[x]) {
        rows[y].push_back(PageId{0, x, y});
        ++present;
      }
  }
  std::vector<PageId> chosen;
  if (present <= limit) {
    for (const auto& row : rows) chosen.insert(chosen.end(), row.begin(), row.end());
    return chosen;
  }
  const size_t want_rows = std::min<size_t>(py, std::max<size_t>(16, (limit + px - 1) / px));
  const size_t per_row = std::max<size_t>(1, limit / want_rows);
  for (size_t k = 0; k < want_rows && chosen.size() < limit; ++k) {
    const auto& row = rows[(2 * k + 1) * py / (2 * want_rows)];
    const size_t n = std::min({per_row, row.size(), limit - chosen.size()});
    for (size_t j = 0; j < n; ++j) chosen.push_back(row[(2 * j + 1) * row.size() / (2 * n)]);
  }
  return chosen;
}

// The texels, as stored, of the training pages that are not constant (those carry no
// statistics), in raster order. With `ids` and `keys`, each page's id and task key for a layer
// whose task seed is `seed` (page_task_key; level 0's alpha scale is 1).
Expected<std::vector<std::vector<uint8_t>>> training_sample(
    const BuildPlan& plan, const LayerInput& in, const LayerPlan& layer, size_t limit,
    uint64_t seed = 0, std::vector<PageId>* ids = nullptr, std::vector<uint64_t>* keys = nullptr) {
  const PageGeometry& g = plan.desc.geometry;
  const uint32_t P = g.payload, S = g.page_size();
  const CoverageMask* coverage = layer.level0->coverage();
  VT_ASSIGN_OR_RETURN(const std::vector<PageId> chosen, training_pages(g, coverage, limit));

  // A streamed level 0 is read again for the build: this read must not count bad values.
  std::shared_ptr<LevelSource> source = layer.level0;
  if (!coverage) {
    VT_ASSIGN_OR_RETURN(source, open_level0(in, layer, plan.options, false));
  }
  RowWindow window(*source, plan.options.address);
  if (plan.options.address == AddressMode::kWrap) {
    VT_RETURN_IF_ERROR(window.pin(P + 2 * plan.margin, plan.margin));
  }
  const size_t page_texels = size_t(S) * S;
  std::vector<std::vector<uint8_t>> pages;
  for (size_t i = 0; i < chosen.size();) {
    const uint32_t r = chosen[i].y;
    size_t end = i;
    while (end < chosen.size() && chosen[end].y == r) ++end;
    VT_ASSIGN_OR_RETURN(RowBand band,
                        window.fetch(int64_t(r) * P - plan.margin, P + 2 * plan.margin));
    std::vector<std::vector<uint8_t>> row(end - i);
    std::vector<uint64_t> row_keys(end - i);
    parallel_for(end - i, plan.threads, [&](size_t k) {
      thread_local std::vector<float> texels;
      texels.resize(page_texels * layer.work_channels);
      cut_page(g, chosen[i + k], plan.options.address, band, texels.data());
      if (keys) row_keys[k] = page_task_key(seed, chosen[i + k], 1.0f, texels);
      row[k].resize(layer.encoder->page_bytes());
      layer.store_page(texels.data(), S, 1.0f, row[k].data());
    });
    for (size_t k = 0; k < row.size(); ++k) {
      if (layer.encoder->is_constant(row[k].data())) continue;
      pages.push_back(std::move(row[k]));
      if (keys) ids->push_back(chosen[i + k]), keys->push_back(row_keys[k]);
    }
    i = end;
  }
  return pages;
}

// What the level choice keeps beside a level's own working set for the libraries, the writer's
// index and thread stacks (measured: ~190 MiB in all at 16K wide RGB). Lower than the process's
// real resident size below; kept so, since the levels that docs/BENCHMARKS.md's large builds
// hold in memory (and their measured peaks) follow from it.
constexpr uint64_t kLevelChoiceAllowance = uint64_t(64) << 20;
// The process's resident set before any work (the linked libraries as loaded, OpenImageIO's
// and the allocator's start-up), peak RSS on 2026-12-02: `vtbake version` 135 MiB, `info` of a
// small file 136, `build procedural:64x64` 138 (docs/RELIABILITY.md, "Memory under
// --memory-limit"). The memory floor counts it whole.
constexpr uint64_t kProcessBytes = uint64_t(136) << 20;

// Bytes the build holds beside the level images and the process's own while it works on a
// level `width` wide.
uint64_t level_working_set(const BuildPlan& plan, const LayerPlan& layer, uint32_t width) {
  const PageGeometry& g = plan.desc.geometry;
  const uint32_t P = g.payload, S = g.page_size(), wc = layer.work_channels;
  const uint64_t row = uint64_t(width) * wc * sizeof(float);
  const uint64_t band_rows = P + 2 * plan.margin;
  // Window, band, read buffer and the allocator's slack on them.
  uint64_t ws = row * band_rows * 4;
  if (plan.options.address == AddressMode::kWrap) ws += row * (band_rows + plan.margin);
  ws += uint64_t(plan.threads) * (row / 2 * 2 * (16 + plan.kernel.taps()));  // downsample
  ws += row / 2 * (P / 2);                                                   // next level's rows
  ws += uint64_t(plan.threads) * S * S * (wc * 4 + 16) * 3;                  // page buffers
  ws += uint64_t(g.pages_x(0)) * S * S * 4;  // encoded pages of a row
  return ws;
}
uint64_t working_set(const BuildPlan& plan, const LayerPlan& layer, uint32_t width) {
  return level_working_set(plan, layer, width) + kLevelChoiceAllowance;
}

// A level of a layer in its working form (floats), in bytes.
uint64_t working_level_bytes(const PageGeometry& g, const LayerPlan& layer, uint32_t level) {
  return uint64_t(g.level_width(level)) * g.level_height(level) * layer.work_channels *
         sizeof(float);
}

// Which levels live in memory: level l + 1 does if it and level l fit in what the working set
// leaves. Level 0 streams, or with coverage is held where open_level0 put it (pull-push runs in
// bands over scratch files too).
std::vector<bool> choose_level_memory(const BuildPlan& plan, const LayerPlan& layer) {
  const PageGeometry& g = plan.desc.geometry;
  uint64_t limit = plan.options.memory_limit;
  // A coverage layer also holds its masks (those small enough to stay in memory) and a
  // dilation's pull levels beside the level images.
  if (layer.level0->coverage()) {
    const uint64_t masks = CoverageMask::pyramid_memory_bytes(g.width, g.height, limit);
    limit -= std::min(limit, masks + dilation_budget(plan.options));
  }
  auto level_bytes = [&](uint32_t l) { return working_level_bytes(g, layer, l); };
  std::vector<bool> in_memory(g.level_count());
  in_memory[0] = layer.level0->in_memory();
  for (uint32_t l = 0; l + 1 < g.level_count(); ++l) {
    const uint64_t cur = in_memory[l] ? level_bytes(l) : 0;
    const uint64_t ws = working_set(plan, layer, g.level_width(l));
    in_memory[l + 1] = ws < limit && cur + level_bytes(l + 1) <= limit - ws;
  }
  return in_memory;
}

// The coarser levels' scratch files in all (floats), before any is written.
uint64_t scratch_level_bytes(const BuildPlan& plan) {
  const PageGeometry& g = plan.desc.geometry;
  uint64_t bytes = 0;
  for (const LayerPlan& layer : plan.layers)
    for (uint32_t l = 1; l < layer.level_in_memory.size(); ++l)
      if (!layer.level_in_memory[l]) bytes += working_level_bytes(g, layer, l);
  return bytes;
}

// Below level 0's working set a limit only sends levels to scratch files: the build says what
// it needs instead of passing the limit in silence (layers are built one after another).
void check_memory_floor(BuildPlan& plan) {
  const PageGeometry& g = plan.desc.geometry;
  for (const LayerPlan& layer : plan.layers)
    plan.memory_floor = std::max(plan.memory_floor,
                                 kProcessBytes + level_working_set(plan, layer, g.level_width(0)));
  const uint64_t limit = plan.options.memory_limit;
  if (limit >= plan.memory_floor) return;
  auto mib = [](uint64_t b) { return std::to_string((b + (1 << 20) - 1) >> 20) + " MiB"; };
  plan.warnings.push_back("memory limit " + mib(limit) + " is below this build's floor of about " +
                          mib(plan.memory_floor) + " (the process's own " + mib(kProcessBytes) +
                          ", level 0's bands of " + std::to_string(g.level_width(0)) +
                          " texels and " + std::to_string(plan.threads) +
                          " threads' page buffers): it needs that much; every level past 0 goes "
                          "to scratch files, and fewer threads lower the floor a little");
}

std::string build_metadata(const BuildOptions& options, const std::vector<LayerPlan>& layers) {
  nlohmann::json sources = nlohmann::json::array();
  for (size_t i = 0; i < layers.size(); ++i)
    sources.push_back(
        {{"layer", layers[i].spec.name}, {"color_space", options.layers[i].color_space}});
  nlohmann::json meta = nlohmann::json::parse(options.metadata_json, nullptr, false);
  if (meta.is_discarded() || !meta.is_object()) meta = nlohmann::json::object();
  meta["build"] = {{"filter", to_string(options.filter)},
                   {"address", to_string(options.address)},
                   {"codec", int(options.codec.codec)},
                   {"dct_quality", options.codec.dct_quality},
                   {"dct_adaptive", options.codec.dct_adaptive},
                   {"layers", sources},
                   {"dct_page_modes", options.codec.dct_page_modes},
                   // -1 (kDefaultPageFloor): each layer's default floor, page_error_bounds.h
                   {"min_psnr", options.codec.min_psnr},
                   {"layer_min_psnr", options.codec.layer_min_psnr}};
  // Recorded only when set, so that earlier files' metadata (and plans) stay as they were.
  if (options.codec.float_texels != FloatTexels::kAuto)
    meta["build"]["float_texels"] = to_string(options.codec.float_texels);
  if (options.codec.half_runtime != HalfRuntime::kBc6h)
    meta["build"]["half_runtime"] = to_string(options.codec.half_runtime);
  if (options.color_config && !options.color_config->is_builtin()) {
    meta["build"]["color_config"] = {{"path", options.color_config->path()},
                                     {"working_space", options.color_config->working_space()},
                                     {"cache_id", options.color_config->cache_id()}};
  }
  return meta.dump();
}

// The settings that decide the output bytes besides the texels: tool version, geometry,
// filter, codec and the layers' names. Thread count, memory limit and paths do not (the output
// does not depend on them).
std::string settings_text(const BuildPlan& plan) {
  const BuildOptions& o = plan.options;
  nlohmann::json j = {{"tool", VTBAKE_VERSION},
                      {"metadata", plan.desc.metadata_json},
                      {"payload", o.payload},
                      {"border", o.border},
                      {"non_finite", int(o.non_finite)},
                      {"alpha_coverage", o.alpha_coverage_reference},
                      {"bc_quality", int(o.codec.bc_quality)},
                      {"zstd_level", o.codec.zstd_level},
                      // Half layers' runtime format (BC6H since issue 19's HDR step): a file made
                      // before it, with RGBA16F, is not the output of these settings.
                      {"half_runtime", to_string(o.codec.half_runtime)}};
  for (const LayerInput& in : o.layers)
    j["layers"].push_back({{"semantic", int(in.semantic)}, {"color_space", in.color_space}});
  return j.dump();
}

// The plan's identity: its settings and every source's content (and coverage). Sets each
// layer's input key (its source's content and coverage) on the way.
Expected<uint64_t> plan_hash(BuildPlan& plan, const std::string& settings) {
  std::vector<uint64_t> parts{XXH3_64bits(settings.data(), settings.size())};
  for (size_t i = 0; i < plan.options.layers.size(); ++i) {
    const LayerInput& in = plan.options.layers[i];
    VT_ASSIGN_OR_RETURN(uint64_t content, in.source->content_hash());
    parts.push_back(content);
    uint64_t coverage = 0;
    if (in.coverage) {
      VT_ASSIGN_OR_RETURN(coverage, in.coverage->content_hash());
    }
    parts.push_back(coverage);
    plan.layers[i].input_key = XXH3_64bits(&parts[parts.size() - 2], 2 * sizeof(uint64_t));
  }
  return XXH3_64bits(parts.data(), parts.size() * sizeof(uint64_t));
}

// What a layer's task keys start from: the settings and the layer as written (codec tables
// included), but not its source, so that a task's key changes only with its own input rows.
uint64_t task_seed(const std::string& settings, const LayerSpec& spec) {
  XXH3_state_t state;
  XXH3_64bits_reset(&state);
  XXH3_64bits_update(&state, settings.data(), settings.size());
  const uint8_t fields[7] = {uint8_t(spec.semantic),       spec.channels,
                             uint8_t(spec.texel_type),     uint8_t(spec.codec),
                             uint8_t(spec.runtime_format), uint8_t(spec.color_space),
                             uint8_t(spec.address_mode)};
  XXH3_64bits_update(&state, fields, sizeof fields);
  XXH3_64bits_update(&state, spec.name.data(), spec.name.size());
  XXH3_64bits_update(&state, spec.codec_tables.data(), spec.codec_tables.size());
  return XXH3_64bits_digest(&state);
}

}  // namespace

std::string scratch_dir_for(const BuildOptions& o) {
  if (!o.scratch_dir.empty()) return o.scratch_dir;
  std::string dir = std::filesystem::path(o.output).parent_path().string();
  return dir.empty() ? "." : dir;
}

namespace {

// Update mode: opens the previous output and keeps it when its pages can be reused (same
// tool, settings and size); sets plan.unchanged when its plan equals this one. Returns the
// tables to pin: --tables-from's, else the kept previous file's.
Expected<PinnedTables> choose_previous(BuildPlan& plan) {
  const BuildOptions& o = plan.options;
  UpdateSummary& u = plan.update;
  u.requested = o.update;
  PinnedTables pinned;
  if (!o.tables_from.empty()) {
    VT_ASSIGN_OR_RETURN(pinned, read_pinned_tables(o.tables_from));
  }
  if (!u.requested) return pinned;
  auto previous = PreviousBuild::open(o.update_from.empty() ? o.output : o.update_from);
  if (!previous.ok()) {
    u.full_rebuild = previous.status().code() == ErrorCode::kNotFound
                         ? "no previous file"
                         : "previous file unreadable (" + previous.status().message() + ")";
    return pinned;
  }
  const UpdateRecord& r = (*previous)->record();
  const PageGeometry &g = (*previous)->reader().geometry(), &ng = plan.desc.geometry;
  if (!(*previous)->has_record()) {
    u.full_rebuild = "the previous file has no page keys";
  } else if (r.tool != VTBAKE_VERSION) {
    u.full_rebuild = "tool version changed (" + r.tool + " -> " VTBAKE_VERSION ")";
  } else if (r.settings_key != plan.settings_key) {
    u.full_rebuild = "settings changed";
  } else if (g.width != ng.width || g.height != ng.height) {
    u.full_rebuild = "size changed (" + std::to_string(g.width) + "x" + std::to_string(g.height) +
                     " -> " + std::to_string(ng.width) + "x" + std::to_string(ng.height) + ")";
  }
  if (!u.full_rebuild.empty()) return pinned;
  plan.previous = std::move(previous).value();
  plan.unchanged = r.plan_hash == plan.hash && !o.retrain_tables && o.tables_from.empty();
  if (!o.tables_from.empty() || o.retrain_tables) return pinned;
  for (const LayerSpec& spec : plan.previous->reader().layers()) {
    if (spec.codec != PageCodec::kDct) continue;
    pinned.names.push_back(spec.name);
    pinned.tables.push_back(spec.codec_tables);
  }
  return pinned;
}

// Stored bytes of `pages` coded by `encoder`.
Expected<uint64_t> sample_bytes(const PageEncoder& encoder,
                                const std::vector<std::vector<uint8_t>>& pages, int threads) {
  std::vector<uint64_t> bytes(pages.size());
  std::vector<Status> errors(pages.size());
  parallel_for(pages.size(), threads, [&](size_t i) {
    EncodedPage e;
    errors[i] = encoder.encode(pages[i].data(), e);
    bytes[i] = e.bytes.size();
  });
  uint64_t total = 0;
  for (size_t i = 0; i < pages.size(); ++i) {
    VT_RETURN_IF_ERROR(errors[i]);
    total += bytes[i];
  }
  return total;
}

// Update mode: a layer whose input, spec and tables (pinned: the previous file's or
// --tables-from's) are those of the previous file's layer of the same name takes that layer's
// pages (LayerPlan::copy_previous). Its tables are kept without a fit measurement: they coded
// this very input before.
bool copy_previous_layer(BuildPlan& plan, LayerPlan& layer, const std::vector<uint8_t>* pinned) {
  if (!plan.previous || plan.options.retrain_tables) return false;
  const int prev = plan.previous->layer_index(layer.spec.name);
  if (prev < 0 || plan.previous->layer_input(prev) != layer.input_key) return false;
  LayerSpec spec = layer.spec;
  if (layer.encoder->wants_training()) {
    if (!pinned) return false;
    spec.codec_tables = *pinned;
  }
  if (spec != plan.previous->reader().layers()[size_t(prev)]) return false;  // every field
  layer.spec = std::move(spec);
  layer.copy_previous = true;
  layer.previous_layer = prev;
  plan.update.tables_pinned |= layer.encoder->wants_training();
  return true;
}

// A DCT layer's tables: `pinned` when given (in update mode only while they code the training
// sample within kRetrainFitBound of fresh tables), else trained on up to 256 of the layer's own
// pages or 16 MiB of their texels (all of level 0 for a 2K layer).
Status plan_tables(BuildPlan& plan, const LayerInput& in, LayerPlan& layer,
                   const std::vector<uint8_t>* pinned, const std::string& settings) {
  const BuildOptions& o = plan.options;
  PageEncoder pinned_encoder = *layer.encoder;
  if (pinned) {
    const std::string what =
        (o.tables_from.empty() ? plan.previous->reader().path() : o.tables_from) + ": layer '" +
        layer.spec.name + "' tables";
    VT_RETURN_IF_ERROR(pinned_encoder.use_tables(*pinned).with_context(what));
    plan.update.tables_pinned = true;
    if (!plan.options.tables_from.empty() || !plan.previous) {
      layer.spec.codec_tables = *pinned;
      layer.encoder = std::make_shared<const PageEncoder>(std::move(pinned_encoder));
      return Status::Ok();
    }
  }
  const size_t limit = std::clamp<size_t>((size_t(16) << 20) / layer.encoder->page_bytes(), 1, 256);
  // Update mode measures the pinned tables on the sample's new pages: those whose task key under
  // the pinned tables the previous file lacks (it stored the others with these very tables).
  const bool update = pinned && plan.previous;
  std::vector<PageId> ids;
  std::vector<uint64_t> keys;
  LayerSpec pinned_spec = layer.spec;
  if (pinned) pinned_spec.codec_tables = *pinned;
  VT_ASSIGN_OR_RETURN(auto pages,
                      training_sample(plan, in, layer, limit, task_seed(settings, pinned_spec),
                                      update ? &ids : nullptr, update ? &keys : nullptr));
  std::vector<std::vector<uint8_t>> measured;
  if (update) {
    const int previous = plan.previous->layer_index(layer.spec.name);
    for (size_t i = 0; i < pages.size(); ++i)
      if (previous < 0 || plan.previous->key(previous, ids[i]) != keys[i])
        measured.push_back(pages[i]);
    plan.update.fit_pages += measured.size();
    if (measured.empty()) {  // nothing new to measure them on
      layer.spec.codec_tables = *pinned;
      layer.encoder = std::make_shared<const PageEncoder>(std::move(pinned_encoder));
      return Status::Ok();
    }
  }
  std::vector<std::span<const uint8_t>> spans(pages.begin(), pages.end());
  PageEncoder trained = *layer.encoder;
  auto tables = trained.train(spans);
  if (!tables.ok()) return tables.status().with_context(layer.spec.name);
  if (pinned) {
    VT_ASSIGN_OR_RETURN(const uint64_t old_bytes,
                        sample_bytes(pinned_encoder, measured, plan.threads));
    VT_ASSIGN_OR_RETURN(const uint64_t new_bytes, sample_bytes(trained, measured, plan.threads));
    const double fit = new_bytes ? double(old_bytes) / double(new_bytes) : 1.0;
    plan.update.tables_fit = std::max(plan.update.tables_fit, fit);
    if (fit <= kRetrainFitBound) {
      layer.spec.codec_tables = *pinned;
      layer.encoder = std::make_shared<const PageEncoder>(std::move(pinned_encoder));
      return Status::Ok();
    }
    char why[160];
    std::snprintf(why, sizeof why, "tables retrained (layer '%s': pinned tables %.3fx over %.2f)",
                  layer.spec.name.c_str(), fit, kRetrainFitBound);
    plan.update.tables_retrained = true;
    if (plan.update.full_rebuild.empty()) plan.update.full_rebuild = why;
  } else if (o.retrain_tables && plan.previous) {
    plan.update.tables_retrained = true;
    if (plan.update.full_rebuild.empty())
      plan.update.full_rebuild = "tables retrained (--retrain-tables)";
  }
  layer.spec.codec_tables = std::move(tables).value();
  layer.encoder = std::make_shared<const PageEncoder>(std::move(trained));
  return Status::Ok();
}

}  // namespace

bool LayerPlan::store_page(float* texels, uint32_t side, float alpha_scale, uint8_t* out,
                           float* reference) const {
  const uint32_t wc = work_channels;
  const size_t count = size_t(side) * side;
  if (alpha >= 0) {
    unpremultiply_page(texels, side, wc, alpha);
    if (alpha_scale != 1.0f)
      for (size_t i = 0; i < count; ++i)
        texels[i * wc + alpha] = std::min(1.0f, texels[i * wc + alpha] * alpha_scale);
  }
  if (spec.texel_type == TexelType::kF32) {
    if (to_storage) to_storage->apply(texels, count, int(wc));
    std::memcpy(out, texels, count * wc * sizeof(float));
    return false;
  }
  if (spec.texel_type == TexelType::kF16) {
    if (to_storage) to_storage->apply(texels, count, int(wc));
    bool clipped = false;
    for (size_t i = 0; i < count * wc; ++i) {
      clipped |= std::abs(texels[i]) > kHalfMax;  // float_to_half clamps to +-kHalfMax
      const uint16_t h = float_to_half(texels[i]);
      std::memcpy(out + 2 * i, &h, 2);
    }
    if (reference) std::memcpy(reference, texels, count * wc * sizeof(float));
    return clipped;
  }
  // 8-bit storage: working values outside [0, 1] clip (colour after its transfer curve, which
  // maps [0, 1] onto itself); normals are unit vectors and never do.
  bool clipped = false;
  if (!normal) {
    for (size_t i = 0; i < count * wc && !clipped; ++i) clipped = texels[i] < 0 || texels[i] > 1;
  }
  if (clipped && reference) {
    std::vector<float> unclipped(texels, texels + count * wc);
    if (to_storage) to_storage->apply(unclipped.data(), count, int(wc));
    for (size_t i = 0; i < count * wc; ++i) {
      float u = std::min(unclipped[i], kFloatMax / 256);
      // Colour under alpha composites times alpha, so its clipping costs that much: a filter's
      // overshoot unpremultiplied under near-zero alpha reads huge and shows as nothing.
      const int c = int(i % wc);
      if (alpha >= 0 && c != alpha) {
        const float clip = std::clamp(u, 0.0f, 1.0f);
        u = clip + (u - clip) * std::clamp(texels[i - c + alpha], 0.0f, 1.0f);
      }
      reference[i] = u * 255.0f;
    }
  }
  if (to_storage) {
    to_storage->apply_to_u8(texels, count, int(wc), out);
    return clipped;
  }
  auto q = [](float v) -> uint8_t {
    if (!(v > 0)) return 0;
    if (v >= 1) return 255;
    return uint8_t(v * 255.0f + 0.5f);
  };
  if (normal) {
    for (size_t i = 0; i < count; ++i) {
      out[i * 2 + 0] = q(texels[i * 3 + 0] * 0.5f + 0.5f);
      out[i * 2 + 1] = q(texels[i * 3 + 1] * 0.5f + 0.5f);
    }
    return false;
  }
  for (size_t i = 0; i < count * wc; ++i) out[i] = q(texels[i]);
  return clipped;
}

uint64_t page_task_key(uint64_t task_seed, const PageId& id, float alpha_scale,
                       const std::vector<float>& texels) {
  XXH3_state_t state;
  XXH3_INITSTATE(&state);  // reset_withSeed reads the state's old seed
  XXH3_64bits_reset_withSeed(&state, task_seed);
  const uint32_t where[3] = {id.level, id.x, id.y};
  XXH3_64bits_update(&state, where, sizeof where);
  XXH3_64bits_update(&state, &alpha_scale, sizeof alpha_scale);
  XXH3_64bits_update(&state, texels.data(), texels.size() * sizeof(float));
  return XXH3_64bits_digest(&state) | 1;
}

Expected<BuildPlan> plan_build(const BuildOptions& options) {
  VT_RETURN_IF_ERROR(check_inputs(options));
  BuildPlan plan;
  plan.options = options;
  plan.threads = thread_count(options.threads);
  plan.kernel = make_downsample_kernel(options.filter);
  plan.scratch_dir = scratch_dir_for(options);
  PageFileDesc& desc = plan.desc;
  for (const LayerInput& in : options.layers) {
    VT_ASSIGN_OR_RETURN(LayerPlan layer, plan_layer(in, options));
    for (const LayerPlan& other : plan.layers) {
      if (other.spec.name == layer.spec.name) {
        return Status(ErrorCode::kInvalidArgument, "two layers named '" + layer.spec.name + "'");
      }
    }
    plan.layers.push_back(std::move(layer));
  }
  const ImageInfo& first = options.layers[0].source->info();
  desc.geometry.width = first.width;
  desc.geometry.height = first.height;
  desc.geometry.payload = options.payload;
  desc.geometry.border = options.border;
  VT_RETURN_IF_ERROR(desc.geometry.validate());
  const uint32_t S = desc.geometry.page_size();
  plan.margin = std::max<uint32_t>(desc.geometry.border, uint32_t(plan.kernel.reach()));
  for (LayerPlan& layer : plan.layers) {
    VT_ASSIGN_OR_RETURN(PageEncoder encoder, PageEncoder::create(layer.spec, options.codec, S));
    layer.encoder = std::make_shared<const PageEncoder>(std::move(encoder));
  }
  desc.metadata_json = build_metadata(options, plan.layers);
  const std::string settings = settings_text(plan);
  plan.settings_key = XXH3_64bits(settings.data(), settings.size());
  VT_ASSIGN_OR_RETURN(plan.hash, plan_hash(plan, settings));
  VT_ASSIGN_OR_RETURN(const PinnedTables pinned, choose_previous(plan));
  if (plan.unchanged) return plan;

  for (size_t i = 0; i < plan.layers.size(); ++i) {
    LayerPlan& layer = plan.layers[i];
    const LayerInput& in = options.layers[i];
    if (copy_previous_layer(plan, layer, pinned.find(layer.spec.name))) continue;
    if (options.level_from) {
      VT_ASSIGN_OR_RETURN(BuildOptions::GivenLevel given, options.level_from(i, 0));
      layer.level0 = std::move(given.source);
      if (layer.level0 && (layer.level0->channels() != layer.work_channels ||
                           layer.level0->width() != in.source->info().width ||
                           layer.level0->height() != in.source->info().height)) {
        return Status(ErrorCode::kInvalidArgument,
                      layer.spec.name + ": the given level 0 is not the layer's working form");
      }
    }
    if (!layer.level0) {
      VT_ASSIGN_OR_RETURN(layer.level0, open_level0(in, layer, options));
    }
    layer.level_in_memory = choose_level_memory(plan, layer);
    if (!layer.encoder->wants_training()) continue;
    VT_RETURN_IF_ERROR(plan_tables(plan, in, layer, pinned.find(layer.spec.name), settings));
  }
  for (const LayerPlan& layer : plan.layers) desc.layers.push_back(layer.spec);
  plan.compress_scratch = options.compress_scratch ||
                          scratch_needs_compression(scratch_level_bytes(plan), plan.scratch_dir);
  check_memory_floor(plan);
  for (LayerPlan& layer : plan.layers) layer.task_seed = task_seed(settings, layer.spec);
  return plan;
}

}  // namespace vt
