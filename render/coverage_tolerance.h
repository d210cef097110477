// Alpha-tested edges in the view comparison. Two renders of a correct bake disagree on which side
// of an alpha cutoff a pixel lies only as far as their alphas differ: the bake stores coverage
// (alpha) resampled into the atlas and filtered through its pyramid, the reference filters the
// original texture. So a pixel drawn by one render only is explained when the alpha it was drawn
// with lies within that difference above a cutoff, and counts as a coverage mismatch otherwise.
#pragma once

#include <cstdint>
#include <span>

#include "render/renderer.h"

namespace vt::render {

struct CoverageMismatch {
  uint64_t either = 0;       // pixels drawn by either render
  uint64_t explained = 0;    // drawn by one only, with an alpha within the tolerance of a cutoff
  uint64_t unexplained = 0;  // drawn by one only otherwise
  // The view's alpha tolerance: the 99th percentile of |reference alpha - virtual alpha| over
  // the pixels both drew with a non-opaque alpha, at least 2/255 (rounding on both sides) and
  // at most 1/8 (so that a wrong alpha channel cannot excuse its own edges).
  double alpha_tolerance = 0;
};

// Classifies the pixels drawn by one render only against the scene's alpha cutoffs (MASK
// materials; none: every such pixel is unexplained). The frames must have the same size.
CoverageMismatch classify_coverage(const ReferenceFrame& reference, const VirtualFrame& frame,
                                   std::span<const float> cutoffs);

}  // namespace vt::render
