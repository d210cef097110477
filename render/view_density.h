// The "density" figure of a view: how many baked texels per source texel the surfaces it sees
// get, so a bake coarser than its sources where a view looks fails that view. CPU only:
// triangles clipped to the view frustum, weighted by the pixels they cover (no occlusion).
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "render/camera.h"
#include "render/view_surfaces.h"

namespace vt::render {

struct ViewDensity {
  // Linear baked texels per source texel, sqrt(atlas texel area / base-colour texel area) per
  // triangle, the pixel-weighted median over the textured triangles in view (0.5 = the bake is
  // 2x coarser than its sources). 0 when no textured triangle is in view (not judged).
  double density = 0;
  double low = 0;             // the pixel-weighted 10th percentile
  double textured_share = 0;  // of the covered pixels (frustum-clipped area, no occlusion)
  double covered_pixels = 0;  // projected area in view, overlaps counted (no occlusion)
  bool judged() const { return textured_share > 0; }
};

// The figure for one camera and a width x height render.
ViewDensity measure_view_density(const ViewSurfaces& surfaces, const Camera& camera, uint32_t width,
                                 uint32_t height);

// Why a view fails its density bound (one line), or "" when it passes or is not judged.
std::string check_view_density(const ViewDensity& density, double min_density);

// {"median" (the density), "p10" (low), "textured_share"}: median and p10 null when not judged.
nlohmann::json to_json(const ViewDensity& density);

}  // namespace vt::render
