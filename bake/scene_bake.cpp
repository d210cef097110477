// The main job (see scene_bake.h).
#include "bake/scene_bake.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <new>
#include <nlohmann/json.hpp>
#include <optional>

#include "bake/build_plan.h"
#include "bake/build_summary_json.h"
#include "bake/coverage_mask.h"
#include "bake/level_source.h"
#include "bake/level_store.h"
#include "bake/unwrap/texel_density.h"
#include "bake/unwrap_cache.h"
#include "bake/update_scene.h"
#include "format/atomic_output.h"

namespace vt {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// A bake holds nothing per atlas texel past the memory limit: the layers' levels and the
// coverage masks (1 bit a texel, bake/coverage_mask.h) go to scratch files. What grows with the
// atlas is per column: the build's level-0 band of a page row (payload + margins, ~136 rows) of
// 4 floats, held about 4 times over (window, band, read buffer, slack: level_working_set).
constexpr uint64_t kBytesPerColumn = 136 * 4 * sizeof(float) * 4;
// Beside it: a transfer pass's accumulators (at most 256 MiB, an eighth of the limit), the masks
// small enough to stay in memory (about a 48th of the limit at most), the libraries and the scene.
uint64_t band_bytes(uint64_t memory_limit) {
  return std::min(uint64_t(256) << 20, memory_limit / 8);
}
constexpr uint64_t kFixedBytes = uint64_t(64) << 20;

uint64_t atlas_bytes(uint64_t width, uint64_t height, uint64_t memory_limit) {
  return width * kBytesPerColumn + CoverageMask::pyramid_memory_bytes(width, height, memory_limit) +
         band_bytes(memory_limit) + kFixedBytes;
}

// Atlas texels a bake fits in `memory_limit`, for a square atlas (0 when not even the fixed part
// does).
double texels_within(uint64_t memory_limit) {
  const uint64_t fixed = band_bytes(memory_limit) + kFixedBytes + memory_limit / 48;
  const double side = memory_limit > fixed ? double(memory_limit - fixed) / kBytesPerColumn : 0.0;
  return side * side;
}

// Refuses an atlas whose bands and in-memory masks pass the memory limit.
Status check_atlas_memory(uint64_t width, uint64_t height, uint64_t memory_limit) {
  const uint64_t need = atlas_bytes(width, height, memory_limit);
  if (need <= memory_limit) return Status::Ok();
  return Error(ErrorCode::kResourceLimit,
               "an atlas of " + std::to_string(width) + "x" + std::to_string(height) +
                   " texels needs at least " + std::to_string(need >> 20) +
                   " MiB (band buffers and coverage masks), over the memory limit of " +
                   std::to_string(memory_limit >> 20) +
                   " MiB; raise --memory-limit or lower --texels-per-unit or --size");
}

// The process's peak resident set so far, in bytes.
uint64_t peak_rss_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return uint64_t(u.ru_maxrss) * 1024;
}

// Runs a stage, turning an allocation failure into an error naming it.
template <class Fn>
auto guarded(const char* stage, Fn&& fn) -> decltype(fn()) {
  try {
    return fn();
  } catch (const std::bad_alloc&) {
    return Error(ErrorCode::kResourceLimit,
                 std::string(stage) +
                     ": out of memory (lower --memory-limit to bake in smaller bands, or lower "
                     "--texels-per-unit or --size)");
  }
}

// Bytes of the transfer's layer stores for a W x H atlas of `scene`'s materials.
uint64_t transfer_store_bytes(const scene::Scene& scene, LightingLayer lighting, uint32_t W,
                              uint32_t H) {
  uint64_t channels = 0;
  for (LayerSemantic l : layers_used(scene, lighting))  // lighting: 4 at most (with AO)
    channels +=
        l == LayerSemantic::kNormal || l == LayerSemantic::kOrm || l == LayerSemantic::kEmissive
            ? 3
            : 4;
  return uint64_t(W) * H * channels * sizeof(float);
}

// Whether the transfer's level-0 stores (`store_bytes`) stay in memory rather than scratch
// files: where the build would hold level 0 in memory too.
bool stores_in_memory(const SceneBakeOptions& options, uint64_t store_bytes) {
  return !options.transfer_to_scratch &&
         level0_fits_memory(store_bytes, options.build.memory_limit);
}

// Refuses a bake whose level-0 stores (`store_bytes` of floats) go to scratch files in `dir`
// and cannot fit its free space even compressed as well as any real atlas's levels: found
// before the work, not when a write fails an hour into it. The transfer checks again from what
// its stores take once written (check_projected_scratch in transfer.cpp).
Status check_scratch_space(uint64_t store_bytes, const std::string& dir) {
  return check_scratch_room(store_bytes / kScratchBestCompression, dir,
                            "the atlas's level 0 (" + gib_text(store_bytes) + " GiB of floats, " +
                                std::to_string(kScratchBestCompression) +
                                "x compressed at best) needs at least");
}

std::string default_unwrapped(const std::string& output) {
  std::filesystem::path p(output);
  p.replace_extension(".glb");
  return p.string();
}

// 1234567 -> "1,234,567".
std::string with_thousands(uint64_t n) {
  std::string digits = std::to_string(n), out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

// The transferred layers with values above 1 (`clipped` is known once the layers are built).
std::vector<LayerRange> layer_ranges(const std::vector<TransferLayer>& transferred) {
  std::vector<LayerRange> out;
  for (const TransferLayer& t : transferred) {
    // Irradiance above 1 is what lighting is: nothing to report, and the layer is half float
    // (lit albedo alike).
    if (t.texels_above_one == 0 || is_light(t.semantic)) continue;
    LayerRange r;
    r.semantic = t.semantic;
    r.layer = to_string(t.semantic);
    r.texels_above_one = t.texels_above_one;
    r.max_value = t.max_value;
    out.push_back(r);
  }
  return out;
}

// An 8-bit layer clips to 1; a float one keeps the values.
void mark_clipped(const BuildSummary& built, std::vector<LayerRange>& ranges) {
  for (LayerRange& r : ranges)
    for (const LayerSummary& l : built.layers)
      if (l.spec.semantic == r.semantic)
        r.layer = l.name, r.clipped = l.spec.texel_type == TexelType::kU8;
}

std::string range_warning(const LayerRange& r) {
  char max[32];
  std::snprintf(max, sizeof max, "%.4g", double(r.max_value));
  std::string line =
      r.layer + ": " + with_thousands(r.texels_above_one) + " texels above 1.0 (max " + max + ")";
  return r.clipped ? line +
                         " clipped: the layer stores 8 bits (--float-texels half or float "
                         "keeps float)"
                   : line + " kept: the layer stores float";
}

}  // namespace

std::vector<LayerInput> layer_inputs(TransferResult& transfer) {
  std::vector<LayerInput> inputs;
  for (TransferLayer& layer : transfer.layers) {
    ImageInfo info;
    info.width = transfer.width;
    info.height = transfer.height;
    info.channels = layer.channels;
    LayerInput in;
    in.semantic = layer.semantic;
    in.coverage = transfer.coverage;
    switch (layer.semantic) {
      case LayerSemantic::kNormal:
        info.is_float = true;  // unit xyz in [-1, 1], not n * 0.5 + 0.5
        break;
      case LayerSemantic::kLitAlbedo:  // radiance, always hdr: half float (build_plan.cpp)
      case LayerSemantic::kAlbedo:
      case LayerSemantic::kEmissive:
        // Linear colour; values in [0, 1] go in as integer-like data so the build stores sRGB
        // 8-bit texels, HDR values keep float.
        info.is_float = layer.hdr;  // lit albedo: always (bake/transfer.h)
        info.color_space = "linear";
        in.color_space = "linear";
        info.alpha_channel = layer.channels == 4 ? 3 : -1;
        break;
      case LayerSemantic::kLighting:
        info.is_float = true;  // irradiance in lux: HDR, stored as half (build_plan.cpp)
        break;
      default:
        info.is_float = layer.hdr;
        break;
    }
    if (layer.store) {
      in.source = std::make_shared<StoredImageSource>(info, std::move(layer.store));
    } else {
      in.source = std::make_shared<MemoryImageSource>(info, std::move(layer.texels));
    }
    in.consume_source = true;  // the build converts in-memory texels in place
    layer.texels.clear();
    inputs.push_back(std::move(in));
  }
  return inputs;
}

Expected<SceneBakeSummary> bake_scene(const std::string& scene_path,
                                      const SceneBakeOptions& options) {
  auto t0 = Clock::now();
  if (options.progress) options.progress({"load", 0.0});
  auto loaded = guarded("load", [&] { return scene::load_scene(scene_path, options.load); });
  if (!loaded.ok()) return loaded.status();
  VT_RETURN_IF_ERROR(scene::validate_geometry(*loaded));  // its messages name the file
  double load_seconds = seconds_since(t0);
  auto summary = bake_scene(*loaded, options);
  if (!summary.ok()) return summary.status().with_context(scene_path);
  summary->stages.insert(summary->stages.begin(), StageTime{"load", load_seconds});
  summary->seconds += load_seconds;
  return summary;
}

namespace {

// The checks before any work, and the bake's content key.
Expected<uint64_t> check_and_key(const scene::Scene& input, const SceneBakeOptions& options) {
  if (options.build.output.empty()) return Error(ErrorCode::kInvalidArgument, "no output path");
  if (input.triangle_count() == 0) {
    return Error(ErrorCode::kInvalidArgument, "the scene has no triangles to bake");
  }
  // Before the unwrapper adds the atlas set, which a slot reading a missing set would read.
  VT_RETURN_IF_ERROR(check_texcoord_sets(input));
  // Damaged PNGs fail now, not after the unwrap (the transfer checks them again, from cache).
  VT_RETURN_IF_ERROR(check_scene_textures(input));
  if (scene_has_lights(input)) VT_RETURN_IF_ERROR(check_lighting_options(options.lighting));
  return scene_bake_key(input, options);
}

// The update mode's cache folder of a bake (SceneBakeOptions::cache), "" = none.
std::string cache_dir(const SceneBakeOptions& options) {
  if (options.cache == "-") return "";
  return options.cache.empty() ? options.build.output + ".cache" : options.cache;
}

// Unwrap and transfer; `prepared.summary` has its warnings and outputs set by the caller.
// `cache_folder`: the folder of the update mode's cache ("" = none).
Status unwrap_and_transfer(const scene::Scene& input, const SceneBakeOptions& options,
                           uint64_t input_key, const std::string& cache_folder,
                           PreparedBake& prepared) {
  SceneBakeSummary& summary = prepared.summary;
  const std::string& output = options.build.output;
  auto report = [&](const char* stage, double f) {
    if (options.progress) options.progress({stage, f});
  };
  // Unwrap.
  auto t0 = Clock::now();
  report("unwrap", 0.0);
  unwrap::UnwrapOptions uo = options.unwrap;
  uo.page_payload = int(options.build.payload);
  uo.threads = options.build.threads;
  // Limits before the work: an asked size must fit the memory limit; a density from the sources
  // is capped where it would not.
  const uint64_t limit = options.build.memory_limit;
  if (uo.size_pages > 0) {
    const uint64_t side = uint64_t(uo.size_pages) * uint64_t(uo.page_payload);
    if (double(side) * double(side) > double(uo.max_atlas_texels)) {
      return Error(ErrorCode::kResourceLimit, "bake: an atlas of " + std::to_string(uo.size_pages) +
                                                  " pages (" + std::to_string(side) +
                                                  " texels) a side exceeds the page format's " +
                                                  "2^24 texels a side");
    }
    VT_RETURN_IF_ERROR(check_atlas_memory(side, side, limit).with_context("bake"));
    const uint64_t stores =
        transfer_store_bytes(input, options.lighting.layer, uint32_t(side), uint32_t(side));
    if (!stores_in_memory(options, stores))
      VT_RETURN_IF_ERROR(
          check_scratch_space(stores, scratch_dir_for(options.build)).with_context("bake"));
  }
  uo.max_size_pages = std::max(
      1, std::min(uo.max_size_pages, unwrap::pages_within(texels_within(limit), uo.page_payload)));
  // Update mode takes the previous bake's unwrap when what the unwrap reads is unchanged (a
  // repainted texture keeps it); every bake stores its own for the next (bake/unwrap_cache.h).
  std::string cache = cache_folder;
  const std::string unwrap_cache = cache.empty() ? "" : cache + "/unwrap.bin";
  uint64_t unwrap_key = 0;
  if (!unwrap_cache.empty()) unwrap_key = unwrap_cache_key(input, uo);
  std::optional<unwrap::UnwrapResult> reused;
  if (!unwrap_cache.empty() && options.build.update)
    reused = read_unwrap_cache(unwrap_cache, unwrap_key, input);
  summary.unwrap_reused = reused.has_value();
  auto unwrapped = guarded("unwrap", [&]() -> Expected<unwrap::UnwrapResult> {
    if (reused) return std::move(*reused);
    return unwrap::unwrap_scene(input, uo);
  });
  if (!unwrapped.ok()) return unwrapped.status().with_context("unwrap");
  // The caches are written from here on; a folder it cannot make means none (a cache that
  // cannot be written only costs the next update its reuse).
  if (!cache.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(cache, ec);
    if (ec) cache.clear();
  }
  if (!cache.empty() && !summary.unwrap_reused)
    (void)write_unwrap_cache(unwrap_cache, unwrap_key, input, *unwrapped);
  summary.unwrap = unwrapped->stats;
  // The unwrap's own (materials baked coarser than their sources) reach the summary's list, which
  // the CLI prints; in UnwrapStats alone they were in the JSON only.
  for (const std::string& w : unwrapped->stats.warnings) summary.warnings.push_back(w);
  summary.peak_rss.push_back({"unwrap", peak_rss_bytes()});
  summary.triangles = uint64_t(unwrapped->stats.faces);
  // Charts that cover almost nothing (degenerate or needle geometry, one huge chart beside
  // specks) leave the atlas empty: every texel baked is then wasted on background.
  if (constexpr double kLowUtilisation = 0.05; summary.unwrap.utilisation < kLowUtilisation) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "atlas utilisation %.4f: the charts cover %.2f%% of the atlas's texels "
                  "(degenerate or needle-thin geometry?)",
                  summary.unwrap.utilisation, 100.0 * summary.unwrap.utilisation);
    summary.warnings.push_back(text);
  }
  summary.stages.push_back({"unwrap", seconds_since(t0)});
  report("unwrap", 1.0);

  // Transfer.
  t0 = Clock::now();
  const uint32_t W = uint32_t(unwrapped->stats.atlas_width),
                 H = uint32_t(unwrapped->stats.atlas_height);
  VT_RETURN_IF_ERROR(check_atlas_memory(W, H, limit).with_context("transfer"));
  TransferOptions to;
  to.width = W, to.height = H;
  to.supersample = options.supersample;
  to.missing_textures = options.missing_textures;
  to.charts.reserve(unwrapped->triangles.size());
  for (const unwrap::AtlasTriangle& t : unwrapped->triangles) to.charts.push_back(t.chart);
  to.threads = options.build.threads;
  to.color_config = options.build.color_config;
  to.lighting = options.lighting;
  to.scratch_dir = scratch_dir_for(options.build);
  to.progress = [&](double f) { report("transfer", f); };
  // Bands of rows straight to the layers' stores: in memory where the build holds level 0 so.
  to.band_rows = options.transfer_band_rows;
  to.band_memory = band_bytes(limit);
  to.texture_cache = texture_cache_bytes(limit);
  const uint64_t stores = transfer_store_bytes(unwrapped->scene, options.lighting.layer, W, H);
  to.stores_in_memory = stores_in_memory(options, stores);
  if (!to.stores_in_memory) {
    VT_RETURN_IF_ERROR(check_scratch_space(stores, to.scratch_dir).with_context("transfer"));
    // The build's scratch: the stores, converted in their own files, and a third more of
    // coarser levels; its levels are compressed as the stores are.
    to.compress_scratch =
        options.build.compress_scratch || scratch_needs_compression(stores / 3 * 4, to.scratch_dir);
  }
  to.coverage_in_memory = !options.transfer_to_scratch && CoverageMask::fits_memory(W, H, limit);
  // The band cache costs a third of the transfer's time (zstd of every band) and 9-17 bytes of
  // disk a texel: written only by a bake that asks for it (--update, or --cache DIR).
  if (!cache.empty() && (options.build.update || !options.cache.empty())) {
    to.cache_out = cache + "/transfer.bin";
    if (options.build.update) to.cache_in = to.cache_out;
    to.image_keys = image_content_keys(unwrapped->scene);
  }
  auto transfer = guarded("transfer", [&] { return transfer_to_stores(unwrapped->scene, to); });
  if (!transfer.ok()) return transfer.status().with_context("transfer");
  summary.peak_rss.push_back({"transfer", peak_rss_bytes()});
  summary.transfer = transfer->stats;
  summary.missing_textures = transfer->missing_textures;
  for (const MissingTexture& m : summary.missing_textures)
    summary.warnings.push_back(m.message() + " (baked from the factor alone)");
  summary.above_one = layer_ranges(transfer->layers);
  if (const uint64_t below = summary.transfer.below_horizon_samples; below > 0) {
    summary.warnings.push_back(
        "normal: the normal maps point below the surface (blue under half) at " +
        with_thousands(below) + " of the transfer's " + with_thousands(summary.transfer.samples) +
        " samples; stored at the horizon, the nearest direction the layer holds");
  }
  if (const LightingStats& l = summary.transfer.lighting; l.clamped + l.non_finite > 0) {
    summary.warnings.push_back("lighting: " + with_thousands(l.clamped) + " samples above " +
                               std::to_string(int(kMaxIrradiance)) + " lux clamped to it, " +
                               with_thousands(l.non_finite) +
                               " non-finite (NaN stored as 0, infinity as the maximum)");
  }
  if (options.lighting.layer == LightingLayer::kCombined && !scene_has_lights(input)) {
    summary.warnings.push_back(
        "--lighting combined: the scene places no light, so there is nothing to combine (no "
        "lit-albedo layer baked)");
  }
  summary.stages.push_back({"transfer", seconds_since(t0)});

  // The build's options, as bake_scene runs them.
  BuildOptions& bo = prepared.build;
  bo = options.build;
  bo.layers = layer_inputs(*transfer);
  bo.compress_scratch = to.compress_scratch;
  bo.address = AddressMode::kClamp;
  bo.update_from = output;
  bo.input_key = input_key;
  bo.provenance_json =
      nlohmann::json{
          {"scene", input.source_path.empty() ? "" : path_for_metadata(input.source_path, output)}}
          .dump();
  nlohmann::json meta = {
      {"tool", "vtbake bake"},
      {"supersample", options.supersample},
      {"texels_per_unit", summary.unwrap.texels_per_unit},
      {"atlas", {W, H}},
      {"unwrap_method", options.unwrap.method == unwrap::Method::kArap ? "arap" : "lscm"},
      {"padding", options.unwrap.padding},
  };
  // Slots baked from their factor alone: the validator's reference draws them so too.
  if (!summary.missing_textures.empty()) meta["missing_textures"] = "warn";
  // Only a lit bake says how it was lit: the metadata of light-less bakes stays as it was.
  if (scene_has_lights(input)) {
    meta["lighting"] = {{"lights", input.placed_lights().size()},
                        {"shadows", options.lighting.shadows},
                        {"ao_samples", options.lighting.ao_samples},
                        {"ao_distance", options.lighting.ao_distance}};
    if (options.lighting.bounces > 0) {  // a bake without bounces keeps its metadata as it was
      meta["lighting"]["bounces"] = options.lighting.bounces;
      meta["lighting"]["bounce_samples"] = options.lighting.bounce_samples;
    }
    if (options.lighting.layer != LightingLayer::kSeparate)  // likewise the default layer mode
      meta["lighting"]["layer"] = to_string(options.lighting.layer);
  }
  bo.metadata_json = meta.dump();
  prepared.unwrapped = std::move(unwrapped).value();
  return Status::Ok();
}

}  // namespace

Expected<PreparedBake> prepare_scene_bake(const scene::Scene& input,
                                          const SceneBakeOptions& options) {
  VT_ASSIGN_OR_RETURN(const uint64_t input_key, check_and_key(input, options));
  PreparedBake prepared;
  prepared.summary.warnings = input.warnings;
  prepared.summary.output = options.build.output;
  VT_RETURN_IF_ERROR(unwrap_and_transfer(input, options, input_key, "", prepared));
  return prepared;
}

Expected<SceneBakeSummary> bake_scene(const scene::Scene& input, const SceneBakeOptions& options) {
  auto start = Clock::now();
  auto report = [&](const char* stage, double f) {
    if (options.progress) options.progress({stage, f});
  };
  const std::string& output = options.build.output;
  VT_ASSIGN_OR_RETURN(const uint64_t input_key, check_and_key(input, options));
  PreparedBake prepared;
  SceneBakeSummary& summary = prepared.summary;
  summary.warnings = input.warnings;
  summary.output = output;
  summary.unwrapped = options.unwrapped.empty()  ? default_unwrapped(output)
                      : options.unwrapped == "-" ? ""
                                                 : options.unwrapped;
  // Update mode: with the scene, its textures and the settings as the previous output was
  // baked from, the outputs stay as they are.
  if (auto same = unchanged_bake(options, summary.unwrapped, input_key)) {
    same->warnings = summary.warnings;
    same->triangles = uint64_t(input.triangle_count());
    same->seconds = seconds_since(start);
    return *same;
  }
  // The page file and the unwrapped scene replace what was there as a pair, or not at all; a
  // bad output path fails here, before the work.
  OutputSet outputs;
  VT_ASSIGN_OR_RETURN(std::string staged_pages, outputs.stage(output));
  std::string staged_scene;
  if (!summary.unwrapped.empty()) {
    VT_ASSIGN_OR_RETURN(staged_scene, outputs.stage(summary.unwrapped));
  }
  VT_RETURN_IF_ERROR(unwrap_and_transfer(input, options, input_key, cache_dir(options), prepared));
  const unwrap::UnwrapResult* unwrapped = &prepared.unwrapped;

  // Pyramid, paging, encode.
  auto t0 = Clock::now();
  BuildOptions bo = prepared.build;
  bo.output = staged_pages;
  bo.progress = [&](const BuildProgress& p) {
    report("build", p.pages_total ? double(p.pages_done) / double(p.pages_total) : 0.0);
  };
  auto built = guarded("build", [&] { return build_page_file(bo); });
  if (!built.ok()) return built.status().with_context("build");
  summary.peak_rss.push_back({"build", peak_rss_bytes()});
  summary.build = std::move(built).value();
  for (const std::string& w : summary.build.warnings) summary.warnings.push_back(w);
  mark_clipped(summary.build, summary.above_one);
  // A clipped layer has the build's own line (BuildSummary::warnings, with the clipped count
  // and range); a layer that keeps its floats is said here.
  for (const LayerRange& r : summary.above_one)
    if (!r.clipped) summary.warnings.push_back(range_warning(r));
  summary.stages.push_back({"build", seconds_since(t0)});

  // The unwrapped scene beside it.
  if (!summary.unwrapped.empty()) {
    t0 = Clock::now();
    report("write scene", 0.0);
    VT_RETURN_IF_ERROR(guarded("write scene", [&] {
                         return unwrap::save_unwrapped_glb(*unwrapped, staged_scene);
                       }).with_context(summary.unwrapped));
    summary.stages.push_back({"write scene", seconds_since(t0)});
  }
  VT_RETURN_IF_ERROR(outputs.commit());

  summary.seconds = seconds_since(start);
  return summary;
}

nlohmann::json to_json(const SceneBakeSummary& s) {
  nlohmann::json stages = nlohmann::json::object();
  for (const StageTime& st : s.stages) stages[st.name] = st.seconds;
  stages["total"] = s.seconds;
  nlohmann::json peak_rss = nlohmann::json::object();
  for (const auto& [stage, bytes] : s.peak_rss) peak_rss[stage] = bytes;
  const unwrap::UnwrapStats& u = s.unwrap;
  const TransferStats& t = s.transfer;
  nlohmann::json transfer_seconds = nlohmann::json::object();
  for (const auto& [name, seconds] : t.stage_seconds) transfer_seconds[name] = seconds;
  nlohmann::json above_one = nlohmann::json::array();
  for (const LayerRange& r : s.above_one) {
    above_one.push_back({{"layer", r.layer},
                         {"texels_above_one", r.texels_above_one},
                         {"max_value", r.max_value},
                         {"clipped", r.clipped},
                         {"clipped_texels", r.clipped ? r.texels_above_one : 0}});
  }
  nlohmann::json missing = nlohmann::json::array();
  for (const MissingTexture& m : s.missing_textures) {
    missing.push_back({{"material", m.material},
                       {"material_index", m.material_index},
                       {"slot", m.slot},
                       {"image", m.image},
                       {"path", m.path},
                       {"reason", m.reason}});
  }
  nlohmann::json out = {
      {"output", s.output},
      {"unwrapped", s.unwrapped},
      {"triangles", s.triangles},
      {"atlas",
       {{"width", u.atlas_width},
        {"height", u.atlas_height},
        {"charts", u.charts},
        {"texels_per_unit", u.texels_per_unit},
        {"utilisation", u.utilisation},
        {"reused", s.unwrap_reused},
        {"stretch_l2", u.stretch_l2},
        {"density", unwrap::density_json(u)}}},
      {"transfer",
       {{"covered_texels", t.covered_texels},
        {"edge_only_texels", t.edge_only_texels},
        {"contested_texels", t.contested_texels},
        {"samples", t.samples},
        {"below_horizon_samples", t.below_horizon_samples},
        {"bands", t.bands},
        {"bands_cached", t.bands_cached},
        {"texels_per_second", t.seconds > 0 ? double(t.covered_texels) / t.seconds : 0.0},
        {"seconds", transfer_seconds},
        {"above_one", above_one},
        {"missing_textures", missing}}},
      {"build", to_json(s.build)},
      {"seconds", stages},
      {"peak_rss_bytes", peak_rss},
      {"warnings", s.warnings},
  };
  // Only a lit bake has the lighting figures (the reports of others stay as they were).
  if (t.lighting.samples > 0) {
    out["transfer"]["lighting"] = {{"samples", t.lighting.samples},
                                   {"shadow_rays", t.lighting.shadow_rays},
                                   {"ao_rays", t.lighting.ao_rays},
                                   {"clamped", t.lighting.clamped},
                                   {"non_finite", t.lighting.non_finite},
                                   {"structure_bytes", t.lighting.bvh_bytes},
                                   {"structure_seconds", t.lighting.build_seconds}};
    if (t.lighting.bounce_rays > 0)
      out["transfer"]["lighting"]["bounce_rays"] = t.lighting.bounce_rays;
  }
  return out;
}

}  // namespace vt
