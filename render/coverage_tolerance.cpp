#include "render/coverage_tolerance.h"

#include <algorithm>
#include <vector>

namespace vt::render {
namespace {

constexpr double kMaxAlphaTolerance = 0.125;

}  // namespace

CoverageMismatch classify_coverage(const ReferenceFrame& reference, const VirtualFrame& frame,
                                   std::span<const float> cutoffs) {
  CoverageMismatch out;
  const size_t n = frame.status.size();
  const auto alpha = [](const Rgba8Image& img, size_t i) { return img.texels[i * 4 + 3] / 255.0; };
  std::vector<double> diffs;
  for (size_t i = 0; i < n; ++i) {
    if (!(frame.status[i] & VirtualFrame::kStatusDrawn) || !reference.covered[i]) continue;
    const double ra = alpha(reference.color, i), va = alpha(frame.color, i);
    if (std::min(ra, va) < 1.0) diffs.push_back(std::abs(ra - va));
  }
  out.alpha_tolerance = 2.0 / 255.0;
  if (!diffs.empty()) {
    auto p99 = diffs.begin() + ptrdiff_t(diffs.size() * 99 / 100);
    std::nth_element(diffs.begin(), p99, diffs.end());
    out.alpha_tolerance = std::clamp(*p99, out.alpha_tolerance, kMaxAlphaTolerance);
  }
  for (size_t i = 0; i < n; ++i) {
    const bool vcov = (frame.status[i] & VirtualFrame::kStatusDrawn) != 0,
               rcov = reference.covered[i] != 0;
    if (vcov || rcov) ++out.either;
    if (vcov == rcov) continue;
    // The render that drew it passed the test: its alpha is at or above the cutoff.
    const double a = vcov ? alpha(frame.color, i) : alpha(reference.color, i);
    const bool near_cutoff = std::any_of(cutoffs.begin(), cutoffs.end(), [&](float c) {
      return a >= c - 0.5 / 255.0 && a <= c + out.alpha_tolerance;
    });
    ++(near_cutoff ? out.explained : out.unexplained);
  }
  return out;
}

}  // namespace vt::render
