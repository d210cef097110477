// Screen-space check of the lighting layer (issue 21): per view, the baked irradiance (or, for a
// `--lighting combined` bake, the lit albedo: base colour x irradiance / pi) rendered
// through the virtual-texture path (feedback -> streamer -> page table -> cache, tone-mapped
// x / (1 + x) in the virtual pass) against a reference computed per pixel from the ORIGINAL
// scene: each pixel's surface found by a ray through its centre (world position, geometric and
// shading normal, the normal map applied: a G-buffer), lit by bake/lighting.h's light model with
// its shadow rays and AO, and tone-mapped alike. The atlas check (atlas_check.h) judges the
// layer's texels; this judges what a viewer sees, through the runtime's own sampling.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "bake/lighting.h"
#include "common/status.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene_draws.h"
#include "render/validate.h"
#include "runtime/streamer.h"

namespace vt::render {

// The reference side: the original scene's lights and ray structure, and its draws for the
// surfaces' attributes.
class LightingReference {
 public:
  // `draws`: reference_scene_draws(scene) with add_shading_frames(scene, draws, true) applied;
  // `materials`: lit_materials(scene) (their normal maps). Both are copied. `options`: the bake's
  // AO and layer mode (combined: the frame is the lit albedo, the base colour from the draws'
  // reference textures and vertex colours); shadows are always cast (a --no-shadows bake must
  // fail). `texel_size`: the world size of
  // a baked texel (1 / the bake's texels_per_unit; 0 = unknown): a pixel's rays spread over it
  // where it is larger than the pixel.
  static Expected<std::unique_ptr<LightingReference>> create(
      const scene::Scene& scene, const SceneDraws& draws, std::span<const LitMaterial> materials,
      LightingOptions options, double texel_size, int threads, uint32_t samples_per_side = 4);
  ~LightingReference();
  // One frame: rgb = 255 x E / (1 + E) per channel of irradiance E (lux; combined: of lit
  // albedo), alpha = 255 x AO (255 without AO), E and AO the means of samples_per_side^2 rays
  // spread over the pixel (or the baked texel, if larger) that meet the mesh its centre meets;
  // `covered` bit 0 where the centre's ray met a surface.
  Expected<ReferenceFrame> render(const Camera& camera, uint32_t width, uint32_t height) const;

 private:
  LightingReference() = default;
  std::unique_ptr<LightingBaker> baker_;
  std::unique_ptr<SurfaceCaster> caster_;
  std::vector<MeshData> meshes_;
  std::vector<LitMaterial> materials_;
  std::vector<ReferenceTexture> textures_;  // base colours (combined only)
  bool combined_ = false;
  int threads_ = 0;
  uint32_t samples_per_side_ = 4;
  double texel_size_ = 0;
};

// Bounds of the lighting view check, measured on the lit sample scene (docs/BENCHMARKS.md).
Thresholds lighting_thresholds();

struct LightingViewResult {
  LightingViewReport report;          // metrics (rgb: tone-mapped irradiance; alpha: AO), times
  std::vector<std::string> failures;  // check_view() against the bounds
  Rgba8Image reference, virt;         // the two frames (for the images)
};

struct LightingViewOptions {
  uint32_t layer = 0;  // the lighting layer of the page source
  AddressMode address_mode = AddressMode::kClamp;
  StreamerOptions streamer;
  uint32_t max_frames = 48;
  Thresholds thresholds = lighting_thresholds();
};

// One view: a cold streamer over the lighting layer, the loop to convergence, the tone-mapped
// virtual pass and the reference frame, compared. Leaves the renderer's virtual texture set to
// the lighting layer.
Expected<LightingViewResult> check_lighting_view(Renderer& renderer,
                                                 std::shared_ptr<const PageSource> source,
                                                 const LightingReference& reference,
                                                 const Camera& camera,
                                                 const LightingViewOptions& options);

}  // namespace vt::render
