#include "bake/build_tasks.h"

#include <algorithm>

#include "bake/level_source.h"

namespace vt {

bool level_needs_whole(const BuildPlan& plan, uint32_t layer, uint32_t level) {
  const LayerPlan& lp = plan.layers[layer];
  const bool alpha_coverage = plan.options.alpha_coverage_reference > 0 && lp.alpha >= 0;
  return level > 0 && (lp.level0->coverage() != nullptr || alpha_coverage);
}

std::vector<BuildTask> make_build_tasks(const BuildPlan& plan) {
  const PageGeometry& g = plan.desc.geometry;
  const uint32_t P = g.payload, half = P / 2, m = plan.margin;
  std::vector<BuildTask> tasks;
  for (uint32_t li = 0; li < plan.layers.size(); ++li) {
    if (plan.layers[li].copy_previous) continue;  // its pages are the previous file's
    std::vector<uint32_t> previous;               // band tasks of the level before, by row
    for (uint32_t l = 0; l < g.level_count(); ++l) {
      std::vector<uint32_t> bands;
      const bool needs_whole = level_needs_whole(plan, li, l);
      uint32_t whole = 0;
      if (needs_whole) {
        whole = uint32_t(tasks.size());
        tasks.push_back({BuildTask::Kind::kLevel, li, l, 0, previous});
      }
      const int64_t h = g.level_height(l);
      for (uint32_t r = 0; r < g.pages_y(l); ++r) {
        BuildTask t{BuildTask::Kind::kBand, li, l, r, {}};
        if (needs_whole) {
          t.deps = {whole};
        } else if (l > 0) {
          // The rows this band reads, addressed as the row window reads them, and the bands
          // of the level before that wrote them.
          for (int64_t y = int64_t(r) * P - m; y < int64_t(r) * P + P + m; ++y) {
            const int64_t row = address_texel(y, h, plan.options.address);
            t.deps.push_back(previous[std::min<size_t>(size_t(row / half), previous.size() - 1)]);
          }
          std::sort(t.deps.begin(), t.deps.end());
          t.deps.erase(std::unique(t.deps.begin(), t.deps.end()), t.deps.end());
        }
        bands.push_back(uint32_t(tasks.size()));
        tasks.push_back(std::move(t));
      }
      previous = std::move(bands);
    }
  }
  return tasks;
}

}  // namespace vt
