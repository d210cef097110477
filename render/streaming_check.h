// Exact streaming check in screen space: each view rendered with the baked levels as an ordinary
// mip-mapped texture (the texels the cache receives, decoded as the GPU decodes them; the same
// footprint filtering, shaders/common.glsl) on the unwrapped scene's atlas UVs, against the
// virtual-texture render of the same view. Both read the same texels, so they agree up to BC
// decoding and filtering rounding: a wrong page-table entry, cache slot, border or level shows
// up here even where the comparison with the original materials is loose.
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "common/status.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "runtime/page_source.h"

namespace vt::render {

// Largest side of a level the check holds as a texture: finer levels are dropped and the pixels
// that want them are excluded (and counted). 8192 x 8192 RGBA8 with its mips is 358 MB.
inline constexpr uint32_t kMaxLevelTextureSide = 8192;

// The baked levels of one layer as one mip chain. Level i of `texture` is the file's level
// first_level + i, in the top-left corner of a mip padded so that the chain halves as Vulkan's
// mips do where the file's levels halve with ceil (ReferenceTexture::levels_width).
struct LevelTexture {
  ReferenceTexture texture;
  uint32_t first_level = 0;   // finest level held (0 unless the atlas is over the side limit)
  uint32_t level_count = 0;   // the file's levels
  uint64_t absent_pages = 0;  // filled from their nearest present ancestor, upsampled nearest
};

// Tiles the payload of every page of `layer` (as source.load() uploads it, BC blocks decoded,
// missing channels as the GPU reads them: G, B 0 and A 255) into its level, borders ignored; the
// padding around a level holds its edge texels addressed by `address_mode`, as page borders
// past the atlas's edge do. Levels wider or taller than `max_side` are dropped from the fine
// end, every coarser level is held. Float layers give kUnsupported.
Expected<LevelTexture> assemble_level_texture(const PageSource& source, uint32_t layer,
                                              AddressMode address_mode,
                                              uint32_t max_side = kMaxLevelTextureSide,
                                              int threads = 0);

// What one view must meet. Measured on the sample scene (numbers in streaming_check.cpp).
struct StreamingBounds {
  int max_abs = 0;              // largest channel difference, 8-bit steps
  int steps = 0;                // a pixel "differs" when a channel is off by more than this
  double max_share_beyond = 0;  // share of compared pixels that differ
  // ...or at most this many of them, whichever is more: a share of a small view rounds to no
  // pixel at all.
  uint64_t max_pixels_beyond = 0;
  double min_psnr = 0;               // channels 0-2, whole view
  double min_tile_psnr = 0;          // worst 16 x 16 tile with at least 32 compared pixels
  double max_coverage_mismatch = 0;  // pixels drawn by one render only (alpha test flips)
  // Pixels whose taps read page borders (StreamingViewMetrics::border_pixels) are bounded apart:
  // a border is its page's own encoding of the neighbour's texels, which the level texture holds
  // only once (from the neighbour's payload), so the two differ by up to both pages' codec error.
  int border_max_abs = 0;
  double border_max_share_beyond = 0;  // share of border pixels off by more than `steps`
};
StreamingBounds default_streaming_bounds(RuntimeFormat cache_format);

struct StreamingViewMetrics {
  // Compared: drawn by both renders, wanting a level the texture holds. max_abs, share_beyond
  // and pixels_beyond count the pixels that read no page border; psnr and the tiles all of them.
  uint64_t pixels = 0;
  uint64_t excluded_fine = 0;      // wanted a dropped fine level
  uint64_t excluded_coarse = 0;    // wanted a dropped coarse level
  uint64_t excluded_fallback = 0;  // sampled a coarser level than wanted (page not resident)
  // Alpha-tested, alpha a few steps above the cutoff in a render that drew the pixel (the other
  // may have drawn it too, or discarded it: a flipped alpha test, not counted as a mismatch).
  uint64_t excluded_alpha_edge = 0;
  uint64_t coverage_mismatch = 0;  // drawn by one render only, not an alpha-edge flip
  int max_abs = 0;
  double psnr = 0;
  double share_beyond = 0;
  uint64_t pixels_beyond = 0;
  double worst_tile_psnr = 0;
  uint32_t worst_tile_x = 0, worst_tile_y = 0;  // its top-left pixel
  // Compared pixels whose taps read page border texels (the page's own encoding of its
  // neighbour's texels), with their own largest difference and count beyond `steps`.
  uint64_t border_pixels = 0, border_beyond = 0;
  int border_max_abs = 0;
};

// Compares the virtual-texture frame with the frame rendered from `levels` (same camera, size).
Expected<StreamingViewMetrics> compare_streaming(const ReferenceFrame& levels,
                                                 const VirtualFrame& frame,
                                                 const LevelTexture& texture, int steps);
// One line per broken bound; empty when the view passes.
std::vector<std::string> check_streaming(const StreamingViewMetrics& m, const StreamingBounds& b);

struct StreamingCheckOptions {
  bool enabled = true;
  uint32_t max_level_side = kMaxLevelTextureSide;
  std::optional<StreamingBounds> bounds;  // default_streaming_bounds(cache format) when unset
  int threads = 0;
};

struct StreamingViewResult {
  StreamingViewMetrics metrics;
  std::vector<std::string> failures;
  double render_ms = 0, compare_ms = 0;
};

struct StreamingCheckReport {
  bool ran = false;
  std::string note;  // why it did not run, or which levels were dropped
  StreamingBounds bounds;
  uint32_t first_level = 0, levels_held = 0, level_count = 0;
  uint64_t absent_pages = 0;
  double assemble_seconds = 0;
  std::vector<StreamingViewResult> views;  // one per camera when ran
};

// Runs the check over `cameras`, given the virtual frames already rendered for them. Sets the
// renderer's reference meshes to `meshes` (the virtual pass's, atlas UVs, reference_texture 0)
// and its reference textures to the levels: the original-material reference is gone afterwards.
Expected<StreamingCheckReport> run_streaming_check(Renderer& renderer, const PageSource& source,
                                                   uint32_t layer, AddressMode address_mode,
                                                   std::span<const MeshData> meshes,
                                                   std::span<const Camera> cameras,
                                                   std::span<const VirtualFrame> frames,
                                                   const StreamingCheckOptions& options);

// The report as report.json's "exact" object (docs/JSON.md).
nlohmann::json to_json(const StreamingCheckReport& report);

}  // namespace vt::render
