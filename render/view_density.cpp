#include "render/view_density.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <vector>

#include "bake/unwrap/texel_density.h"

namespace vt::render {
namespace {

using Clip = std::array<double, 4>;

Clip to_clip(const Mat4& m, Vec3f p) {
  Clip r{};
  for (int row = 0; row < 4; ++row)
    r[row] = double(m.m[0 * 4 + row]) * p.x + double(m.m[1 * 4 + row]) * p.y +
             double(m.m[2 * 4 + row]) * p.z + double(m.m[3 * 4 + row]);
  return r;
}

// Signed distance to the i-th plane of Vulkan's clip volume (-w <= x, y <= w, 0 <= z <= w).
double plane(const Clip& v, int i) {
  switch (i) {
    case 0:
      return v[3] + v[0];
    case 1:
      return v[3] - v[0];
    case 2:
      return v[3] + v[1];
    case 3:
      return v[3] - v[1];
    case 4:
      return v[2];
    default:
      return v[3] - v[2];
  }
}

// Pixels the triangle covers after clipping to the frustum (Sutherland-Hodgman).
double clipped_pixels(const Mat4& m, const SurfaceTriangle& t, double width, double height) {
  std::vector<Clip> poly = {to_clip(m, t.p[0]), to_clip(m, t.p[1]), to_clip(m, t.p[2])};
  std::vector<Clip> next;
  for (int i = 0; i < 6 && !poly.empty(); ++i) {
    next.clear();
    for (size_t k = 0; k < poly.size(); ++k) {
      const Clip& a = poly[k];
      const Clip& b = poly[(k + 1) % poly.size()];
      const double da = plane(a, i), db = plane(b, i);
      if (da >= 0) next.push_back(a);
      if ((da >= 0) != (db >= 0)) {
        const double s = da / (da - db);
        Clip c;
        for (int j = 0; j < 4; ++j) c[j] = a[j] + (b[j] - a[j]) * s;
        next.push_back(c);
      }
    }
    poly.swap(next);
  }
  if (poly.size() < 3) return 0;
  double area2 = 0;
  for (size_t k = 0; k < poly.size(); ++k) {
    const Clip& a = poly[k];
    const Clip& b = poly[(k + 1) % poly.size()];
    if (!(a[3] > 0) || !(b[3] > 0)) return 0;
    area2 += (a[0] / a[3]) * (b[1] / b[3]) - (b[0] / b[3]) * (a[1] / a[3]);
  }
  // NDC spans 2 units per side.
  return std::abs(area2) / 2 * (width / 2) * (height / 2);
}

}  // namespace

ViewDensity measure_view_density(const ViewSurfaces& s, const Camera& camera, uint32_t width,
                                 uint32_t height) {
  ViewDensity out;
  std::vector<unwrap::DensitySample> samples;
  double textured = 0;
  for (const SurfaceTriangle& t : s.triangles) {
    const double px = clipped_pixels(camera.view_proj, t, width, height);
    if (!(px > 0) || !std::isfinite(px)) continue;
    out.covered_pixels += px;
    if (!(t.source_texels > 0) || !(t.atlas_texels > 0)) continue;
    textured += px;
    samples.push_back({std::sqrt(double(t.atlas_texels) / t.source_texels), px});
  }
  if (textured > 0) {
    out.textured_share = textured / out.covered_pixels;
    out.density = unwrap::area_percentile(samples, 0.5);
    out.low = unwrap::area_percentile(std::move(samples), 0.1);
  }
  return out;
}

std::string check_view_density(const ViewDensity& d, double min_density) {
  if (!d.judged() || d.density >= min_density) return "";
  char line[200];
  std::snprintf(line, sizeof line,
                "density %.2f baked texels per source texel, below %.2f (the bake is %.1fx "
                "coarser than its sources here)",
                d.density, min_density, d.density > 0 ? 1.0 / d.density : 0.0);
  return line;
}

nlohmann::json to_json(const ViewDensity& d) {
  return {{"median", d.judged() ? nlohmann::json(d.density) : nlohmann::json()},
          {"p10", d.judged() ? nlohmann::json(d.low) : nlohmann::json()},
          {"textured_share", d.textured_share}};
}

}  // namespace vt::render
