// The virtual-texture loop of the validation renderer, as a game runs it: feedback pass ->
// read back -> runtime Streamer (resolver, cache, loader, page table) -> copy uploaded pages
// into the physical cache -> page-table texture update -> repeat until no new page comes;
// then the final pass, compared with the reference pass.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "common/status.h"
#include "render/atlas_check.h"
#include "render/camera.h"
#include "render/emissive_check.h"
#include "render/lit_pass.h"
#include "render/normal_check.h"
#include "render/renderer.h"
#include "render/streaming_check.h"
#include "render/view_density.h"
#include "render/view_planner.h"
#include "runtime/streamer.h"

namespace vt::render {

// The renderer's virtual texture for one layer of a streamer's source (slots, format, geometry).
// kUnsupported for formats the renderer cannot sample (float layers).
Expected<VirtualTextureSetup> virtual_setup_for(const Streamer& streamer, uint32_t layer,
                                                AddressMode address_mode);

struct ConvergeOptions {
  uint32_t layer = 0;        // the layer the renderer's cache holds
  uint32_t max_frames = 48;  // give up (converged = false) after this many frames
  // Consecutive frames that must map nothing new: one cycle of the feedback pass's tap rotation
  // and jitter, so every tap of every pixel has asked once.
  uint32_t quiet_frames = 4;
  LitLayers lit;  // layers uploaded into the renderer's lit caches beside `layer`
};

struct ConvergeResult {
  bool converged = false;
  uint32_t frames_to_converge = 0;  // frames until the last one that brought a new page
  uint32_t frames_rendered = 0;     // including the quiet frames
  uint32_t pages_uploaded = 0;
  uint32_t load_errors = 0;
  bool thrashing = false;           // the working set did not fit the cache in some frame
  std::vector<double> feedback_ms;  // per frame: feedback pass + read back (wall clock)
  std::vector<double> stream_ms;    // per frame: streamer update + uploads + page table
};

// Runs the loop for one view. The renderer's virtual texture must come from
// virtual_setup_for(streamer, options.layer, ...). Deterministic: waits for the loader every
// frame, so the result does not depend on thread timing.
Expected<ConvergeResult> converge_view(Renderer& renderer, Streamer& streamer, const Camera& camera,
                                       const ConvergeOptions& options = {});

// Per-view comparison of the final pass against the reference pass.
struct ViewMetrics {
  uint64_t pixels = 0;    // pixels compared: drawn by both renders
  double psnr_rgb = 0;    // over the compared pixels, channels 0-2
  double psnr_alpha = 0;  // channel 3
  int max_abs = 0;        // largest channel difference
  // PSNR (channels 0-2) of the worst 16 x 16 tile with at least 32 compared pixels: a local
  // fault (a bad border, one wrong page) barely moves the whole-view PSNR but sinks its tile.
  double worst_tile_psnr = 0;
  uint32_t worst_tile_x = 0, worst_tile_y = 0;  // its top-left pixel
  double ssim = 0;                              // whole image, channels 0-2
  double coarser_share = 0;  // share of covered pixels whose fine taps read a coarser level
  uint64_t unresident_pixels = 0;
  // Share of the pixels either render drew that only one of them drew and no alpha cutoff
  // explains (render/coverage_tolerance.h).
  double coverage_mismatch_share = 0;
  uint64_t alpha_edge_pixels = 0;  // drawn by one render only, explained by an alpha cutoff
  uint64_t outline_pixels = 0;  // compared, within 2 of background or a silhouette, no border tap
};

// `alpha_cutoffs`: the scene's MASK cutoffs, which explain pixels drawn by one render only.
Expected<ViewMetrics> compare_view(const ReferenceFrame& reference, const VirtualFrame& frame,
                                   std::span<const float> alpha_cutoffs = {});

// Pass/fail bounds of one view. Measured on the synthetic bake (docs/BENCHMARKS.md): correct
// bakes score >= 55 dB whole view and per tile with an uncompressed cache, >= 35.6 / 34.1 dB
// with BC1; zeroed borders, a wrong page, an off-by-one table level or swapped channels sink
// the worst tile to <= 28.3 dB.
struct Thresholds {
  double min_psnr = 40.0;
  double min_tile_psnr = 40.0;
  double max_coarser_share = 0.05;  // after convergence
  // Alpha-tested edges flip on rounding differences between the two paths' filtering.
  double max_coverage_mismatch = 0.01;
  // validate_bake: a view whose density (view_density.h) is below this fails; 0.5 = the bake is
  // 2x coarser than its sources where the view looks.
  double min_density = 0.5;
};
// Defaults for a cache format: 40 dB for uncompressed caches, 30 dB for BC caches (BC1 alone
// costs ~36 dB on photographs, ../shared/ANCHORS.md).
Thresholds default_thresholds(RuntimeFormat cache_format);
// Bounds for a real bake against its original scene, where the reference is the source
// material, not the baked levels: transfer resampling, the storage codec and the BC transcode all
// count. Measured on the procedural sample scene (`vtbake sample-scene`, default DCT bake, BC3
// cache, 4 views at 640x360): 34.1-36.3 dB whole view, 24.9-26.6 dB worst tile. Provisional:
// min_psnr 30 dB, min_tile_psnr 20 dB, until broken real bakes have been measured.
Thresholds scene_thresholds();
// Why the view fails (one line per broken bound, or no compared pixel at all); empty when it
// passes.
std::vector<std::string> check_view(const ViewMetrics& metrics, const Thresholds& thresholds);

// Bounds of the lit comparison against the original materials (lit_pass.h), on top of the
// view's own: measured on the sample scene (docs/BENCHMARKS.md).
Thresholds lit_scene_thresholds();

struct LitViewReport {
  ViewMetrics metrics;  // the lit virtual render against the lit reference
  double reference_ms = 0, virtual_ms = 0;
  std::optional<EmissiveMetrics> emissive;  // with an emissive layer (emissive_check.h)
  double emissive_ms = 0;                   // both emissive-only passes
  std::optional<NormalMetrics> normals;     // with a normal layer (normal_check.h)
  double normals_ms = 0;                    // both normals passes
};
// A view's "lit" object in report.json (docs/JSON.md).
nlohmann::json to_json(const LitViewReport& lit);

// The screen-space check of the lighting layer in one view (lighting_check.h): the tone-mapped
// irradiance through the virtual-texture path against the per-pixel reference from the original
// scene; alpha = AO (psnr_alpha reported, not judged: both sides are sampled).
struct LightingViewReport {
  ViewMetrics metrics;
  ConvergeResult converge;
  double reference_ms = 0, virtual_ms = 0;  // the CPU reference frame; the final virtual pass
};
// A view's "lighting" object in report.json (docs/JSON.md).
nlohmann::json to_json(const LightingViewReport& lighting);

struct ViewReport {
  uint32_t view = 0;
  ViewMetrics metrics;
  ConvergeResult converge;
  double reference_ms = 0;            // one reference pass with read back
  double virtual_ms = 0;              // one final pass with read back
  std::vector<std::string> failures;  // check_view(); empty when the view passes
  std::vector<std::string> images;    // files written for this view
  ViewDensity density;                // validate_bake: baked texels per source texel in view
  std::string framing;                // an automatic view: what it frames (PlannedView)
  // The lit comparison, when the bake has a normal, ORM or emissive layer it can render; its
  // failures are in `failures`, prefixed "lit: ".
  std::optional<LitViewReport> lit;
  // With a lighting layer: its screen-space check; failures in `failures`, prefixed "lighting: ".
  std::optional<LightingViewReport> lighting;
};

struct ValidationReport {
  std::string page_file;
  uint32_t layer = 0;
  std::string cache_format;
  std::string device;
  uint32_t width = 0, height = 0;
  Thresholds thresholds;
  Thresholds lit_thresholds;
  EmissiveBounds emissive_bounds;
  NormalBounds normal_bounds;
  Thresholds lighting_thresholds;        // the lighting view check's (with a lighting layer)
  std::vector<std::string> lit_layers;   // the layers the lit pass read (names); empty: no lit pass
  std::vector<std::string> lit_skipped;  // layers it could not render, and why
  std::vector<ViewReport> views;
  std::string out_dir;     // where the PNGs (and, from validate_bake, report.json) went; "" = none
  AtlasCheckReport atlas;  // validate_bake's atlas-space page check (atlas.ran: it ran)
  // What the run could not take into account: the importers' warnings of both scenes (each
  // naming its file), atlas layers left unchecked and why.
  std::vector<std::string> warnings;
  std::string contact_sheet;  // validate_bake's one-glance PNG (render/contact_sheet.h)
  // validate_bake's wall clock per stage, seconds: reading the camera file, the page file and
  // both scenes; the atlas check; Vulkan and renderer set-up; every view; the contact sheet.
  struct Seconds {
    double load = 0, atlas_check = 0, setup = 0, views = 0, contact_sheet = 0, total = 0;
  } seconds;
  StreamingCheckReport exact;  // the exact streaming check (exact.ran: it ran)
  ViewPlan view_plan;          // validate_bake's automatic views (none with a camera file)
  // Every view passes and the atlas check found no failing page; with no views, the atlas check
  // ran and passed.
  bool passed() const;
};

struct ValidateOptions {
  uint32_t layer = 0;
  AddressMode address_mode = AddressMode::kClamp;  // the layer's, from the page file
  StreamerOptions streamer;
  ConvergeOptions converge;              // its layer is set from `layer`
  std::optional<Thresholds> thresholds;  // default_thresholds(cache format) when unset
  LitLayers lit;                         // lit pass inputs; none set: no lit pass
  Thresholds lit_thresholds = lit_scene_thresholds();
  EmissiveBounds emissive_bounds = default_emissive_bounds();
  NormalBounds normal_bounds = default_normal_bounds();
  std::string
      out_dir;  // where PNGs go (view_<i>_{reference,virtual,diff,residency}.png); "" = none
  std::vector<float> alpha_cutoffs;  // the scene's MASK cutoffs (compare_view)
  // The exact streaming check runs after the views when `exact_meshes` (the meshes set_meshes
  // was given) is not empty; it leaves the renderer's reference set to the baked levels.
  StreamingCheckOptions exact;
  std::span<const MeshData> exact_meshes;
  // The pages the exact check's level texture holds; unset: `source`, what the cache streams.
  // Another source (the file as written, when the cache is fed from elsewhere) makes the check
  // see a fault between the file and the cache.
  std::shared_ptr<const PageSource> exact_levels;
};

// Validates one layer over `cameras`: per view a cold streamer over `source`, the loop to
// convergence, the final and reference passes, metrics, pass/fail and (optionally) images.
// The renderer's meshes and reference textures must already be set.
Expected<ValidationReport> validate_views(Renderer& renderer,
                                          std::shared_ptr<const PageSource> source,
                                          std::span<const Camera> cameras,
                                          const ValidateOptions& options);

// A bake against the scene it came from, as `vtbake validate` runs it.
struct BakeValidationOptions {
  std::string scene;      // the original scene (any format scene::load_scene reads)
  std::string page_file;  // the bake (.vtpf)
  std::string unwrapped;  // the unwrapped scene the bake wrote; "" = page_file with .glb
  std::string out_dir;    // PNGs and report.json; "" = page_file with .validate
  // "" = the albedo layer, plus the lit check with every normal, ORM and emissive layer; a
  // normal, ORM or emissive layer's name = the albedo check and the lit check with that layer.
  std::string layer;
  std::string cameras_file;  // a camera file (camera.h); "" = `views` planned views
  uint32_t views = 6;        // planned views (view_planner.h): overview, surfaces, texels
  UpAxis up = UpAxis::kAuto;
  uint32_t width = 1280, height = 720;
  Thresholds thresholds = scene_thresholds();
  Thresholds lit_thresholds = lit_scene_thresholds();
  EmissiveBounds emissive_bounds = default_emissive_bounds();
  NormalBounds normal_bounds = default_normal_bounds();
  // The lighting view check's bounds; unset: lighting_thresholds() (lighting_check.h).
  std::optional<Thresholds> lighting_thresholds;
  uint32_t slots = 32;           // physical cache slots per side
  uint32_t max_frames = 48;      // per view, before giving up converging
  bool prefer_hardware = false;  // a hardware Vulkan device rather than lavapipe
  AtlasCheckOptions atlas;       // out_dir is set to out_dir
  StreamingCheckOptions exact;   // the virtual render against the baked levels
  bool render_views = true;      // false: the atlas check alone (no Vulkan needed)
  scene::SceneLoadOptions load;  // how the original scene is read
};

// Reads the camera file (first, so that a bad one fails fast), the page file and both scenes,
// checks every page in atlas space (check_atlas_pages, no GPU), renders every view through the
// virtual-texture path and from the original materials (validate_views) and writes the PNGs and
// report.json into out_dir. A view out of bounds is a report that has not passed(), not an error;
// errors are bad input (kInvalidArgument, kNotFound, kCorrupt), no usable Vulkan device
// (kUnsupported) or a failed write (kIo).
Expected<ValidationReport> validate_bake(const BakeValidationOptions& options);

}  // namespace vt::render
