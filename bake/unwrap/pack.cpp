// Chart packing: each chart's conservative texel footprint (every texel a triangle touches with
// the atlas rasteriser's footprint margin) is dropped onto a skyline in each of four quarter-turn
// rotations, keeping the spot with the lowest top, then the least wasted space under it. Quarter
// turns never mirror a chart. The gutter is exact: a placed chart's footprint dilated by `padding`
// (Chebyshev) must lie above the skyline of raw footprints, so any two charts have `padding` empty
// texels between.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <thread>

#include "bake/unwrap/atlas_raster.h"
#include "bake/unwrap/unwrap_internal.h"
#include "common/parallel.h"
#include "common/target_clones.h"

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
  auto extend = [](std::vector<int>& lo, std::vector<int>& hi, int64_t line, int64_t first,
                   int64_t last) {
    lo[size_t(line)] = std::min(lo[size_t(line)], int(first));
    hi[size_t(line)] = std::max(hi[size_t(line)], int(last));
  };
  for (const auto& t : chart.tris) {
    const Vec2d& a = chart.points[t[0]];
    const Vec2d& b = chart.points[t[1]];
    const Vec2d& c = chart.points[t[2]];
    const RasterTriangle tri({a.x, a.y, b.x, b.y, c.x, c.y});
    for_each_touched_run(
        tri, kFootprintMargin, grid, false,
        [&](int64_t j, int64_t i0, int64_t i1) { extend(f.row_min, f.row_max, j, i0, i1); });
    for_each_touched_run(tri, kFootprintMargin, grid, true, [&](int64_t i, int64_t j0, int64_t j1) {
      extend(f.col_min, f.col_max, i, j0, j1);
    });
  }
  return f;
}

// Column profiles of one rotation of a footprint.
struct Profile {
  int width = 0, height = 0;  // rotated grid
  std::vector<int> top;       // per raw column: highest occupied row + 1 (0 = empty column)
  std::vector<int> low;       // per dilated column (width + 2 * padding): lowest row - padding
  // For the search by runs (Skyline::drop_heights, Skyline::sky_under): the maximal runs of dilated
  // columns of one finite `low`, and the runs [begin, end) of raw columns with top > 0 with their
  // count and the sum of their `low[d + padding]`.
  struct LowRun {
    int begin, length, low;
  };
  std::vector<LowRun> low_runs;
  std::vector<std::pair<int, int>> top_runs;
  int64_t top_columns = 0, top_low_sum = 0;
  // Another rotation's profile is the same (a rectangle's half turn, a square's quarter turns):
  // it drops to the same places, so the first of them wins every tie and this one need not be
  // searched.
  bool repeats_earlier = false;
  bool same_shape(const Profile& o) const {
    return width == o.width && height == o.height && top == o.top && low == o.low;
  }
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
  for (int d = 0; d < int(pr.low.size());) {
    int e = d + 1;
    while (e < int(pr.low.size()) && pr.low[e] == pr.low[d]) ++e;
    if (pr.low[d] != kEmpty) pr.low_runs.push_back({d, e - d, pr.low[d]});
    d = e;
  }
  for (int d = 0; d < pr.width;) {
    if (pr.top[d] == 0) {
      ++d;
      continue;
    }
    int e = d;
    for (; e < pr.width && pr.top[e] > 0; ++e)
      ++pr.top_columns, pr.top_low_sum += pr.low[e + padding];
    pr.top_runs.emplace_back(d, e);
    d = e;
  }
  return pr;
}

// out[x] = max(out[x], max(a[x], b[x]) - low) for x in [0, n): the packer's innermost loop (90%
// of a pack of many small charts), so it gets AVX2/AVX-512 where the CPU has them.
VT_TARGET_CLONES
void raise_to_window_max(const int* a, const int* b, int low, int* out, int n) {
  for (int x = 0; x < n; ++x) out[x] = std::max(out[x], std::max(a[x], b[x]) - low);
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

// The skyline, padded by `padding` columns of "nothing" on each side (sky[-padding .. width +
// padding)), with a sparse table of its maxima (level k: the maximum of 2^k columns from each
// one, kept up to date where a placement raises the sky) and column sums for the search by runs.
class Skyline {
 public:
  Skyline(int width, int padding) : width_(width), padding_(padding) {
    const size_t n = size_t(width) + 2 * size_t(padding);
    levels_.emplace_back(n, kNothing);
    for (int x = 0; x < width; ++x) levels_[0][size_t(x + padding)] = 0;
    while ((size_t(2) << (levels_.size() - 1)) <= n) {
      const size_t half = size_t(1) << (levels_.size() - 1);
      const std::vector<int>& below = levels_.back();
      std::vector<int> level(n - 2 * half + 1);
      for (size_t i = 0; i < level.size(); ++i) level[i] = std::max(below[i], below[i + half]);
      levels_.push_back(std::move(level));
    }
  }
  int operator[](int x) const { return levels_[0][size_t(x + padding_)]; }
  void raise(int x, int height) {
    int& h = levels_[0][size_t(x + padding_)];
    h = std::max(h, height);
    dirty_begin_ = std::min(dirty_begin_, size_t(x + padding_));
    dirty_end_ = std::max(dirty_end_, size_t(x + padding_) + 1);
  }
  // Brings the maxima and sums up to date after the raises of one placement.
  void placed() {
    for (size_t k = 1; k < levels_.size() && dirty_begin_ < dirty_end_; ++k) {
      const size_t span = size_t(1) << k, half = span / 2;
      std::vector<int>& level = levels_[k];
      const std::vector<int>& below = levels_[k - 1];
      const size_t first = dirty_begin_ >= span - 1 ? dirty_begin_ - (span - 1) : 0;
      const size_t last = std::min(level.size(), dirty_end_);
      for (size_t i = first; i < last; ++i) level[i] = std::max(below[i], below[i + half]);
    }
    dirty_begin_ = SIZE_MAX, dirty_end_ = 0;
    sums_stale_ = true;
  }
  // y(x) = max(0, max over the non-empty dilated columns d of sky[x + d - padding] - low[d]) for
  // x in [0, x_max]: the height a profile drops to at x, exactly as a column-by-column scan
  // finds it, in O(runs) a position from one window maximum per run of equal `low`.
  // In int: heights stay far below 2^31 and kNothing - low far above -2^31, and the loop
  // vectorises.
  void drop_heights(const Profile& pr, int x_max, std::vector<int>& y) const {
    y.assign(size_t(x_max) + 1, 0);
    int* out = y.data();
    for (const Profile::LowRun& run : pr.low_runs) {
      size_t k = 0;
      while ((size_t(2) << k) <= size_t(run.length)) ++k;
      const int* a = levels_[k].data() + run.begin;  // padded index of sky[x + begin - padding]
      raise_to_window_max(a, a + (run.length - (1 << k)), run.low, out, x_max + 1);
    }
  }
  // Sum of sky over the columns x + d of the profile whose top > 0.
  int64_t sky_under(const Profile& pr, int x) {
    if (sums_stale_) {
      prefix_.assign(size_t(width_) + 1, 0);
      for (int i = 0; i < width_; ++i) prefix_[size_t(i) + 1] = prefix_[size_t(i)] + (*this)[i];
      sums_stale_ = false;
    }
    int64_t s = 0;
    for (const auto& [b, e] : pr.top_runs) s += prefix_[size_t(x + e)] - prefix_[size_t(x + b)];
    return s;
  }

 private:
  // Padding columns: below any drop, so that they never raise one.
  static constexpr int kNothing = std::numeric_limits<int>::min() / 4;
  int width_, padding_;
  std::vector<std::vector<int>> levels_;
  size_t dirty_begin_ = SIZE_MAX, dirty_end_ = 0;
  std::vector<int64_t> prefix_;
  bool sums_stale_ = true;
};

PackResult pack_charts(const std::vector<PackChart>& charts, int width, int padding, int threads,
                       int give_up_above) {
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
    for (int r = 0; r < 4; ++r) {
      profiles[c][r] = profile(f, g, r, padding);
      for (int q = 0; q < r && !profiles[c][r].repeats_earlier; ++q)
        profiles[c][r].repeats_earlier = profiles[c][r].same_shape(profiles[c][q]);
    }
  });

  std::vector<size_t> order(charts.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    Grid ga = grid_of(charts[a]), gb = grid_of(charts[b]);
    int ha = std::min(ga.gx, ga.gy), hb = std::min(gb.gx, gb.gy);
    if (ha != hb) return ha > hb;
    return static_cast<int64_t>(ga.gx) * ga.gy > static_cast<int64_t>(gb.gx) * gb.gy;
  });

  Skyline sky(width, padding);
  std::vector<int> drop;
  int top_all = 0;
  for (size_t c : order) {
    int64_t best_top = std::numeric_limits<int64_t>::max(), best_waste = 0;
    Placement best;
    for (int r = 0; r < 4; ++r) {
      const Profile& pr = profiles[c][r];
      if (pr.width > width || pr.repeats_earlier) continue;
      const int x_max = width - pr.width;
      // The lowest top, then the least wasted space under the chart, then the first position.
      sky.drop_heights(pr, x_max, drop);
      for (int x = 0; x <= x_max; ++x) {
        const int64_t y = drop[size_t(x)], top = y + pr.height;
        if (top > best_top) continue;
        const int64_t waste =
            pr.top_columns * (y + padding) + pr.top_low_sum - sky.sky_under(pr, x);
        if (top < best_top || waste < best_waste) {
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
      if (pr.top[d] > 0) sky.raise(best.x + d, best.y + pr.top[d]);
    sky.placed();
    top_all = std::max(top_all, best.y + pr.height);
    result.placements[c] = best;
    if (top_all > give_up_above) break;  // the rest cannot bring the top down
  }
  result.height = top_all;
  return result;
}

}  // namespace vt::unwrap::detail
