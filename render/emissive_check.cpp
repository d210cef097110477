#include "render/emissive_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "codec/metrics.h"
#include "common/srgb.h"

namespace vt::render {

EmissiveBounds default_emissive_bounds() {
  // Correct bakes of the sample scene (test bake: 256-texel sources, 4 pages, 320x180; and the
  // default bake at 1280x720): emission 0.84x the materials' seen close on the 1-texel lines,
  // up to 1.63x from afar (the reference's mips average sRGB bytes, which darkens thin bright
  // lines; the bake filters in linear light), PSNR over the glowing pixels 10.9-15.7 dB (the
  // atlas is coarser than the lines). An emissive layer at half strength seen close: 0.41x.
  EmissiveBounds b;
  b.min_psnr = 8.0;
  b.min_tile_psnr = 5.0;
  b.max_energy_stops = 0.85;  // 0.55x-1.80x
  return b;
}

Expected<EmissiveMetrics> compare_emissive(const ReferenceFrame& reference,
                                           const VirtualFrame& frame) {
  const Rgba8Image& r = reference.color;
  const Rgba8Image& t = frame.color;
  const size_t n = size_t(t.width) * t.height;
  if (r.width != t.width || r.height != t.height || r.texels.size() != n * 4 ||
      t.texels.size() != n * 4 || frame.status.size() != n || reference.covered.size() != n) {
    return Error(ErrorCode::kInvalidArgument, "render: compared emissive images differ in size");
  }
  float linear[256];
  for (int i = 0; i < 256; ++i) linear[i] = srgb_to_linear(float(i) / 255.0f);
  constexpr uint32_t kTile = 16;
  const uint32_t tiles_x = (t.width + kTile - 1) / kTile;
  std::vector<double> tile_sse(size_t(tiles_x) * ((t.height + kTile - 1) / kTile), 0.0);
  std::vector<uint32_t> tile_count(tile_sse.size(), 0);
  EmissiveMetrics m;
  double sse = 0, energy_ref = 0, energy_test = 0;
  for (uint32_t y = 0; y < t.height; ++y)
    for (uint32_t x = 0; x < t.width; ++x) {
      const size_t i = size_t(y) * t.width + x;
      if (!(frame.status[i] & VirtualFrame::kStatusDrawn) || !(reference.covered[i] & 1u)) continue;
      const uint8_t* a = &r.texels[i * 4];
      const uint8_t* b = &t.texels[i * 4];
      for (int c = 0; c < 3; ++c) energy_ref += linear[a[c]], energy_test += linear[b[c]];
      m.reference_glow_pixels += std::max({a[0], a[1], a[2]}) > kEmissiveDark;
      if (std::max({a[0], a[1], a[2], b[0], b[1], b[2]}) <= kEmissiveDark) continue;
      double px = 0;
      for (int c = 0; c < 3; ++c) px += double(int(a[c]) - b[c]) * double(int(a[c]) - b[c]);
      sse += px;
      ++m.pixels;
      const size_t k = size_t(y / kTile) * tiles_x + x / kTile;
      tile_sse[k] += px;
      tile_count[k]++;
    }
  m.psnr_rgb = m.pixels ? psnr_from_mse(sse / (3.0 * double(m.pixels))) : kPsnrIdentical;
  m.worst_tile_psnr = kPsnrIdentical;
  for (size_t k = 0; k < tile_sse.size(); ++k) {
    if (tile_count[k] < 32) continue;
    m.worst_tile_psnr =
        std::min(m.worst_tile_psnr, psnr_from_mse(tile_sse[k] / (3.0 * tile_count[k])));
  }
  if (energy_ref > 0) {
    m.energy_ratio = energy_test / energy_ref;
  } else if (energy_test > 0) {
    m.energy_ratio = kPsnrIdentical;  // glows where the materials do not: as far off as reported
  }
  return m;
}

std::vector<std::string> check_emissive(const EmissiveMetrics& m, const EmissiveBounds& b) {
  std::vector<std::string> why;
  char line[160];
  if (m.psnr_rgb < b.min_psnr) {
    std::snprintf(line, sizeof line, "emissive: PSNR %.2f dB below %.2f dB", m.psnr_rgb,
                  b.min_psnr);
    why.push_back(line);
  }
  if (m.worst_tile_psnr < b.min_tile_psnr) {
    std::snprintf(line, sizeof line, "emissive: worst tile PSNR %.2f dB below %.2f dB",
                  m.worst_tile_psnr, b.min_tile_psnr);
    why.push_back(line);
  }
  const double stops = m.energy_ratio > 0 ? std::abs(std::log2(m.energy_ratio)) : 1e9;
  if (m.energy_judged() && stops > b.max_energy_stops) {
    std::snprintf(
        line, sizeof line,
        "emissive: the virtual texture emits %.2fx the materials' light, beyond %.2fx-%.2fx",
        m.energy_ratio, std::exp2(-b.max_energy_stops), std::exp2(b.max_energy_stops));
    why.push_back(line);
  }
  return why;
}

nlohmann::json to_json(const EmissiveMetrics& m) {
  return {{"psnr_rgb", m.psnr_rgb},
          {"worst_tile_psnr", m.worst_tile_psnr},
          {"pixels_compared", m.pixels},
          {"energy_ratio", m.energy_ratio},
          {"reference_glow_pixels", m.reference_glow_pixels},
          {"energy_judged", m.energy_judged()}};
}

}  // namespace vt::render
