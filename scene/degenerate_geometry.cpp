// Warnings for geometry that loads but bakes to nothing: zero-area triangles get no texels,
// and a primitive made only of them gets none at all (its material is silently absent).
#include <algorithm>
#include <cmath>
#include <string>

#include "scene/scene_io_util.h"

namespace vt::scene::detail {
namespace {

// Below this fraction of the primitive's bounding-box diagonal squared a triangle's area is
// zero for the atlas: at any atlas size a texel is far larger.
constexpr double kZeroAreaFraction = 1e-12;

double diagonal_squared(const Primitive& p) {
  std::array<double, 3> lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY};
  for (const Vec3& v : p.positions)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], double(v[k]));
      hi[k] = std::max(hi[k], double(v[k]));
    }
  double d = 0;
  for (int k = 0; k < 3; ++k)
    if (hi[k] >= lo[k]) d += (hi[k] - lo[k]) * (hi[k] - lo[k]);
  return d;
}

// Triangles of `p` with zero area; non-finite or out-of-range ones are validate_geometry's.
size_t zero_area_triangles(const Primitive& p) {
  const double floor = kZeroAreaFraction * diagonal_squared(p);
  size_t zero = 0;
  for (size_t t = 0; t + 2 < p.indices.size(); t += 3) {
    uint32_t i0 = p.indices[t], i1 = p.indices[t + 1], i2 = p.indices[t + 2];
    if (std::max({i0, i1, i2}) >= p.positions.size()) continue;
    const Vec3 &a = p.positions[i0], &b = p.positions[i1], &c = p.positions[i2];
    double e1[3], e2[3];
    for (int k = 0; k < 3; ++k) {
      e1[k] = double(b[k]) - a[k];
      e2[k] = double(c[k]) - a[k];
    }
    double x = e1[1] * e2[2] - e1[2] * e2[1], y = e1[2] * e2[0] - e1[0] * e2[2],
           z = e1[0] * e2[1] - e1[1] * e2[0];
    double area = 0.5 * std::sqrt(x * x + y * y + z * z);
    if (std::isfinite(area) && area <= floor) ++zero;
  }
  return zero;
}

}  // namespace

void warn_about_degenerate_geometry(Scene* scene) {
  const std::string file = scene->source_path.empty() ? "scene" : scene->source_path;
  size_t zero = 0, total = 0, empty_prims = 0;
  std::string first_zero, empty_list;
  for (size_t mi = 0; mi < scene->meshes.size(); ++mi) {
    const Mesh& mesh = scene->meshes[mi];
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const Primitive& p = mesh.primitives[pi];
      const size_t n = zero_area_triangles(p);
      if (n == 0) continue;
      const std::string where = "mesh '" + (mesh.name.empty() ? std::to_string(mi) : mesh.name) +
                                "' primitive " + std::to_string(pi);
      zero += n;
      if (first_zero.empty()) first_zero = where;
      if (n == p.triangle_count()) {
        if (++empty_prims <= 5) empty_list += (empty_list.empty() ? "" : ", ") + where;
      }
    }
  }
  for (const Mesh& mesh : scene->meshes)
    for (const Primitive& p : mesh.primitives) total += p.triangle_count();
  if (zero == 0) return;
  scene->warnings.push_back(file + ": " + std::to_string(zero) + " of " + std::to_string(total) +
                            " triangles have zero area and get no texels (first in " + first_zero +
                            ")");
  if (empty_prims > 0)
    scene->warnings.push_back(
        file + ": " + std::to_string(empty_prims) +
        (empty_prims == 1 ? " primitive has" : " primitives have") +
        " no area at all and will not appear in the bake: " + empty_list +
        (empty_prims > 5 ? " and " + std::to_string(empty_prims - 5) + " more" : ""));
}

}  // namespace vt::scene::detail
