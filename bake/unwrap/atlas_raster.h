// The one atlas rasteriser: which texels and which sample points a triangle in atlas texel
// space owns. Packing (chart footprints), the atlas check (the no-overlap and gutter proof) and
// material transfer (texel values) all use it, so the check proves the rule transfer relies on.
//
// Texel (x, y) is the square [x, x + 1) x [y, y + 1), its centre at (x + 0.5, y + 0.5).
//
// Fill rule (samples): a point belongs to a triangle when every edge function is positive, or
// zero on a top-left edge (an edge that goes down, or left when horizontal, in the triangle's
// positive orientation). Each edge is evaluated from its lexicographically smaller endpoint, so
// two triangles sharing an edge get exactly opposite values and a point on it belongs to one.
//
// Touch (conservative): a triangle touches a texel when it meets the texel's open square grown
// by `margin` texels on every side. Margin 0 is what transfer covers and the check proves;
// packing reserves footprints with kFootprintMargin.
//
// Zero-area and non-finite triangles own no sample and touch no texel.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace vt::unwrap {

// The margin of packing footprints, in texels. Packing works on double chart coordinates; atlas
// UVs are rounded to float afterwards (up to ~1e-3 texel in a 16k atlas) and that rounding must
// never move a triangle into a texel its footprint did not reserve.
inline constexpr double kFootprintMargin = 1.0 / 32;

// Texels x0..x1, y0..y1 (inclusive); empty when x1 < x0 or y1 < y0.
struct TexelRect {
  int64_t x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  bool empty() const { return x1 < x0 || y1 < y0; }
  TexelRect clipped(const TexelRect& r) const {
    return {std::max(x0, r.x0), std::max(y0, r.y0), std::min(x1, r.x1), std::min(y1, r.y1)};
  }
};

// A triangle prepared for rasterisation: corners reordered to positive orientation (x right,
// y down: counter-clockwise as seen with y up), edges in canonical form.
struct RasterTriangle {
  double x[3] = {}, y[3] = {};
  double area2 = 0;  // twice the area
  struct Edge {
    double ax, ay, dx, dy, sign;
    bool include_zero;           // top-left edge
  } e[3] = {};                   // e[k] is the edge opposite corner k (from corner k+1 to k+2)
  uint8_t order[3] = {0, 1, 2};  // input corner of each reordered corner

  RasterTriangle() = default;
  // Corners (x0, y0, x1, y1, x2, y2) in atlas texel coordinates.
  explicit RasterTriangle(const std::array<double, 6>& corners);

  // Zero area or not finite: owns nothing.
  bool empty() const { return !(area2 > 0) || !std::isfinite(area2); }
  // Edge k's function at p: positive inside, exactly opposite in a neighbour sharing the edge.
  double edge(int k, double px, double py) const {
    const Edge& g = e[k];
    return g.sign * (g.dx * (py - g.ay) - g.dy * (px - g.ax));
  }
  // True when p belongs to the triangle by the fill rule; then lambda holds its barycentrics
  // (of the reordered corners).
  bool contains(double px, double py, double lambda[3]) const {
    for (int k = 0; k < 3; ++k) {
      double v = edge(k, px, py);
      if (v < 0 || (v == 0 && !e[k].include_zero)) return false;
      lambda[k] = v;
    }
    for (int k = 0; k < 3; ++k) lambda[k] /= area2;
    return true;
  }
  // Texels whose open square grown by `margin` meets the bounding box (nothing when empty()).
  TexelRect bounds(double margin) const;
  // Barycentrics of the closest point of the closed triangle to p.
  void closest_barycentrics(double px, double py, double lambda[3]) const;
  // Squared distance from p to the closed triangle.
  double distance2_to(double px, double py) const;
};

// Calls fn(x, y) for every texel of `clip` the triangle touches with `margin`, row by row.
template <class Fn>
void for_each_touched_texel(const RasterTriangle& t, double margin, const TexelRect& clip,
                            Fn&& fn) {
  if (t.empty()) return;
  const TexelRect r = t.bounds(margin).clipped(clip);
  // The largest value of an edge function over a square of half side h centred at c is its
  // value at c plus h times the sum of its gradient's magnitudes.
  const double half = 0.5 + margin;
  double reach[3];
  for (int k = 0; k < 3; ++k) reach[k] = half * (std::abs(t.e[k].dx) + std::abs(t.e[k].dy));
  for (int64_t y = r.y0; y <= r.y1; ++y)
    for (int64_t x = r.x0; x <= r.x1; ++x) {
      const double cx = x + 0.5, cy = y + 0.5;
      bool touch = true;
      for (int k = 0; k < 3 && touch; ++k) touch = t.edge(k, cx, cy) + reach[k] > 0;
      if (touch) fn(x, y);
    }
}

// The same texels as for_each_touched_texel, as runs: fn(line, first, last) for each row
// (by_columns false: line = y, texels x = first..last) or each column (true: line = x, texels
// y = first..last) that has any. Along one line each edge test is monotone, in floating point
// too (the edge function is affine in the moving coordinate, evaluated the same way), so a line's
// touched texels are one run, found by bisection: O(lines x log) per triangle instead of O(area).
template <class Fn>
void for_each_touched_run(const RasterTriangle& t, double margin, const TexelRect& clip,
                          bool by_columns, Fn&& fn) {
  if (t.empty()) return;
  const TexelRect r = t.bounds(margin).clipped(clip);
  if (r.empty()) return;
  const double half = 0.5 + margin;
  double reach[3];
  int rises[3];  // along the line, edge k's value rises (1), falls (-1) or stays (0)
  for (int k = 0; k < 3; ++k) {
    reach[k] = half * (std::abs(t.e[k].dx) + std::abs(t.e[k].dy));
    const double slope = by_columns ? t.e[k].sign * t.e[k].dx : -t.e[k].sign * t.e[k].dy;
    rises[k] = slope > 0 ? 1 : slope < 0 ? -1 : 0;
  }
  const int64_t l0 = by_columns ? r.x0 : r.y0, l1 = by_columns ? r.x1 : r.y1;
  const int64_t a0 = by_columns ? r.y0 : r.x0, a1 = by_columns ? r.y1 : r.x1;
  for (int64_t line = l0; line <= l1; ++line) {
    // Whether every edge of direction `dir` passes at position a of the line.
    auto pass = [&](int dir, int64_t a) {
      const double cx = (by_columns ? line : a) + 0.5, cy = (by_columns ? a : line) + 0.5;
      for (int k = 0; k < 3; ++k)
        if (rises[k] == dir && !(t.edge(k, cx, cy) + reach[k] > 0)) return false;
      return true;
    };
    if (!pass(0, a0)) continue;
    int64_t lo = a0, hi = a1 + 1;  // the first position where the rising edges pass
    while (lo < hi) {
      const int64_t mid = lo + (hi - lo) / 2;
      if (pass(1, mid))
        hi = mid;
      else
        lo = mid + 1;
    }
    const int64_t first = lo;
    lo = a0 - 1, hi = a1;  // the last position where the falling edges pass
    while (lo < hi) {
      const int64_t mid = lo + (hi - lo + 1) / 2;
      if (pass(-1, mid))
        lo = mid;
      else
        hi = mid - 1;
    }
    if (first <= lo) fn(line, first, lo);
  }
}

// For each band of `band_rows` rows of an atlas `height` rows high, the triangles (indices, in
// order) that may touch a texel of it with `margin`.
std::vector<std::vector<uint32_t>> bin_by_rows(const std::vector<RasterTriangle>& tris,
                                               int64_t height, int64_t band_rows,
                                               double margin = 0);

}  // namespace vt::unwrap
