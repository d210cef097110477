// Chart packing: each chart's conservative texel footprint (every texel a triangle touches with
// the atlas rasteriser's footprint margin) is dropped onto a skyline in each of four quarter-turn
// rotations, keeping the spot with the lowest top, then the least wasted space under it. Quarter
// turns never mirror a chart. The gutter is exact: a placed chart's footprint dilated by `padding`
// (Chebyshev) must lie above the skyline of raw footprints, so any two charts have `padding` empty
// texels between.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <thread>

#include "bake/unwrap/atlas_raster.h"
#include "bake/unwrap/unwrap_internal.h"
#include "common/parallel.h"

namespace vt::unwrap::detail {
namespace {

struct Grid {
  int gx = 1, gy = 1;
};

Grid grid_of(const PackChart& c) {
  return {std::max(1, static_cast<int>(std::ceil(c.width))),
          std::max(1, static_cast<int>(std::ceil(c.height)))};
}

// A chart's conservative footprint (every texel a triangle touches with the footprint margin)
// as the extent of each column and each row of its unrotated grid: all a profile reads, in
// memory linear in the chart's sides (a cell bitmap was quadratic: a ground chart of 20K x 20K
// texels took 400 MB at a 32K atlas, two of them at once on two threads).
struct Footprint {
  std::vector<int> col_min, col_max;  // per column i: lowest and highest occupied row j
  std::vector<int> row_min, row_max;  // per row j: lowest and highest occupied column i
};

constexpr int kEmpty = std::numeric_limits<int>::max();

Footprint footprint(const PackChart& chart, const Grid& g) {
  Footprint f;
  f.col_min.assign(size_t(g.gx), kEmpty), f.col_max.assign(size_t(g.gx), -1);
  f.row_min.assign(size_t(g.gy), kEmpty), f.row_max.assign(size_t(g.gy), -1);
  const TexelRect grid = {0, 0, g.gx - 1, g.gy - 1};
  for (const auto& t : chart.tris) {
    const Vec2d& a = chart.points[t[0]];
    const Vec2d& b = chart.points[t[1]];
    const Vec2d& c = chart.points[t[2]];
    const RasterTriangle tri({a.x, a.y, b.x, b.y, c.x, c.y});
    for_each_touched_texel(tri, kFootprintMargin, grid, [&](int64_t i64, int64_t j64) {
      const int i = int(i64), j = int(j64);
      f.col_min[size_t(i)] = std::min(f.col_min[size_t(i)], j);
      f.col_max[size_t(i)] = std::max(f.col_max[size_t(i)], j);
      f.row_min[size_t(j)] = std::min(f.row_min[size_t(j)], i);
      f.row_max[size_t(j)] = std::max(f.row_max[size_t(j)], i);
    });
  }
  return f;
}

// Column profiles of one rotation of a footprint.
struct Profile {
  int width = 0, height = 0;  // rotated grid
  std::vector<int> top;       // per raw column: highest occupied row + 1 (0 = empty column)
  std::vector<int> low;       // per dilated column (width + 2 * padding): lowest row - padding
  int min_low = 0;
};

// Rotated cell (x, y) of grid cell (i, j), matching place_point: rotation 0 (x, y) = (i, j),
// 1 (gy-1-j, i), 2 (gx-1-i, gy-1-j), 3 (j, gx-1-i). A rotated column is then one grid column
// (rotations 0, 2) or row (1, 3), and its lowest and highest y come from that one's extent.
Profile profile(const Footprint& f, const Grid& g, int rotation, int padding) {
  Profile pr;
  const bool swap = rotation & 1;
  pr.width = swap ? g.gy : g.gx;
  pr.height = swap ? g.gx : g.gy;
  std::vector<int> bottom(pr.width, kEmpty);
  pr.top.assign(pr.width, 0);
  for (int x = 0; x < pr.width; ++x) {
    const bool flip = rotation == 1 || rotation == 2;  // x counts the grid's lines backwards
    const size_t line = size_t(flip ? pr.width - 1 - x : x);
    const int lo = swap ? f.row_min[line] : f.col_min[line];
    const int hi = swap ? f.row_max[line] : f.col_max[line];
    if (hi < 0) continue;  // empty
    // Rotations 2 and 3 count y backwards from the grid's other side.
    const bool back = rotation >= 2;
    bottom[x] = back ? pr.height - 1 - hi : lo;
    pr.top[x] = (back ? pr.height - 1 - lo : hi) + 1;
  }
  pr.low.assign(pr.width + 2 * padding, kEmpty);
  for (int x = 0; x < pr.width; ++x) {
    if (bottom[x] == kEmpty) continue;
    for (int d = 0; d <= 2 * padding; ++d)
      pr.low[x + d] = std::min(pr.low[x + d], bottom[x] - padding);
  }
  pr.min_low = kEmpty;
  for (int v : pr.low) pr.min_low = std::min(pr.min_low, v);
  return pr;
}

}  // namespace

Vec2d place_point(const PackChart& chart, const Placement& pl, const Vec2d& p) {
  Grid g = grid_of(chart);
  Vec2d r;
  switch (pl.rotation) {
    case 0:
      r = p;
      break;
    case 1:
      r = {g.gy - p.y, p.x};
      break;
    case 2:
      r = {g.gx - p.x, g.gy - p.y};
      break;
    default:
      r = {p.y, g.gx - p.x};
      break;
  }
  return {r.x + pl.x, r.y + pl.y};
}

PackResult pack_charts(const std::vector<PackChart>& charts, int width, int padding, int threads) {
  PackResult result;
  result.placements.resize(charts.size());
  result.width = width;
  // Profiles are independent per chart: build them in parallel, place serially (deterministic).
  std::vector<std::array<Profile, 4>> profiles(charts.size());
  // Small chart sets are not worth a thread each.
  const int workers = std::min(thread_count(threads), int(charts.size() / 64 + 1));
  parallel_for(charts.size(), workers, [&](size_t c) {
    Grid g = grid_of(charts[c]);
    const Footprint f = footprint(charts[c], g);
    for (int r = 0; r < 4; ++r) profiles[c][r] = profile(f, g, r, padding);
  });

  std::vector<size_t> order(charts.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    Grid ga = grid_of(charts[a]), gb = grid_of(charts[b]);
    int ha = std::min(ga.gx, ga.gy), hb = std::min(gb.gx, gb.gy);
    if (ha != hb) return ha > hb;
    return static_cast<int64_t>(ga.gx) * ga.gy > static_cast<int64_t>(gb.gx) * gb.gy;
  });

  std::vector<int> sky(width, 0);
  int top_all = 0;
  for (size_t c : order) {
    int64_t best_top = std::numeric_limits<int64_t>::max(), best_waste = 0;
    Placement best;
    for (int r = 0; r < 4; ++r) {
      const Profile& pr = profiles[c][r];
      if (pr.width > width) continue;
      int x_max = width - pr.width;
      for (int x = 0; x <= std::max(0, x_max); ++x) {
        int64_t y = 0;
        bool pruned = false;
        for (int d = 0; d < static_cast<int>(pr.low.size()); ++d) {
          int ax = x + d - padding;
          if (ax < 0 || ax >= width || pr.low[d] == kEmpty) continue;
          y = std::max<int64_t>(y, sky[ax] - pr.low[d]);
          if (y + pr.height > best_top) {
            pruned = true;
            break;
          }
        }
        if (pruned) continue;
        int64_t top = y + pr.height;
        int64_t waste = 0;
        for (int d = 0; d < pr.width && x + d < width; ++d)
          if (pr.top[d] > 0) waste += y + pr.low[d + padding] + padding - sky[x + d];
        if (top < best_top || (top == best_top && waste < best_waste)) {
          best_top = top;
          best_waste = waste;
          best = {r, x, static_cast<int>(y)};
        }
      }
    }
    if (best_top == std::numeric_limits<int64_t>::max()) {
      // No rotation fits the width: report it; the caller picks a wider atlas or lower density.
      result.overflow = true;
      best = {0, 0, top_all + padding};
    }
    const Profile& pr = profiles[c][best.rotation];
    for (int d = 0; d < pr.width && best.x + d < width; ++d)
      if (pr.top[d] > 0) sky[best.x + d] = std::max(sky[best.x + d], best.y + pr.top[d]);
    top_all = std::max(top_all, best.y + pr.height);
    result.placements[c] = best;
  }
  result.height = top_all;
  return result;
}

}  // namespace vt::unwrap::detail
