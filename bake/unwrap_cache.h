// The unwrap's cache (update mode, issue 16): a bake stores its unwrap result (the unwrapped
// meshes, which node places which, the statistics and the atlas triangles) under the key of
// everything the unwrap reads: the meshes, nodes and materials, each image's label and header
// size (never its texels: a repainted texture keeps the unwrap), the density file and the
// options. An update whose key matches takes the stored result instead of unwrapping again.
// Anything else (another key, a damaged, truncated or foreign file) is ignored and the scene is
// unwrapped, so a bad cache costs time, never a different atlas. Layout: a header (magic,
// version, key, sizes, checksum of the packed result) and the result as one zstd frame; written
// under a temporary name and renamed when complete.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "bake/unwrap/unwrap.h"
#include "common/status.h"
#include "scene/scene.h"

namespace vt {

// The key of unwrapping `scene` with `options` (threads aside: the unwrap is the same at any
// thread count). Reads the images' headers and the density file.
uint64_t unwrap_cache_key(const scene::Scene& scene, const unwrap::UnwrapOptions& options);

// The result stored at `path` under `key`, rebuilt on `scene` (its materials, images and lights
// are the scene's own); nullopt when there is none, it was stored under another key, or it does
// not check out.
std::optional<unwrap::UnwrapResult> read_unwrap_cache(const std::string& path, uint64_t key,
                                                      const scene::Scene& scene);

// Stores `result` (the unwrap of `scene`) under `key` at `path`, replacing what was there.
Status write_unwrap_cache(const std::string& path, uint64_t key, const scene::Scene& scene,
                          const unwrap::UnwrapResult& result);

}  // namespace vt
