// The main job: a scene in, a page file and the unwrapped scene out.
// unwrap (bake/unwrap) -> transfer (bake/transfer.h) -> pyramid, paging, encode (bake/build.h).
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <utility>
#include <vector>

#include "bake/build.h"
#include "bake/transfer.h"
#include "bake/unwrap/unwrap.h"
#include "common/status.h"
#include "scene/scene.h"

namespace vt {

// One progress report: the running stage and how far it is, 0..1.
struct SceneBakeProgress {
  const char* stage = "";  // "load", "unwrap", "transfer", "build", "write scene"
  double fraction = 0;
};

struct SceneBakeOptions {
  // The build of the transferred layers, as `vtbake build` takes it: output (the .vtpf path),
  // codec, payload and border, filter, alpha coverage, non-finite policy, scratch_dir (transfer
  // and build; "" = beside the output), memory_limit (transfer buffers: an eighth, at most 256 MiB,
  // for a pass's accumulators, a quarter for the source textures in memory, texture_cache_bytes; +
  // build) and threads (every stage). bake_scene sets what the scene decides: layers, address mode
  // (clamp: charts do not tile), metadata and progress.
  BuildOptions build;
  std::string unwrapped;         // the unwrapped scene (.glb); "" = output with .glb, "-" = none
  unwrap::UnwrapOptions unwrap;  // page_payload and threads are taken from `build`
  int supersample = 1;           // 1, 4 or 16 transfer samples per texel
  // The lighting layer, baked only when the scene places a light (TransferOptions::lighting).
  LightingOptions lighting;
  MissingTextures missing_textures = MissingTextures::kError;  // see TransferOptions
  scene::SceneLoadOptions load;  // how the scene file is read (bake_scene(path, ...) only)
  // Atlas rows the transfer rasterises and samples at a time (TransferOptions::band_rows;
  // 0 = from the memory limit), and whether its layers go to scratch files whatever the limit
  // (else where the build would not hold them in memory either). The output depends on neither;
  // tests force small bands.
  uint32_t transfer_band_rows = 0;
  bool transfer_to_scratch = false;
  // Update mode's cache folder: the unwrap (bake/unwrap_cache.h) as `cache`/unwrap.bin, written
  // by every bake, and the transfer's bands (bake/transfer_cache.h) as `cache`/transfer.bin,
  // written by an update (build.update, a first one included) or when `cache` is given; both
  // read by an update.
  // "" = the output's path with ".cache" appended, "-" = none. The output does not depend on it.
  std::string cache;
  std::function<void(const SceneBakeProgress&)> progress;

  // 8 GiB by default rather than the build's 2: the transfer's layers stay in memory (faster)
  // while the build can hold them (level0_fits_memory); past that every stage works in bands
  // through scratch files.
  SceneBakeOptions() { build.memory_limit = uint64_t(8) << 30; }
};

// A baked layer some of whose covered texels have a channel above 1 (HDR emissive, bright
// factors): kept when the layer stores floats (--codec raw), clipped to 1 when it stores 8 bits.
struct LayerRange {
  LayerSemantic semantic = LayerSemantic::kEmissive;
  std::string layer;  // the page file's layer name ("emissive")
  uint64_t texels_above_one = 0;
  float max_value = 0;
  bool clipped = false;
};

struct SceneBakeSummary {
  std::string output, unwrapped;
  uint64_t triangles = 0;  // unwrapped (instances counted separately)
  unwrap::UnwrapStats unwrap;
  bool unwrap_reused = false;  // update mode: the unwrap taken from the cache (unwrap_cache.h)
  TransferStats transfer;
  std::vector<LayerRange> above_one;             // layers with values above 1 only
  std::vector<MissingTexture> missing_textures;  // MissingTextures::kWarn
  BuildSummary build;                            // raw bytes and ratio: bake/build_summary_json.h
  // Every warning, one line each: the scene importer's (scene::Scene::warnings), then missing
  // textures, then clipped layers. The CLI prints them as "warning: LINE".
  std::vector<std::string> warnings;
  std::vector<StageTime> stages;  // load, unwrap, transfer, build, write scene
  // The process's peak resident set (bytes) at the end of unwrap, transfer and build: the
  // first is the load's and the unwrap's own memory, apart from the bands that follow.
  std::vector<std::pair<std::string, uint64_t>> peak_rss;
  double seconds = 0;
};

// A bake up to its build, for callers that run the build elsewhere (bake/shard.h: a build farm):
// the scene checked, unwrapped and its materials transferred, and the build's options filled
// in as bake_scene runs them (layers, address mode, metadata, provenance, input key; output and
// update_from are options.build.output). summary holds the stages so far.
struct PreparedBake {
  SceneBakeSummary summary;
  BuildOptions build;
  unwrap::UnwrapResult unwrapped;
};
Expected<PreparedBake> prepare_scene_bake(const scene::Scene& scene,
                                          const SceneBakeOptions& options);

// Loads `scene_path` (glTF, OBJ, PLY, Draco) and bakes it.
Expected<SceneBakeSummary> bake_scene(const std::string& scene_path,
                                      const SceneBakeOptions& options);
// Bakes a scene already in memory.
Expected<SceneBakeSummary> bake_scene(const scene::Scene& scene, const SceneBakeOptions& options);

// The summary as one JSON object (for --json and build farms, docs/JSON.md); the build part
// is to_json(summary.build) under "build".
nlohmann::json to_json(const SceneBakeSummary& summary);

// The transfer's texels as build inputs (linear colour, data, float normals) with coverage.
std::vector<LayerInput> layer_inputs(TransferResult& transfer);

}  // namespace vt
