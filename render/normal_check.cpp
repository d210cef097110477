#include "render/normal_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

namespace vt::render {

constexpr double kDegreesPerRadian = 57.295779513082320876;

NormalBounds default_normal_bounds() {
  // Correct bakes (2026-12-03, adaptive taps): the sample scene's default bake at 1280x720,
  // mean angle 2.1-4.9 deg, correlation 0.90-0.98 (reference detail 17-24 deg RMS: the tile
  // grooves); its 4-page test bake at 320x180, 4.8 deg, 0.83; ClearCoatTest 0.5-2.1 deg,
  // 0.96-1.00. The test bake with green flipped: 7.3-7.6 deg, correlation -0.10-0.00.
  NormalBounds b;
  b.max_mean_deg = 10.0;
  b.min_detail_correlation = 0.5;
  return b;
}

Expected<NormalMetrics> compare_normals(const ReferenceFrame& reference,
                                        const VirtualFrame& frame) {
  const Rgba8Image& r = reference.color;
  const Rgba8Image& t = frame.color;
  const size_t n = size_t(t.width) * t.height;
  if (r.width != t.width || r.height != t.height || r.texels.size() != n * 4 ||
      t.texels.size() != n * 4 || frame.status.size() != n || reference.covered.size() != n) {
    return Error(ErrorCode::kInvalidArgument, "render: compared normal images differ in size");
  }
  // Angles in tenths of a degree: a histogram gives the percentile without sorting.
  constexpr int kBins = 1801;
  std::vector<uint64_t> histogram(kBins, 0);
  NormalMetrics m;
  double sum_deg = 0, dot_rv = 0, sq_r = 0, sq_v = 0, sq_angle_r = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!(frame.status[i] & VirtualFrame::kStatusDrawn) || !(reference.covered[i] & 1u)) continue;
    double a[3], b[3], diff = 0, la = 0, lb = 0, ab = 0;
    for (int c = 0; c < 3; ++c) {
      a[c] = r.texels[i * 4 + c] / 127.5 - 1.0, b[c] = t.texels[i * 4 + c] / 127.5 - 1.0;
      diff += (a[c] - b[c]) * (a[c] - b[c]);
      la += a[c] * a[c], lb += b[c] * b[c], ab += a[c] * b[c];
    }
    // Both shading normals are unit and share the vertex normal: the detail vectors' difference
    // is the normals' chord, 2 sin(angle / 2).
    const double deg = 2.0 * std::asin(std::min(1.0, std::sqrt(diff) / 2.0)) * kDegreesPerRadian;
    const double ref_deg = 2.0 * std::asin(std::min(1.0, std::sqrt(la) / 2.0)) * kDegreesPerRadian;
    sum_deg += deg;
    sq_angle_r += ref_deg * ref_deg;
    dot_rv += ab, sq_r += la, sq_v += lb;
    m.max_deg = std::max(m.max_deg, deg);
    ++histogram[std::min(kBins - 1, int(deg * 10.0))];
    ++m.pixels;
  }
  if (m.pixels == 0) return m;
  m.mean_deg = sum_deg / double(m.pixels);
  m.reference_detail_deg = std::sqrt(sq_angle_r / double(m.pixels));
  if (sq_r > 0 && sq_v > 0)
    m.detail_correlation = dot_rv / std::sqrt(sq_r * sq_v);
  else if (sq_r > 0 || sq_v > 0)
    m.detail_correlation = 0;
  const uint64_t rank = (m.pixels * 99 + 99) / 100;
  uint64_t seen = 0;
  for (int k = 0; k < kBins; ++k) {
    seen += histogram[k];
    if (seen >= rank) {
      m.p99_deg = (k + 1) / 10.0;
      break;
    }
  }
  return m;
}

std::vector<std::string> check_normals(const NormalMetrics& m, const NormalBounds& b) {
  std::vector<std::string> why;
  char line[200];
  if (m.mean_deg > b.max_mean_deg) {
    std::snprintf(line, sizeof line, "normals: mean angle %.2f deg above %.2f deg", m.mean_deg,
                  b.max_mean_deg);
    why.push_back(line);
  }
  if (m.detail_judged() && m.detail_correlation < b.min_detail_correlation) {
    std::snprintf(line, sizeof line,
                  "normals: the normal layer repeats the materials' detail with correlation %.2f, "
                  "below %.2f (a flipped or swapped channel?)",
                  m.detail_correlation, b.min_detail_correlation);
    why.push_back(line);
  }
  return why;
}

nlohmann::json to_json(const NormalMetrics& m) {
  return {{"pixels", m.pixels},
          {"mean_deg", m.mean_deg},
          {"p99_deg", m.p99_deg},
          {"max_deg", m.max_deg},
          {"detail_correlation", m.detail_correlation},
          {"reference_detail_deg", m.reference_detail_deg},
          {"detail_judged", m.detail_judged()}};
}

}  // namespace vt::render
