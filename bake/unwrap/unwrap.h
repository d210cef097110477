// vtbake's unwrapper: gives every triangle of a scene its own texels in one atlas.
// Charts are grown on normal deviation (material boundaries and original UV seams always cut),
// cut to disks, parameterised with CGAL (LSCM or ARAP), checked for flips, self-overlap and
// stretch (failing charts are split and redone), scaled to a world texel density (the scene's,
// from its textures by default, or a material's or object's own) and packed with rotation and a
// gutter into an atlas that is a whole number of pages.
#pragma once

#include <array>
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "common/status.h"
#include "scene/scene.h"

namespace vt::unwrap {

enum class Method { kLscm, kArap };

struct UnwrapOptions {
  // World texel density (texels per world unit). 0 = chosen: to fit `size_pages` when given,
  // else the sources' density (texel_density.h) held within [min_size_pages, max_size_pages],
  // else (nothing textured) to fit kDefaultSizePages.
  double texels_per_unit = 0.0;
  int size_pages = 0;      // fit the atlas to size_pages × size_pages pages; 0 = not asked
  int page_payload = 120;  // the atlas is a whole number of pages of this many texels
  // Empty texels kept between any two charts (the gutter). 8: texels of two charts are then 9
  // apart, so no 8x8 DCT block of level 0 and no 4x4 BC block of level 1 holds both (with 4,
  // quantisation rang one chart's colour into its neighbour: ClearCoatTest, docs/BENCHMARKS.md).
  int padding = 8;
  Method method = Method::kLscm;
  bool share_instances = false;       // false: every instance gets its own texels (megatexture)
  double max_chart_angle_deg = 60.0;  // a face joins a chart only within this cone of normals
  double max_chart_stretch = 1.05;    // chart L2 stretch above this is split and redone
  int max_split_rounds = 4;           // stretch split-and-redo rounds (disk/flip splits always run)
  int threads = 0;                    // 0 = hardware concurrency
  // Larger atlases are a resource error; the default is the page format's bound (2^24 texels a
  // side): memory limits are the bake's to check (bands make any size fit).
  int64_t max_atlas_texels = int64_t{1} << 48;
  // Bounds on the side of an atlas sized by the sources' density: a larger one is fitted to
  // max_size_pages (every density scaled alike), a smaller one to min_size_pages.
  int max_size_pages = 128;
  int min_size_pages = 4;
  // Per-material and per-object densities and the scene's own density or size, as a density
  // file (texel_density.h). "" = the scene's NAME.density.json when it exists; "-" = none.
  // --texels-per-unit and --size (the fields above) win over the file's.
  std::string density_file;
};

// The atlas side, in pages, when nothing sets the density: no texture gives one.
constexpr int kDefaultSizePages = 16;

// Time spent per stage, seconds.
struct StageTimes {
  double segment = 0, parameterize = 0, pack = 0, check = 0, output = 0;
};

struct UnwrapStats {
  int64_t faces = 0;             // triangles unwrapped (instances counted separately)
  int64_t degenerate_faces = 0;  // zero-area triangles (mapped to a tiny chart of their own)
  int64_t charts = 0;
  int split_rounds = 0;      // stretch split-and-redo rounds that found work
  int64_t charts_split = 0;  // charts split for non-disk topology, flips, overlap or stretch
  int atlas_width = 0, atlas_height = 0;  // texels
  int pages_x = 0, pages_y = 0;
  double texels_per_unit = 0;         // achieved by every chart without its own density
  double source_texels_per_unit = 0;  // the sources' density (kSourcePercentile), 0 = none
  // How the density was chosen: "texels_per_unit" (asked), "size" (fit size_pages), "sources",
  // "sources, capped" (fitted to max_size_pages), "sources, floored" (to min_size_pages),
  // "default size" (nothing textured), "default size, grown to fit its charts" (more charts
  // than kDefaultSizePages hold at any density).
  std::string density_rule;
  std::string density_file;  // the density file read, "" = none
  struct MaterialDensity {
    std::string name;
    double source = 0;     // texels per unit its textures give (area-weighted median), 0 = none
    double requested = 0;  // its own texels per unit (density file or glTF extras), 0 = none
    double requested_scale = 0;  // its own scale of the scene's density, 0 = none
    double achieved = 0;         // texels per unit its charts got (area-weighted mean)
  };
  std::vector<MaterialDensity> materials;  // materials with a source or a requested density
  // Objects (nodes) denser than the scene's sources, given a scale of the scene's density of
  // their own (texel_density.h's object_scales).
  struct ObjectDensity {
    std::string name;
    double source = 0;  // texels per unit of its sources (kSourcePercentile)
    double scale = 0;   // of the scene's density
  };
  std::vector<ObjectDensity> objects;
  // E.g. the bake is more than 2x coarser than its sources, naming the worst materials.
  std::vector<std::string> warnings;
  double utilisation = 0;  // texel centres covered by a triangle / atlas texels
  double stretch_l2 = 0;   // Sander et al., area weighted, normalised so UV area = 3D area
  double stretch_linf = 0;
  int64_t flipped_triangles = 0;      // UV orientation opposite to the chart's (must be 0)
  int64_t overlapping_triangles = 0;  // triangles sharing a covered texel centre (must be 0)
  int64_t overlapping_texels = 0;     // texels touched by two charts, conservatively (must be 0)
  int64_t unmapped_faces = 0;         // faces with non-finite atlas UVs (must be 0)
  StageTimes seconds;
};

// One triangle as laid out in the atlas, for pictures and checks.
struct AtlasTriangle {
  // Atlas texel coordinates (x right, y down) of its three corners, exactly as transfer reads
  // them: the float atlas UVs times the atlas size, in double.
  std::array<double, 6> uv;
  int32_t chart = 0;
  float stretch_l2 = 1.0f;  // this triangle's Sander L2 stretch (normalised)
};

struct UnwrapResult {
  scene::Scene scene;  // the input with a new TEXCOORD_n (n = old UV set count) per primitive
  UnwrapStats stats;
  std::vector<AtlasTriangle> triangles;  // every unwrapped triangle
};

// Unwraps every mesh instance of `scene`. With share_instances false each instance becomes a
// mesh of its own in the output. Errors: non-finite positions or bad indices (naming the mesh
// and vertex), an atlas over max_atlas_texels, an invalid option.
Expected<UnwrapResult> unwrap_scene(const scene::Scene& scene, const UnwrapOptions& options);

// Writes the unwrapped scene as .glb with TANGENT in the atlas frame (the one the baked normal
// layer is expressed in; gltf_export.h GltfWriteOptions::atlas_tangents).
Status save_unwrapped_glb(const UnwrapResult& result, const std::string& path);

// Texel-space checks of a laid-out atlas with the atlas rasteriser (atlas_raster.h; used by
// unwrap_scene, exposed for tests): utilisation (texel centres covered), overlapping triangles
// (texel centres two triangles own by the fill rule) and overlapping texels (texels two charts
// touch: what transfer counts as contested).
struct AtlasCheck {
  double utilisation = 0;
  int64_t covered_texels = 0;
  int64_t overlapping_triangles = 0;
  int64_t overlapping_texels = 0;
  int64_t flipped_triangles = 0;  // clockwise (x right, y down) triangles of nonzero area
};
AtlasCheck check_atlas(const std::vector<AtlasTriangle>& triangles, int width, int height);

// The unwrap report as JSON text.
std::string report_json(const UnwrapStats& stats);
// The density part of the report (also in the scene bake's): {"texels_per_unit",
// "source_texels_per_unit", "rule", "file", "materials": [{"name", "source", "requested",
// "achieved"}], "warnings"}.
nlohmann::json density_json(const UnwrapStats& stats);
// A PNG of the atlas: left half charts in distinct colours, right half L2 stretch (blue = 1,
// red >= 1.5), background dark. At most max_side pixels per half-side (the atlas is scaled down).
Status write_atlas_picture(const UnwrapResult& result, const std::string& path,
                           int max_side = 2048);

}  // namespace vt::unwrap
