// Exact texel-space checks of an atlas. Texel-centre coverage uses a fixed-point grid (1/256
// texel) with a top-left style tie rule, so two triangles that share an edge never both cover a
// centre and a covered-twice centre is a real overlap. Chart overlap is conservative: a texel
// counts if any part of it is touched by triangles of two different charts.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "bake/unwrap/unwrap.h"
#include "bake/unwrap/unwrap_internal.h"

namespace vt::unwrap {
namespace {

constexpr int kSubBits = 8;
constexpr int64_t kOne = int64_t{1} << kSubBits;
constexpr int kBandRows = 256;

struct Fixed {
  int64_t x, y;
};

bool triangle_touches_texel(const detail::P2& a, const detail::P2& b, const detail::P2& c, int i,
                            int j) {
  // Separating axes: the box axes (done by the caller's bounds) and the three edge normals.
  const detail::P2* v[3] = {&a, &b, &c};
  const double eps = 1e-6;
  for (int e = 0; e < 3; ++e) {
    const auto& p = *v[e];
    const auto& q = *v[(e + 1) % 3];
    const auto& r = *v[(e + 2) % 3];
    double nx = q[1] - p[1], ny = p[0] - q[0];
    double side = nx * (r[0] - p[0]) + ny * (r[1] - p[1]);
    if (side == 0) continue;
    double best = side > 0 ? -1e300 : 1e300;
    for (int k = 0; k < 4; ++k) {
      double x = i + ((k & 1) ? 1 + eps : -eps), y = j + ((k & 2) ? 1 + eps : -eps);
      double s = nx * (x - p[0]) + ny * (y - p[1]);
      best = side > 0 ? std::max(best, s) : std::min(best, s);
    }
    if (side > 0 ? best < 0 : best > 0) return false;
  }
  return true;
}

}  // namespace

AtlasCheck check_atlas(const std::vector<AtlasTriangle>& tris, int width, int height) {
  AtlasCheck out;
  if (width <= 0 || height <= 0) return out;
  int bands = (height + kBandRows - 1) / kBandRows;
  // Bucket triangles by the bands their bounds touch.
  std::vector<std::vector<uint32_t>> in_band(bands);
  for (size_t t = 0; t < tris.size(); ++t) {
    const auto& uv = tris[t].uv;
    double cross = (uv[2] - uv[0]) * (uv[5] - uv[1]) - (uv[3] - uv[1]) * (uv[4] - uv[0]);
    if (cross > 0) ++out.flipped_triangles;  // y down: front faces appear counter-clockwise
    double y0 = std::min({uv[1], uv[3], uv[5]}), y1 = std::max({uv[1], uv[3], uv[5]});
    if (!std::isfinite(y0) || !std::isfinite(y1)) continue;
    int b0 = std::clamp(static_cast<int>(std::floor(y0 - 1)) / kBandRows, 0, bands - 1);
    int b1 = std::clamp(static_cast<int>(std::floor(y1 + 1)) / kBandRows, 0, bands - 1);
    for (int b = b0; b <= b1; ++b) in_band[b].push_back(static_cast<uint32_t>(t));
  }
  std::vector<int32_t> owner(static_cast<size_t>(width) * kBandRows);
  std::vector<int32_t> chart_owner(owner.size());
  std::vector<char> overlap_texel(owner.size());
  std::vector<char> tri_overlaps(tris.size(), 0);
  for (int b = 0; b < bands; ++b) {
    int row0 = b * kBandRows, row1 = std::min(height, row0 + kBandRows);
    std::fill(owner.begin(), owner.end(), -1);
    std::fill(chart_owner.begin(), chart_owner.end(), -1);
    std::fill(overlap_texel.begin(), overlap_texel.end(), 0);
    for (uint32_t t : in_band[b]) {
      const auto& uv = tris[t].uv;
      detail::P2 a = {uv[0], uv[1]}, bb = {uv[2], uv[3]}, c = {uv[4], uv[5]};
      int i0 = std::max(0, static_cast<int>(std::floor(std::min({a[0], bb[0], c[0]}))));
      int i1 = std::min(width - 1, static_cast<int>(std::floor(std::max({a[0], bb[0], c[0]}))));
      int j0 = std::max(row0, static_cast<int>(std::floor(std::min({a[1], bb[1], c[1]}))));
      int j1 = std::min(row1 - 1, static_cast<int>(std::floor(std::max({a[1], bb[1], c[1]}))));
      // Fixed-point corners, ordered so that the edge functions are positive inside.
      Fixed f[3];
      for (int k = 0; k < 3; ++k)
        f[k] = {std::llround(uv[2 * k] * kOne), std::llround(uv[2 * k + 1] * kOne)};
      int64_t area = (f[1].x - f[0].x) * (f[2].y - f[0].y) - (f[1].y - f[0].y) * (f[2].x - f[0].x);
      if (area < 0) std::swap(f[1], f[2]);
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
          size_t cell = static_cast<size_t>(j - row0) * width + i;
          // Conservative chart ownership.
          if (triangle_touches_texel(a, bb, c, i, j)) {
            int32_t& co = chart_owner[cell];
            if (co < 0)
              co = tris[t].chart;
            else if (co != tris[t].chart)
              overlap_texel[cell] = 1;
          }
          if (area == 0) continue;
          int64_t px = i * kOne + kOne / 2, py = j * kOne + kOne / 2;
          bool inside = true;
          for (int e = 0; e < 3 && inside; ++e) {
            const Fixed& p = f[e];
            const Fixed& q = f[(e + 1) % 3];
            int64_t dx = q.x - p.x, dy = q.y - p.y;
            int64_t ef = dx * (py - p.y) - dy * (px - p.x);
            if (ef < 0) inside = false;
            // A centre exactly on an edge belongs to one side only: the same edge seen from
            // the neighbouring triangle runs the other way and fails this test.
            else if (ef == 0 && !(dy > 0 || (dy == 0 && dx < 0)))
              inside = false;
          }
          if (!inside) continue;
          int32_t& o = owner[cell];
          if (o < 0) {
            o = static_cast<int32_t>(t);
          } else {
            tri_overlaps[t] = 1;
            tri_overlaps[o] = 1;
          }
        }
    }
    for (int j = row0; j < row1; ++j)
      for (int i = 0; i < width; ++i) {
        size_t cell = static_cast<size_t>(j - row0) * width + i;
        out.covered_texels += owner[cell] >= 0;
        out.overlapping_texels += overlap_texel[cell];
      }
  }
  for (char o : tri_overlaps) out.overlapping_triangles += o;
  out.utilisation = static_cast<double>(out.covered_texels) / (static_cast<double>(width) * height);
  return out;
}

}  // namespace vt::unwrap
