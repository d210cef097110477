// From the scene model (scene/) to what the renderer draws: world-space meshes (instances
// flattened) with the UVs of the virtual texture, and the reference meshes with their own UVs
// and textures (base colour x factor, as the bake's albedo layer holds it).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/status.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace vt::render {

struct SceneDraws {
  std::vector<MeshData> meshes;
  std::vector<ReferenceTexture> textures;  // reference draws only
  Vec3f bounds_min, bounds_max;            // world space; min > max when there is no geometry
  // Reference draws: base colour images that could not be read, drawn from their material's
  // factor (ReferenceDrawOptions::missing_as_factor), one line each.
  std::vector<std::string> missing_textures;
};

// Ends each line of SceneDraws::missing_textures.
inline constexpr char kDrawnFromFactor[] = " (drawn from its factor, as the bake did)";

struct ReferenceDrawOptions {
  uint32_t max_texture_side = 4096;  // larger images are box-reduced to fit
  // A base colour image that cannot be read: the material's factor alone, as `vtbake bake
  // --missing-textures warn` baked it, listed in SceneDraws::missing_textures; false: an error.
  bool missing_as_factor = false;
};

// The unwrapped scene for the virtual-texture pass: every primitive with its UV set `uv_set`
// (-1: its last set, where the unwrapper puts the atlas UVs). Alpha-mask materials keep their
// cutoff. Errors name the mesh and primitive lacking the set.
Expected<SceneDraws> virtual_scene_draws(const scene::Scene& scene, int uv_set = -1);

// The original scene for the reference pass, under the bake's material rules
// (scene/material_rules.h): one reference texture per material, its base colour image
// (OpenImageIO; float images are taken as linear, others as sRGB) multiplied by
// base_color_factor in linear light and stored as sRGB 8-bit, with a full mip chain and the
// texture's sampler (wrap per axis, magFilter); a material without an image gets a 1 x 1 texture
// of its factor, and one no drawn primitive uses is not read. An image that cannot be read is
// an error naming the material and the slot (or see `options`). Each vertex's UV
// is the slot's texCoord set through its KHR_texture_transform (exact: the transform is affine)
// and its colour the primitive's COLOR_0 (alpha 1 for OPAQUE materials); MASK keeps its cutoff.
Expected<SceneDraws> reference_scene_draws(const scene::Scene& scene,
                                           const ReferenceDrawOptions& options = {});

}  // namespace vt::render
