// Texel-space checks of an atlas with the atlas rasteriser, on the very coordinates transfer
// reads: a texel centre owned by two triangles is a real overlap (the fill rule gives a centre
// on a shared edge to one side only), and a texel touched by two charts is one that transfer
// would find contested (the gutter proof).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "bake/unwrap/atlas_raster.h"
#include "bake/unwrap/unwrap.h"

namespace vt::unwrap {
namespace {

constexpr int64_t kBandRows = 256;

}  // namespace

AtlasCheck check_atlas(const std::vector<AtlasTriangle>& tris, int width, int height) {
  AtlasCheck out;
  if (width <= 0 || height <= 0) return out;
  std::vector<RasterTriangle> raster;
  raster.reserve(tris.size());
  for (const AtlasTriangle& t : tris) {
    const auto& uv = t.uv;
    double cross = (uv[2] - uv[0]) * (uv[5] - uv[1]) - (uv[3] - uv[1]) * (uv[4] - uv[0]);
    if (cross > 0) ++out.flipped_triangles;  // y down: front faces appear counter-clockwise
    raster.emplace_back(uv);
  }
  const auto bins = bin_by_rows(raster, height, kBandRows);
  std::vector<int32_t> owner(static_cast<size_t>(width) * kBandRows);
  std::vector<int32_t> chart_owner(owner.size());
  std::vector<char> overlap_texel(owner.size());
  std::vector<char> tri_overlaps(tris.size(), 0);
  for (size_t b = 0; b < bins.size(); ++b) {
    const int64_t row0 = int64_t(b) * kBandRows, row1 = std::min<int64_t>(height, row0 + kBandRows);
    std::fill(owner.begin(), owner.end(), -1);
    std::fill(chart_owner.begin(), chart_owner.end(), -1);
    std::fill(overlap_texel.begin(), overlap_texel.end(), 0);
    const TexelRect band = {0, row0, width - 1, row1 - 1};
    for (uint32_t t : bins[b]) {
      const RasterTriangle& r = raster[t];
      for_each_touched_texel(r, 0.0, band, [&](int64_t i, int64_t j) {
        size_t cell = static_cast<size_t>(j - row0) * width + static_cast<size_t>(i);
        int32_t& co = chart_owner[cell];
        if (co < 0)
          co = tris[t].chart;
        else if (co != tris[t].chart)
          overlap_texel[cell] = 1;
        double lambda[3];
        if (!r.contains(i + 0.5, j + 0.5, lambda)) return;
        int32_t& o = owner[cell];
        if (o < 0) {
          o = static_cast<int32_t>(t);
        } else {
          tri_overlaps[t] = 1;
          tri_overlaps[o] = 1;
        }
      });
    }
    for (size_t cell = 0; cell < static_cast<size_t>(row1 - row0) * width; ++cell) {
      out.covered_texels += owner[cell] >= 0;
      out.overlapping_texels += overlap_texel[cell];
    }
  }
  for (char o : tri_overlaps) out.overlapping_triangles += o;
  out.utilisation = static_cast<double>(out.covered_texels) / (static_cast<double>(width) * height);
  return out;
}

}  // namespace vt::unwrap
