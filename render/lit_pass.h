// The lit comparison (issue 15 item 3): the same metal-roughness shading rendered from the
// original materials (base colour, normal map in the mesh's tangent frame, occlusion /
// roughness / metallic, emissive) and through the virtual texture (the albedo, normal, ORM and
// emissive layers, all streamed through one page table). This file holds the scene side (what
// the lit reference samples, the shading frames, the lights of a view) and the glue to the
// streamer; the passes themselves are Renderer::render_lit_reference / render_lit_virtual.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "common/status.h"
#include "format/page_file.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene_draws.h"
#include "runtime/streamer.h"
#include "scene/scene.h"

namespace vt::render {

// Which layer of the page source feeds each lit input (LitInput order); nullopt: not baked,
// or not renderable (a float layer: `skipped` says which). A lit pass runs only when some input
// beyond albedo is set.
struct LitLayers {
  std::array<std::optional<uint32_t>, kLitInputCount> layer;
  std::array<RuntimeFormat, kLitInputCount> format{};  // the layer's upload (cache) format
  std::vector<std::string> skipped;  // "emissive: runtime format rgba16f cannot be rendered"
  bool any() const { return layer[1] || layer[2] || layer[3]; }
  // LitFrameOptions::inputs: the inputs beyond albedo that have a layer.
  uint32_t inputs() const;
};

// The lit inputs of a page file: the first layer of each semantic (albedo, normal, ORM,
// emissive), or with `only` non-empty, albedo and the layer named `only` (a normal, ORM or
// emissive layer). kInvalidArgument when `only` names another kind of layer.
Expected<LitLayers> find_lit_layers(std::span<const LayerSpec> layers,
                                    std::span<const RuntimeFormat> upload_formats,
                                    const std::string& only = "");

// The lights of a view, from its camera: the key light above and to the right of the camera,
// the fill light low on the left, both behind the camera, so every surface the view sees is lit.
LitFrameOptions lit_frame_for(const Camera& camera, uint32_t inputs);

// One LitMaterial per material and one for the default material (last), in the order of
// reference_scene_draws' textures, under the same options (texture size; an image that cannot be
// read is an error naming the material and the image, or the slot's factor alone, listed in
// `missing`).
Expected<std::vector<LitMaterial>> lit_materials(const scene::Scene& scene,
                                                 const ReferenceDrawOptions& options = {},
                                                 std::vector<std::string>* missing = nullptr);

// Fills the vertex normals and tangents of `draws` (made by reference_scene_draws or
// virtual_scene_draws from `scene`, same order) in world space: the primitive's own, else
// scene/tangent_frame.h's, as the bake's transfer derives them. For the reference draws
// (`reference`), also each vertex's tex_uv: the normal, occlusion, metallic-roughness and emissive
// slots' UV sets through their KHR_texture_transform (scene/material_rules.h).
Status add_shading_frames(const scene::Scene& scene, SceneDraws& draws, bool reference);

// The renderer's lit caches for `lit`, in the streamer's slots (after set_virtual_texture).
Status set_lit_caches_for(Renderer& renderer, const LitLayers& lit);
// Copies the uploaded pages' lit layers into their caches.
Status upload_lit_pages(Renderer& renderer, const LitLayers& lit,
                        std::span<const PageUpload> uploads);

// The lights of an emissive-only frame: every light off and only the emissive input, so both
// passes shade to the emissive contribution alone (black elsewhere).
LitFrameOptions emissive_frame_for(const Camera& camera);
// A normals frame: both passes write their shading normal (render/normal_check.h).
LitFrameOptions normals_frame_for(const Camera& camera);

struct LitFrames {
  ReferenceFrame reference;
  VirtualFrame virt;
  double reference_ms = 0, virtual_ms = 0;  // each pass with read back
  // With an emissive layer: the emissive-only pair (emissive_frame_for), both passes' time.
  std::optional<ReferenceFrame> emissive_reference;
  std::optional<VirtualFrame> emissive_virtual;
  double emissive_ms = 0;
  // With a normal layer: the normals pair (normals_frame_for), both passes' time.
  std::optional<ReferenceFrame> normals_reference;
  std::optional<VirtualFrame> normals_virtual;
  double normals_ms = 0;
};
// Both lit passes of one view (the streamer converged, the caches uploaded), and the
// emissive-only pair when `lit` has an emissive layer.
Expected<LitFrames> render_lit_view(Renderer& renderer, const Camera& camera, const LitLayers& lit);

}  // namespace vt::render
