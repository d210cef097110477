// Material transfer: fills the level-0 texels of every layer the scene's materials use from the
// source materials, through the atlas UVs the unwrapper added. Rasterisation in atlas space is
// exact (texel-centre samples, top-left fill rule, shared edges evaluated bit-identically so no
// sample lands in two triangles) and conservative (a texel any part of a triangle touches is
// covered; with no sample inside it takes the closest point of the closest triangle). Textures
// are read once through OpenImageIO into float MIP levels (colour converted to the working
// space per source texel, bake/transfer_texture.h) and filtered at the footprint of the atlas
// texel (or sub-sample): anisotropic, trilinear, bilinear taps. Normal maps are decoded in the
// source tangent frame and re-encoded in the atlas UVs' tangent frame. The output is linear
// (colour) or data texels plus a coverage mask, ready for build_page_file.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "bake/lighting.h"
#include "common/status.h"
#include "format/page_file.h"
#include "scene/scene.h"

namespace vt {

class ColorConfig;
class CoverageMask;
class LevelStore;

// What a texture that cannot be read does to the transfer.
enum class MissingTextures {
  kError,  // the transfer fails naming the material, the slot, the image and the path tried
  kWarn,   // the slot uses its factor alone; every miss is listed in TransferResult
};
Expected<MissingTextures> parse_missing_textures(const std::string& name);  // "error", "warn"

struct TransferOptions {
  uint32_t width = 0, height = 0;  // atlas size in texels
  int atlas_uv_set = -1;           // UV set holding atlas UVs; -1 = each primitive's last set
  int supersample = 1;             // samples per texel: 1, 4 (2x2) or 16 (4x4)
  int threads = 0;                 // 0 = all cores; the output does not depend on it
  // Folder for copies of embedded images (OpenImageIO's texture cache reads files). "" = the
  // system temporary folder. Copies are removed before transfer_materials returns.
  std::string scratch_dir;
  // Larger atlases are a resource error (default: the page format's 2^24 texels a side).
  uint64_t max_texels = uint64_t(1) << 48;
  // The atlas is transferred `band_rows` rows at a time (rounded to a multiple of 16; 0 = as
  // many as `band_memory` bytes of accumulators hold; in-memory stores: all rows, accumulated in
  // the stores themselves), each pass written to the layers' stores.
  // The texels do not depend on it.
  uint32_t band_rows = 0;
  uint64_t band_memory = uint64_t(256) << 20;
  // Memory for the scene's textures (bake/transfer_texture.h: every MIP level as floats,
  // w x h x channels x 4 bytes x 4/3 each). Textures loaded past it are read from mapped
  // scratch files under scratch_dir instead; the texels do not depend on it. The scene bake
  // passes texture_cache_bytes(limit).
  uint64_t texture_cache = uint64_t(2) << 30;
  // transfer_to_stores: the layers' stores are in memory, or scratch files under scratch_dir;
  // the same for the coverage mask (1 bit per texel, bake/coverage_mask.h).
  bool stores_in_memory = true;
  bool coverage_in_memory = true;
  // Scratch stores compressed in chunks (scratch_needs_compression in bake/level_store.h).
  bool compress_scratch = false;
  // Filter for MIP levels made (maketx-style, in the scratch folder) for untiled sources;
  // "" = box-filtered levels (TransferTexture's, colour averaged in linear light). A maketx
  // filter averages the file's encoded values. Measured against the texel-footprint (box)
  // average on stripes above the atlas Nyquist limit with OpenImageIO's TextureSystem (before
  // 2026-12-03): "lanczos3" lowered the RMSE at 1 sample per texel (0.048 -> 0.034) but raised it
  // at 4 and 16 (0.0003 -> 0.018 / 0.006); the box levels now give 0.00024 at every rate
  // (SceneBake.SupersamplingNeverLosesAccuracy), so the default keeps them.
  std::string mip_filter;
  MissingTextures missing_textures = MissingTextures::kError;
  // The atlas chart of every triangle, in transfer order (meshes, primitives that have
  // triangles, faces): unwrap::UnwrapResult::triangles[i].chart. Empty = charts are the
  // triangles connected through shared vertices or equal atlas UVs of a primitive.
  std::vector<int32_t> charts;
  // Base colour and emissive textures are converted from their colour space (file rules,
  // metadata, else sRGB/float linear) to this config's working space. Null = built-in config.
  std::shared_ptr<const ColorConfig> color_config;
  // The lighting layer, baked when the scene places a light (bake/lighting.h).
  LightingOptions lighting;
  // Band cache (bake/transfer_cache.h; not with a lighting layer, whose texels depend on the
  // whole scene): a band of rows whose key (its triangles, their primitives' data and
  // materials, the images those read, the settings) `cache_in` holds is read from it rather
  // than transferred; every band is stored in `cache_out`. "" = none. image_keys: a content key
  // per scene image (update_scene.h image_content_keys), needed by either. The texels do not
  // depend on the cache.
  std::string cache_in, cache_out;
  std::vector<uint64_t> image_keys;
  std::function<void(double fraction)> progress;  // from the calling thread, 0..1
};

struct TransferLayer {
  LayerSemantic semantic = LayerSemantic::kAlbedo;
  // albedo 3 or 4 (alpha only if a texel is not opaque), normal 3, ..., lighting 3 (+ AO),
  // lit albedo 3 or 4 (as albedo)
  uint32_t channels = 0;
  bool hdr = false;  // some value is above 1 (emissive or linear EXR sources)
  // Covered texels with a colour or data channel above 1 (alpha and normals excluded), and
  // the largest such value: what an 8-bit layer clips.
  uint64_t texels_above_one = 0;
  float max_value = 0;
  // width * height * channels floats. Albedo/emissive: linear RGB(A), not premultiplied.
  // ORM: occlusion, roughness, metallic. Normal: unit xyz in the atlas tangent frame.
  // Lighting: irradiance RGB (lux), then AO in [0, 1] when asked. Always hdr. Lit albedo
  // (LightingLayer::kCombined, in the lighting layer's place): linear base colour x irradiance
  // / pi RGB, then alpha as albedo's. Always hdr.
  // Uncovered texels are 0 (the build dilates them away).
  std::vector<float> texels;
  // transfer_to_stores: the texels in a store instead (memory or scratch file), `channels` a
  // texel.
  std::shared_ptr<LevelStore> store;
};

struct TransferStats {
  uint64_t triangles = 0;
  uint64_t covered_texels = 0;
  uint64_t sampled_texels = 0;    // covered texels with at least one sample inside
  uint64_t edge_only_texels = 0;  // covered conservatively only (closest-point value)
  uint64_t contested_texels = 0;  // touched by two charts (0 when the atlas has a gutter)
  uint64_t samples = 0;           // material evaluations
  // Normal-map samples that pointed below the surface, stored at the horizon (Transfer::evaluate).
  uint64_t below_horizon_samples = 0;
  LightingStats lighting;      // the lighting layer's samples and rays (none: all 0)
  uint64_t texture_bytes = 0;  // the source textures' MIP levels (memory or mapped scratch)
  uint64_t bands = 0;          // bands of rows, and those read from the band cache
  uint64_t bands_cached = 0;
  double seconds = 0;
  // Where `seconds` went, in order: "setup" (triangles, bins, band keys), "stores" (the layers'
  // level-0 stores made), "bands" (rasterised and sampled, or read from the band cache), "cache"
  // (the band cache written), "layers" (finished layers); then, beside them, "images" (the
  // textures' loading, on its own thread during "stores" and "bands") and "images_wait" (what
  // "bands" waited for it).
  std::vector<std::pair<const char*, double>> stage_seconds;
};

// A material texture slot whose image could not be read (MissingTextures::kWarn).
struct MissingTexture {
  std::string material;  // the material's name (may be empty)
  int material_index = -1;
  std::string slot;    // glTF's name for it: "baseColorTexture", "normalTexture", ...
  std::string image;   // the image's name, or "embedded image N 'name'"
  std::string path;    // the file tried (for an embedded image, its scratch copy)
  std::string reason;  // OpenImageIO's words
  // "material 'M' baseColorTexture: image 'I' (tried /a/b.png): REASON"
  std::string message() const;
};

struct TransferResult {
  uint32_t width = 0, height = 0;
  std::shared_ptr<const CoverageMask> coverage;  // width x height
  std::vector<TransferLayer> layers;  // in LayerSemantic order, only those the scene uses
  std::vector<MissingTexture> missing_textures;  // in material, then slot order
  TransferStats stats;
};

// A material's texture slots under glTF's names ("baseColorTexture", ...), in the order
// errors and misses are reported.
struct TextureSlot {
  const char* name;
  scene::TextureRef scene::Material::*ref;
};
std::span<const TextureSlot> texture_slots();

// Every texture slot of a material a primitive uses reads a UV set the primitive has. The error
// names the mesh, primitive, material, slot and set. Run on the scene before unwrapping: the
// atlas set the unwrapper appends would otherwise pass for a missing one.
Status check_texcoord_sets(const scene::Scene& scene);

// The texture memory a transfer gets within a memory limit: a quarter of it, at least 32 MiB
// and at most 2 GiB (the scene bake's default 8 GiB limit gives 2 GiB, as before the budget).
uint64_t texture_cache_bytes(uint64_t memory_limit);

// Every PNG a material in use reads (file or embedded) has whole chunks with correct CRCs
// (check_png_chunks). The error (kCorrupt, whatever MissingTextures says: the file is there but
// damaged) names the material, the slot, the file and the chunk. Files that cannot be opened
// pass here: the transfer reports them as missing textures.
Status check_scene_textures(const scene::Scene& scene);

// Which layers the materials of `scene` call for: albedo always; normal if some material has a
// normal map; ORM if some material has a metallic-roughness or occlusion texture or factors
// other than glTF's defaults; emissive if some material emits; lighting (lit albedo when
// `lighting` is combined) if a displayed node places a light. (Alpha is decided by texels.)
std::vector<LayerSemantic> layers_used(const scene::Scene& scene,
                                       LightingLayer lighting = LightingLayer::kSeparate);

// Transfers the materials of an unwrapped scene (meshes carrying atlas UVs in [0,1], glTF
// orientation: v down, texel row y = v * height). Texture slots honour their sampler (wrap
// modes, magFilter nearest), TEXCOORD_n and KHR_texture_transform; emissive is factor x
// strength x texture; base colour is factor x texture x COLOR_0. Errors name the image or mesh
// at fault; an unreadable texture names the material and slot too (see MissingTextures).
Expected<TransferResult> transfer_materials(const scene::Scene& scene,
                                            const TransferOptions& options);
// The same transfer out of core: the atlas is rasterised and sampled one band of rows at a
// time and each layer's texels go to TransferLayer::store (scratch files unless
// TransferOptions::stores_in_memory), so memory holds only a band's accumulators and the
// coverage. The texels are those transfer_materials gives, bit for bit.
Expected<TransferResult> transfer_to_stores(const scene::Scene& scene,
                                            const TransferOptions& options);

// Rasterisation alone, for tests and the atlas checks: triangles given as atlas texel
// coordinates (x0, y0, x1, y1, x2, y2) and a chart id each. owner[t] = the triangle whose
// value texel t takes (-1 = not covered), inside[t] = samples of t that lie inside a triangle.
struct AtlasRaster {
  std::vector<int32_t> owner;
  std::vector<uint8_t> inside;
  uint64_t contested_texels = 0;
  uint64_t double_sampled = 0;  // sub-sample positions claimed by two triangles (must be 0)
};
AtlasRaster rasterize_atlas(const std::vector<std::array<double, 6>>& triangles,
                            const std::vector<int32_t>& chart, uint32_t width, uint32_t height,
                            int supersample = 1);

// Sub-sample offsets inside a texel (in [0,1)^2) for 1, 4 or 16 samples per texel.
std::vector<std::array<double, 2>> supersample_pattern(int supersample);

}  // namespace vt
