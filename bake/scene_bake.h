// The main job: a scene in, a page file and the unwrapped scene out.
// unwrap (bake/unwrap) -> transfer (bake/transfer.h) -> pyramid, paging, encode (bake/build.h).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "bake/build.h"
#include "scene/scene.h"
#include "bake/transfer.h"
#include "bake/unwrap/unwrap.h"
#include "common/status.h"

namespace vt {

// One progress report: the running stage and how far it is, 0..1.
struct SceneBakeProgress {
  const char* stage = "";  // "load", "unwrap", "transfer", "build", "write scene"
  double fraction = 0;
};

struct SceneBakeOptions {
  std::string output;            // the .vtpf path
  std::string unwrapped;         // the unwrapped scene (.glb); "" = output with .glb, "-" = none
  unwrap::UnwrapOptions unwrap;  // page_payload is taken from `payload`
  int supersample = 1;           // 1, 4 or 16 transfer samples per texel
  PageEncoderOptions codec;
  uint32_t payload = 120;
  uint32_t border = 4;
  int threads = 0;                            // 0 = all cores
  uint64_t memory_limit = uint64_t(8) << 30;  // transfer buffers + build
  std::function<void(const SceneBakeProgress&)> progress;
};

struct SceneBakeSummary {
  std::string output, unwrapped;
  uint64_t triangles = 0;  // unwrapped (instances counted separately)
  unwrap::UnwrapStats unwrap;
  TransferStats transfer;
  BuildSummary build;
  uint64_t raw_bytes = 0;         // every level of every layer as uncompressed stored texels
  double ratio = 0;               // raw_bytes / file bytes
  std::vector<StageTime> stages;  // load, unwrap, transfer, build, write scene
  double seconds = 0;
};

// Loads `scene_path` (glTF, OBJ, PLY, Draco) and bakes it.
Expected<SceneBakeSummary> bake_scene(const std::string& scene_path,
                                      const SceneBakeOptions& options);
// Bakes a scene already in memory.
Expected<SceneBakeSummary> bake_scene(const scene::Scene& scene, const SceneBakeOptions& options);

// The summary as one JSON object (for --json and build farms).
std::string summary_json(const SceneBakeSummary& summary);

// The transfer's texels as build inputs (linear colour, data, float normals) with coverage.
std::vector<LayerInput> layer_inputs(TransferResult& transfer);

}  // namespace vt
