// The second step of a build: the plan cut into tasks. A band task takes the rows of one page
// row of one level of one layer (with the filter margin), and gives that row's encoded pages and
// its share of the next level's rows. A level task completes a level that needs all of its
// rows at once (pull-push dilation of a coverage layer, coverage-preserving alpha). Tasks are
// deterministic: a band's key, hash(the layer's task seed, the task, its input rows), names its
// output, so that update mode and sharding over a build farm can tell what must be redone.
// Dependencies are explicit; build_pages runs the tasks in list order, which respects them.
#pragma once

#include <cstdint>
#include <vector>

#include "bake/build_plan.h"

namespace vt {

struct BuildTask {
  enum class Kind : uint8_t {
    kBand = 0,   // pages of page row `row` of `level`, and its rows of level + 1
    kLevel = 1,  // `level` complete: dilate it, fix its alpha scale (row unused)
  };
  Kind kind = Kind::kBand;
  uint32_t layer = 0, level = 0, row = 0;
  std::vector<uint32_t> deps;  // indices of the tasks whose output this one reads
};

// Every task of the plan (none for a layer that copies the previous file's, update mode), in an
// order that respects the dependencies: layers in order, levels
// fine to coarse, rows top to bottom. Level-0 bands read the source and depend on nothing
// (a streamed source is read top to bottom, so they run in order).
std::vector<BuildTask> make_build_tasks(const BuildPlan& plan);

// Whether level `level` (>= 1) of `layer` needs all of its rows before any band reads it.
bool level_needs_whole(const BuildPlan& plan, uint32_t layer, uint32_t level);

}  // namespace vt
