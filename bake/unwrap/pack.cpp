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

// Footprint cells (i, j) of a chart in its unrotated grid: every texel a triangle touches with
// the footprint margin.
std::vector<char> footprint(const PackChart& chart, const Grid& g) {
  std::vector<char> cells(static_cast<size_t>(g.gx) * g.gy, 0);
  const TexelRect grid = {0, 0, g.gx - 1, g.gy - 1};
  for (const auto& t : chart.tris) {
    const Vec2d& a = chart.points[t[0]];
    const Vec2d& b = chart.points[t[1]];
    const Vec2d& c = chart.points[t[2]];
    const RasterTriangle tri({a.x, a.y, b.x, b.y, c.x, c.y});
    for_each_touched_texel(tri, kFootprintMargin, grid, [&](int64_t i, int64_t j) {
      cells[static_cast<size_t>(j) * g.gx + static_cast<size_t>(i)] = 1;
    });
  }
  return cells;
}

// Column profiles of one rotation of a footprint.
struct Profile {
  int width = 0, height = 0;  // rotated grid
  std::vector<int> top;       // per raw column: highest occupied row + 1 (0 = empty column)
  std::vector<int> low;       // per dilated column (width + 2 * padding): lowest row - padding
  int min_low = 0;
};

constexpr int kEmpty = std::numeric_limits<int>::max();

Profile profile(const std::vector<char>& cells, const Grid& g, int rotation, int padding) {
  Profile pr;
  bool swap = rotation & 1;
  pr.width = swap ? g.gy : g.gx;
  pr.height = swap ? g.gx : g.gy;
  std::vector<int> bottom(pr.width, kEmpty);
  pr.top.assign(pr.width, 0);
  for (int j = 0; j < g.gy; ++j)
    for (int i = 0; i < g.gx; ++i) {
      if (!cells[static_cast<size_t>(j) * g.gx + i]) continue;
      int x, y;  // rotated cell, matching place_point
      switch (rotation) {
        case 0:
          x = i, y = j;
          break;
        case 1:
          x = g.gy - 1 - j, y = i;
          break;
        case 2:
          x = g.gx - 1 - i, y = g.gy - 1 - j;
          break;
        default:
          x = j, y = g.gx - 1 - i;
          break;
      }
      bottom[x] = std::min(bottom[x], y);
      pr.top[x] = std::max(pr.top[x], y + 1);
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
    auto cells = footprint(charts[c], g);
    for (int r = 0; r < 4; ++r) profiles[c][r] = profile(cells, g, r, padding);
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
