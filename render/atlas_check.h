// Atlas-space page check: every stored and constant page of every layer of a scene bake, as the
// runtime uploads it (stored or transcoded BC blocks decoded as the GPU decodes them), against
// reference texels recomputed from the original materials: the transfer re-run over the whole
// atlas at full precision, the file's pyramid filter with the build's dilation for coarser
// levels, and the layer's storage conversion, border texels included. Exact up to the storage
// codec and the BC transcode, so one page from the wrong place or level, a wrong border or a
// swapped channel stands out. CPU only: no Vulkan.
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "bake/lighting.h"
#include "bake/pyramid.h"
#include "bake/transfer.h"
#include "common/status.h"
#include "format/page_file.h"
#include "scene/scene.h"

namespace vt {
class PageSource;
}

namespace vt::render {

// What a page of one layer must meet. Colour, ORM and custom layers: PSNR over every channel
// (8-bit scale) at least min_psnr. Normal layers: mean and largest angular error at most
// max_mean_deg and max_max_deg.
struct AtlasLayerBounds {
  double min_psnr = 30.0;
  double max_mean_deg = 4.0;
  double max_max_deg = 40.0;
  // Largest per-channel shift of a page's mean, 8-bit steps: catches a scaled or offset layer
  // on dark pages, where PSNR hardly moves (emissive at half strength).
  double max_mean_shift = 2.0;
  // A page below min_psnr still passes when within this of its runtime floor (the reference
  // page through the runtime's BC format alone; AtlasPageError::runtime_floor_psnr): content
  // that BC cannot hold, e.g. a coarse-level mosaic of tiny charts of unrelated colours, is not
  // the bake's error. 3 dB, plus what DCT storage costs on top of BC alone (the sample scene's
  // dct - bc bound difference) for DCT layers.
  double floor_margin_db = 3.0;
};

// Bounds for a layer from its semantic, storage codec and runtime format: the worst page
// measured on correct bakes of the sample scene (default DCT quality, BC, raw; every level)
// plus a margin (numbers in atlas_check.cpp).
AtlasLayerBounds default_atlas_bounds(const LayerSpec& layer);

struct AtlasCheckOptions {
  bool enabled = true;
  int threads = 0;  // 0 = all cores
  // The reference holds the whole atlas once (the transfer's buffers, then two levels): a
  // larger atlas is skipped with a note rather than run out of memory.
  uint64_t memory_limit = uint64_t(8) << 30;
  std::string scratch_dir;    // for the transfer's copies of embedded images; "" = temporary
  std::string out_dir;        // heat maps (atlas_<layer>_level<L>.png); "" = none
  uint32_t worst_pages = 8;   // pages listed per layer, worst first
  double psnr_offset_db = 0;  // added to every layer's min_psnr (negative loosens)
  // Compare the stored texels (decoded, before the runtime's BC transcode) instead of the
  // upload: a raw bake then matches its reference exactly, every page at kPsnrIdentical.
  bool stored_texels = false;
};

// One page's error. psnr: all channels, 8-bit scale (kPsnrIdentical when equal); normal layers
// also the angular error of the XY normals.
struct AtlasPageError {
  PageId id;
  uint32_t layer = 0;
  double psnr = 0;
  int max_abs = 0;
  double mean_shift = 0;  // largest |mean(upload) - mean(reference)| over channels, 8-bit steps
  double mean_deg = 0, max_deg = 0;
  // The reference page through the runtime's BC format alone (encode + decode): what a perfect
  // bake scores. Computed only for pages below their layer's min_psnr, 0 otherwise (see
  // AtlasLayerBounds::floor_margin_db).
  double runtime_floor_psnr = 0;
  bool missing = false;  // the reference covers the page but the file has none
  bool failed = false;
};

struct AtlasLayerReport {
  std::string name;
  LayerSemantic semantic = LayerSemantic::kAlbedo;
  std::string codec, runtime_format;
  AtlasLayerBounds bounds;
  uint64_t pages_checked = 0, pages_failed = 0;
  double min_psnr = 0, mean_psnr = 0;  // over the checked pages
  double worst_mean_shift = 0;
  double worst_mean_deg = 0, worst_max_deg = 0;  // normal layers
  std::vector<AtlasPageError> worst;  // worst first: the failing ones, then the closest to failing
  std::vector<std::string> heat_maps;
  std::string note;  // why the layer was not checked ("" = checked)
};

struct AtlasCheckReport {
  bool ran = false;  // false when disabled or skipped (see note)
  std::string note;
  std::vector<AtlasLayerReport> layers;
  double transfer_seconds = 0, seconds = 0;
  std::vector<std::string> failures;  // one line per failing layer, naming its worst pages
  bool passed() const { return failures.empty(); }
};

// What a scene bake recorded in its metadata that the references repeat. One parse: a 64K bake's
// metadata holds megabytes of page keys.
struct BakeSettings {
  bool scene_bake = false;  // "tool": "vtbake bake"
  int supersample = 1;
  MipFilter filter = MipFilter::kKaiser;
  // AO samples and distance, bounces; shadows on, whatever the bake used: the references always
  // cast them. Defaults for a file without.
  LightingOptions lighting;
  // kWarn when the bake drew some texture slot from its factor alone (`--missing-textures warn`
  // and an image it could not read), so that the references do the same.
  MissingTextures missing_textures = MissingTextures::kError;
  double texels_per_unit = 0;  // 0: not recorded
};
// Errors only for a mip filter this build does not know.
Expected<BakeSettings> baked_settings(const PageFileReader& reader);

// Checks `reader`'s pages against `unwrapped` (the scene the bake wrote, for its atlas UVs) with
// the materials and images of `original` (the scene it was baked from; they must have as many
// materials). A failing page is a report that has not passed(), not an error; errors are bad
// input (kInvalidArgument: the file is not a scene bake of this scene) or a failed write (kIo).
Expected<AtlasCheckReport> check_atlas_pages(std::shared_ptr<const PageFileReader> reader,
                                             const scene::Scene& original,
                                             const scene::Scene& unwrapped,
                                             const AtlasCheckOptions& options);
// The same with the file's settings already read (baked_settings).
Expected<AtlasCheckReport> check_atlas_pages(std::shared_ptr<const PageFileReader> reader,
                                             const BakeSettings& settings,
                                             const scene::Scene& original,
                                             const scene::Scene& unwrapped,
                                             const AtlasCheckOptions& options);

// What the runtime uploads for page `id` of `layer`, as the layer's stored channels: BC blocks
// decoded as the GPU decodes them, 8-bit uploads narrowed to spec.channels, float uploads as they
// are. `upload` is scratch; `out` takes page_size^2 texels of spec.texel_bytes().
Status uploaded_texels(const PageSource& source, const LayerSpec& spec, const PageId& id,
                       uint32_t layer, std::vector<uint8_t>& upload, uint8_t* out);

// The report as report.json's "atlas" object (docs/JSON.md).
nlohmann::json to_json(const AtlasCheckReport& report);

}  // namespace vt::render
