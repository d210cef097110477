// Internal pieces of vt_unwrap shared between its source files (not installed, not for callers).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include <string>

#include "bake/unwrap/texel_density.h"
#include "bake/unwrap/unwrap.h"
#include "common/vec.h"

namespace vt::unwrap::detail {

// The smallest axis-aligned box holding some points; lo > hi on every axis when there are none.
template <class V>
struct Bounds {
  V lo, hi;
};
inline Bounds<Vec2d> bounds_of(const std::vector<Vec2d>& points) {
  Bounds<Vec2d> b{{1e300, 1e300}, {-1e300, -1e300}};
  for (const Vec2d& p : points) {
    b.lo = {std::min(b.lo.x, p.x), std::min(b.lo.y, p.y)};
    b.hi = {std::max(b.hi.x, p.x), std::max(b.hi.y, p.y)};
  }
  return b;
}
inline Bounds<Vec3d> bounds_of(const std::vector<Vec3d>& points) {
  Bounds<Vec3d> b{{1e300, 1e300, 1e300}, {-1e300, -1e300, -1e300}};
  for (const Vec3d& p : points) {
    b.lo = {std::min(b.lo.x, p.x), std::min(b.lo.y, p.y), std::min(b.lo.z, p.z)};
    b.hi = {std::max(b.hi.x, p.x), std::max(b.hi.y, p.y), std::max(b.hi.z, p.z)};
  }
  return b;
}

enum class ParamStatus { kOk, kNotDisk, kFailed };

// Parameterises one chart (a connected manifold face set with local vertices) with CGAL.
// Returns kNotDisk when the faces do not form one disk, kFailed when the solver fails; on kOk
// `uv` holds one point per vertex (not yet checked for flips: the caller does that).
// This is the only function that touches CGAL, so CGAL is compiled once.
ParamStatus parameterize_chart(const std::vector<Vec3d>& vertices,
                               const std::vector<std::array<uint32_t, 3>>& faces, Method method,
                               std::vector<Vec2d>* uv);

// A chart ready to pack: triangles in chart-local texel coordinates (already scaled to the
// texel density and rotated to a small bounding box), origin at the box's minimum corner.
struct PackChart {
  std::vector<Vec2d> points;                  // local texel coordinates
  std::vector<std::array<uint32_t, 3>> tris;  // into points
  double width = 0, height = 0;               // bounding box
};

// Where a chart went: rotation by quarter turns (counter-clockwise in x-right/y-up), then an
// integer texel offset.
struct Placement {
  int rotation = 0;
  int x = 0, y = 0;
};

struct PackResult {
  std::vector<Placement> placements;
  int width = 0, height = 0;  // used extent in texels (height = top of the skyline)
  bool overflow = false;      // some chart was wider than the atlas in every rotation
};

// Skyline packing of conservative chart footprints, `padding` empty texels between charts,
// into an atlas `width` texels wide. Deterministic. Once the packed height passes
// `give_up_above` the packing stops (a trial that cannot fit a height): the height returned is
// then over it and the placements incomplete.
PackResult pack_charts(const std::vector<PackChart>& charts, int width, int padding, int threads,
                       int give_up_above = std::numeric_limits<int>::max());

// Applies a placement to a local point (the inverse of nothing: used to write atlas UVs).
Vec2d place_point(const PackChart& chart, const Placement& placement, const Vec2d& p);

// How stage 4 sizes the atlas: the options, the density file and the sources' density decide
// (texel_density.cpp).
struct DensityPlan {
  enum class Mode {
    kExact,     // texels_per_unit as given
    kFitPages,  // scaled to fill pages x pages
    kBounded,   // texels_per_unit unless the atlas side leaves [min_pages, max_pages]
  };
  Mode mode = Mode::kFitPages;
  double texels_per_unit = 0;  // the density of a chart with no density of its own; 0 = none
  int pages = 0;
  int min_pages = 0, max_pages = 0;
  // kFitPages at the default size (nothing asked for a size): when the charts cannot fit
  // `pages` at any density, the atlas grows instead, up to max_pages.
  bool may_grow = false;
  // Own densities per material (density file, else glTF extras) and per node (subtrees applied).
  std::vector<OwnDensity> materials, nodes;
  // Per node: the scale its own sources ask for where nothing was given (object_scales), 0 = none.
  std::vector<double> object_scale;
  SourceDensity source;
  std::string rule, file;  // UnwrapStats::density_rule (before bounds) and density_file

  // The density a surface of `material` under `node` asks for: the node's own, else its
  // material's, else the node's object_scale; unset = the scene's.
  OwnDensity wanted(int material, int node) const;
};
Expected<DensityPlan> plan_density(const scene::Scene& scene, const UnwrapOptions& options);

// Fills UnwrapStats' density fields but the rule after packing: `achieved` is the area-weighted
// density per material (0 = not drawn), and the warning names materials under half their sources.
void report_density(const DensityPlan& plan, const scene::Scene& scene,
                    const std::vector<double>& achieved, UnwrapStats* stats);

}  // namespace vt::unwrap::detail
