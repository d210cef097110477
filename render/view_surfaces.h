// The baked scene as the view planner and the density figure see it: world-space triangles with
// their area in baked (atlas) texels and in source (base-colour) texels, grouped into charts.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "common/status.h"
#include "common/vec.h"
#include "scene/scene.h"

namespace vt::render {

struct SurfaceTriangle {
  std::array<Vec3f, 3> p;  // world space
  Vec3f normal;            // unit, from the winding
  float world_area = 0;
  float atlas_texels = 0;   // area in level-0 texels of the virtual texture
  float source_texels = 0;  // area in base-colour texels (texture transform applied); 0 = none
  uint32_t chart = 0;       // triangles joined by shared atlas-UV vertices
};

struct ViewSurfaces {
  std::vector<SurfaceTriangle> triangles;  // zero-area triangles left out
  uint32_t chart_count = 0;
  Vec3f lo, hi;  // world bounds of the triangles
  // Base-colour images whose header gave no size ("NAME: why"): their triangles count as
  // untextured for the density figure.
  std::vector<std::string> unreadable;
};

// Gathers every mesh instance of the unwrapped scene `baked` (atlas UVs in each primitive's last
// UV set, the source UV sets and materials before it, as the unwrapper writes them), for an
// atlas of atlas_width x atlas_height level-0 texels. Reads base-colour image headers only.
// kInvalidArgument when no triangle has area or a primitive lacks the atlas UV set.
Expected<ViewSurfaces> gather_view_surfaces(const scene::Scene& baked, uint32_t atlas_width,
                                            uint32_t atlas_height);

}  // namespace vt::render
