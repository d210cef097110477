// Update mode for a scene bake: the key of everything a bake's output follows from (the
// scene's meshes, materials and nodes, the bytes of every texture and density file, the
// settings and the tool version; never a path or a time), and the check that the previous
// output already is the bake of that key, which lets an unchanged bake skip every stage.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "bake/scene_bake.h"
#include "common/status.h"
#include "scene/scene.h"

namespace vt {

// The content key of a bake of `scene` with `options`. Errors name an unreadable texture.
Expected<uint64_t> scene_bake_key(const scene::Scene& scene, const SceneBakeOptions& options);

// A content key per image of `scene`: its name, uri, embedded bytes or file content (a marker
// when it cannot be read), for the transfer's band cache (TransferOptions::image_keys).
std::vector<uint64_t> image_content_keys(const scene::Scene& scene);

// With options.build.update: the summary of the previous output (at options.build.output,
// with its unwrapped scene at `unwrapped` when one is wanted) when it was baked from `key`
// with this tool version and its tables stay as they are; nullopt when the bake must run.
std::optional<SceneBakeSummary> unchanged_bake(const SceneBakeOptions& options,
                                               const std::string& unwrapped, uint64_t key);

}  // namespace vt
