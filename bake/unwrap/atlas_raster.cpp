// The atlas rasteriser (see atlas_raster.h).
#include "bake/unwrap/atlas_raster.h"

#include <limits>
#include <utility>

namespace vt::unwrap {

RasterTriangle::RasterTriangle(const std::array<double, 6>& p) {
  for (int k = 0; k < 3; ++k) x[k] = p[2 * k], y[k] = p[2 * k + 1];
  double a2 = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
  if (a2 < 0) {
    std::swap(x[1], x[2]);
    std::swap(y[1], y[2]);
    std::swap(order[1], order[2]);
    a2 = -a2;
  }
  area2 = a2;
  for (int k = 0; k < 3; ++k) {
    int i = (k + 1) % 3, j = (k + 2) % 3;  // edge i -> j
    bool forward = std::make_pair(x[i], y[i]) < std::make_pair(x[j], y[j]);
    int a = forward ? i : j, b = forward ? j : i;
    Edge& g = e[k];
    g.ax = x[a], g.ay = y[a], g.dx = x[b] - x[a], g.dy = y[b] - y[a];
    g.sign = forward ? 1.0 : -1.0;
    double ex = x[j] - x[i], ey = y[j] - y[i];
    g.include_zero = ey > 0 || (ey == 0 && ex < 0);
  }
}

TexelRect RasterTriangle::bounds(double margin) const {
  if (empty()) return {};
  double minx = std::min({x[0], x[1], x[2]}), maxx = std::max({x[0], x[1], x[2]});
  double miny = std::min({y[0], y[1], y[2]}), maxy = std::max({y[0], y[1], y[2]});
  // Open squares: texel i meets (min, max) when i < max and i + 1 > min.
  return {int64_t(std::floor(minx - margin)), int64_t(std::floor(miny - margin)),
          int64_t(std::ceil(maxx + margin)) - 1, int64_t(std::ceil(maxy + margin)) - 1};
}

void RasterTriangle::closest_barycentrics(double px, double py, double lambda[3]) const {
  double inside[3];
  bool in = true;
  for (int k = 0; k < 3; ++k) {
    inside[k] = edge(k, px, py) / area2;
    if (inside[k] < 0) in = false;
  }
  if (in) {
    for (int k = 0; k < 3; ++k) lambda[k] = inside[k];
    return;
  }
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    int i = (k + 1) % 3, j = (k + 2) % 3;
    double ex = x[j] - x[i], ey = y[j] - y[i];
    double len2 = ex * ex + ey * ey;
    double s = len2 > 0 ? ((px - x[i]) * ex + (py - y[i]) * ey) / len2 : 0.0;
    s = std::clamp(s, 0.0, 1.0);
    double qx = x[i] + s * ex - px, qy = y[i] + s * ey - py;
    double d = qx * qx + qy * qy;
    if (d < best) {
      best = d;
      lambda[k] = 0, lambda[i] = 1 - s, lambda[j] = s;
    }
  }
}

double RasterTriangle::distance2_to(double px, double py) const {
  double l[3];
  closest_barycentrics(px, py, l);
  double qx = l[0] * x[0] + l[1] * x[1] + l[2] * x[2] - px;
  double qy = l[0] * y[0] + l[1] * y[1] + l[2] * y[2] - py;
  return qx * qx + qy * qy;
}

std::vector<std::vector<uint32_t>> bin_by_rows(const std::vector<RasterTriangle>& tris,
                                               int64_t height, int64_t band_rows, double margin) {
  const int64_t bands = height > 0 ? (height + band_rows - 1) / band_rows : 0;
  std::vector<std::vector<uint32_t>> bins(static_cast<size_t>(bands));
  for (uint32_t t = 0; t < tris.size(); ++t) {
    const TexelRect r = tris[t].bounds(margin);
    const int64_t ya = std::max<int64_t>(0, r.y0), yb = std::min<int64_t>(height - 1, r.y1);
    if (yb < ya) continue;
    for (int64_t b = ya / band_rows; b <= yb / band_rows; ++b) bins[size_t(b)].push_back(t);
  }
  return bins;
}

}  // namespace vt::unwrap
