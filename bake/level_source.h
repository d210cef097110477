// Where the build reads a pyramid level's rows from, in the layer's working form (linear light,
// premultiplied alpha, decoded unit normals): level 0 streamed from its image source, level 0
// held whole and dilated (layers with a coverage mask), or a coarser level the build wrote
// (LevelStore: memory or scratch file). The build's tasks see only this interface, so the
// streaming and the whole-level regimes run the same code.
#pragma once

#include <cstdint>
#include <memory>

#include "bake/build.h"
#include "common/status.h"

namespace vt {

class CoverageMask;
class LevelStore;
struct LayerPlan;

class LevelSource {
 public:
  virtual ~LevelSource() = default;
  virtual uint32_t width() const = 0;
  virtual uint32_t height() const = 0;
  virtual uint32_t channels() const = 0;
  size_t row_floats() const { return size_t(width()) * channels(); }
  // Rows [y0, y1), width() * channels() floats each. Cheapest in increasing y.
  virtual Status read(uint32_t y0, uint32_t y1, float* out) = 0;
  // The level's coverage, or nullptr: all covered.
  virtual const CoverageMask* coverage() const { return nullptr; }
  // True when the level's texels are held in memory (not streamed nor in a scratch file).
  virtual bool in_memory() const { return false; }
  // NaN, Inf and negative values the source held (level 0; counted once per texel).
  virtual NonFiniteReport non_finite() const { return {}; }
  // Level 0 of an 8-bit layer: the values its storage clips (counted once per texel).
  virtual ClipReport clipped() const { return {}; }
  // The store holding the level's texels whole, or nullptr (streamed): the farm's plan saves it
  // rather than copying its rows (LevelStore::save).
  virtual LevelStore* held_store() { return nullptr; }
};

// Level 0 of `input` as `plan` converts it. Without a coverage mask it streams: rows are read
// and converted when asked for, and bad values are counted, and with NonFinitePolicy::kError
// refused, in the order the build reads them (`count_bad_values` = false for reads that must
// not count, such as the training sample). With a mask the whole level is converted once, in
// place when the source hands over its texels in the working channel layout, and dilated by
// pull-push; it must then fit the memory limit.
// Whether held level-0 images of `bytes` in all (layers with coverage) stay in memory under
// `memory_limit` (else they go to scratch files): the rule the scene bake's transfer follows too.
inline bool level0_fits_memory(uint64_t bytes, uint64_t memory_limit) {
  return bytes * 5 / 4 * 2 <= memory_limit;
}

Expected<std::shared_ptr<LevelSource>> open_level0(const LayerInput& input, const LayerPlan& plan,
                                                   const BuildOptions& options,
                                                   bool count_bad_values = true);

}  // namespace vt
