// Texel density from the sources: how many texels per world unit a scene's textures give on its
// surfaces, the statistic the atlas is sized by, and the density side file (per-material and
// per-object densities). Image sizes come from headers only (OpenImageIO), never from pixels.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "common/status.h"
#include "scene/scene.h"

namespace vt::unwrap {

// The fraction of textured area the default atlas density must serve: the area-weighted 90th
// percentile of the per-triangle source density. The median would halve the density of the
// detailed tenth of a scene (signs, faces); the maximum would let one small, densely mapped
// decal size the whole atlas.
constexpr double kSourcePercentile = 0.9;

// The default atlas density over that source density. The bake resamples its sources, and a
// texel of the atlas at the source's own density lands between source texels: the bilinear
// resample of a resample blurs, and close views' worst tiles reached only 16-20 dB against the
// sources. Twice the density brought them over 20 dB on the corpus models measured (see
// docs/BENCHMARKS.md) for 4x the level-0 texels, which --max-size and the memory limit bound.
constexpr double kSourceOversample = 2.0;

// An object (node) whose own sources are more than kSourceOversample times denser than the
// scene's percentile would be baked coarser than its sources (a smaller, nearer copy of a shared
// texture: Collada/earthCylindrical's second globe): it gets its density in proportion, at most
// this many times the scene's. Denser objects short of that keep at least one baked texel per
// source texel at the scene's density, as the scene's own densest tenth does.
constexpr double kMaxObjectScale = 4.0;

// The texels those objects add may at most equal this share of the scene's textured texels at
// its own density; beyond it every object's scale is reduced alike (on a log scale), so that a
// densely mapped decal cannot decide the atlas's size.
constexpr double kObjectScaleBudget = 1.0;

// One textured triangle: its linear source density (texels per world unit) and its world area.
struct DensitySample {
  double texels_per_unit = 0;
  double area = 0;
};

// The area-weighted quantile `p` (0..1) of `samples`: the smallest density d such that the
// triangles with density <= d hold at least p of the total area. 0 when there is no area.
double area_percentile(std::vector<DensitySample> samples, double p);

// The linear source density of one triangle: sqrt(width * height * uv_area / world_area) for a
// texture of width x height texels, uv_area in UV units (1 = the whole texture once) and
// world_area in square world units. 0 when either area is zero or not finite.
double triangle_source_density(double width, double height, double uv_area, double world_area);

// Width and height of an image from its header (a file or embedded bytes).
Expected<std::array<int, 2>> image_size(const scene::Image& image);

struct SourceDensity {
  // Per material (Scene::materials order): the area-weighted median density of its textured
  // triangles (the slot with the most texels per triangle), 0 = untextured or never drawn.
  std::vector<double> material;
  std::vector<double> material_area;  // world area of each material's textured triangles
  // Per node (Scene::nodes order): kSourcePercentile over the textured triangles of the meshes
  // it holds (not its subtree), and their world area; 0 = none.
  std::vector<double> node, node_area;
  double scene = 0;  // kSourcePercentile over every textured triangle, 0 = none
  // Images whose header could not be read ("NAME: why"): their slots give no density. Transfer
  // reports missing textures by its own policy, so this is not an error here.
  std::vector<std::string> unreadable;
};

// Measures the scene's source density over every mesh instance in world space (with
// share_instances, each mesh once, placed by its first instance, as the unwrapper does). Reads
// the header of every image a drawn material uses.
SourceDensity measure_source_density(const scene::Scene& scene, bool share_instances);

// Per node: the scale of the scene's density its own sources ask for (SourceDensity::node over
// SourceDensity::scene, capped at kMaxObjectScale and by kObjectScaleBudget), 0 where that ratio
// is at most kSourceOversample or `has_own` (its own density was given) says so.
std::vector<double> object_scales(const SourceDensity& source, const std::vector<char>& has_own);

// A surface's own density: texels per world unit, or a scale of the scene's density (2 = twice
// as fine as the rest). Neither set = the scene's.
struct OwnDensity {
  double texels_per_unit = 0;
  double scale = 0;
  bool set() const { return texels_per_unit > 0 || scale > 0; }
};

// The density side file, JSON:
//   {"texels_per_unit": 40, "size_pages": 16,
//    "materials": {"Brick": 200, "Floor": {"scale": 0.5}},
//    "objects": {"Sign": {"texels_per_unit": 400}}}
// every key optional. "texels_per_unit" and "size_pages" are the scene's density or atlas size
// (as --texels-per-unit and --size; the command line wins); "materials" name materials and
// "objects" (or "nodes") name nodes (a node's density covers its subtree; the deepest named node
// wins, and an object's density wins over its material's). A value is texels per world unit, or
// {"texels_per_unit": D} or {"scale": K} (K times the scene's density). The same densities can
// come from glTF: extras.vtbake_texels_per_unit on a material or node (the file wins).
struct DensityFile {
  std::string path;
  double texels_per_unit = 0;
  int size_pages = 0;
  std::vector<OwnDensity> materials;  // per material, unset = not named
  std::vector<OwnDensity> nodes;      // per node as named (subtrees not applied)
};

// Reads and checks a side file against the scene: errors name the file and the problem (bad
// JSON, a non-positive density, a material or object the scene does not have).
Expected<DensityFile> load_density_file(const std::string& path, const scene::Scene& scene);

// Per node: the own density that applies to it, the deepest named node of its path winning
// (`named` per node; the scene's roots down).
std::vector<OwnDensity> spread_to_subtrees(const scene::Scene& scene,
                                           const std::vector<OwnDensity>& named);

// The side file looked for beside a scene when none is named: "DIR/NAME.gltf" ->
// "DIR/NAME.density.json". "" for a scene with no source path.
std::string default_density_file(const std::string& scene_path);

// The density file the unwrap of `scene` reads for the option `density_file` (UnwrapOptions):
// the file named, or "" for "-", or when none is named the default beside the scene if it
// exists ("" otherwise).
std::string density_file_to_read(const scene::Scene& scene, const std::string& density_file);

// The largest square atlas side, in pages of `page_payload` texels, whose texels fit `texels`.
int pages_within(double texels, int page_payload);

}  // namespace vt::unwrap
