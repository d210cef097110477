// Pull-push dilation (pyramid.h) of a level that need not fit in memory: the level's rows are
// read from its store (memory or scratch file) in bands, the pull levels (coverage-weighted
// sums in double) live in memory within a budget and in scratch files past it, and the filled
// rows are written back. The same bytes as pull_push on the whole level: every sum is made of
// the same terms added in the same order.
#pragma once

#include <cstdint>
#include <string>

#include "common/status.h"

namespace vt {

class CoverageMask;
class LevelStore;

struct BandedDilationOptions {
  uint64_t memory_budget = uint64_t(256) << 20;  // pull levels and row buffers
  std::string scratch_dir;                       // pull levels past the budget ("" = ".")
  uint32_t band_rows = 0;  // level rows read at a time; 0 = from the budget (tests force few)
};

// Bytes pull_push needs to dilate a width x height level of `channels` floats in memory.
uint64_t pull_push_bytes(uint32_t width, uint32_t height, uint32_t channels);

// Dilates `level` in place under `coverage` (the level's size, read in the same bands). Returns
// the number of texels filled (0 when every texel or none is covered: the level is left as it
// is).
Expected<uint64_t> pull_push_banded(LevelStore& level, const CoverageMask& coverage,
                                    const BandedDilationOptions& options);

}  // namespace vt
