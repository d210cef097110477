// The emissive contribution alone (issue 15): both lit passes rendered with every light off and
// only the emissive input (lit_pass.h emissive_frame_for), so each shades to its emission and
// black elsewhere. The whole lit view dilutes a wrong emissive layer with everything that does
// not glow; here it stands alone. Two measures: PSNR over the pixels either render lights up, and
// the ratio of the emitted light summed over the view (linear), which filtering and the atlas's
// coarser density keep while a scaled or dimmed layer does not.
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "common/status.h"
#include "render/renderer.h"

namespace vt::render {

struct EmissiveMetrics {
  uint64_t pixels = 0;         // drawn by both renders, a channel above kEmissiveDark in either
  double psnr_rgb = 0;         // over those pixels, channels 0-2
  double worst_tile_psnr = 0;  // worst 16 x 16 tile with at least 32 of them
  // Virtual over reference emission summed in linear light over the pixels both drew; 1 when
  // neither emits.
  double energy_ratio = 1;
  uint64_t reference_glow_pixels = 0;  // pixels the reference lights up (above kEmissiveDark)
  // Whether energy_ratio is judged: the reference glows on at least kMinGlowPixels. A view of
  // surfaces that emit nothing has no light to keep; what the virtual render shows there
  // (codec bleed from a glowing chart next door) is judged by the PSNR bounds alone.
  bool energy_judged() const { return reference_glow_pixels >= kMinGlowPixels; }
  static constexpr uint64_t kMinGlowPixels = 32;  // one 16 x 16 tile's worth, as the tiles count
};

// A channel at or below this (8-bit sRGB) does not count as emitting.
inline constexpr int kEmissiveDark = 2;

// Bounds measured on correct bakes (docs/BENCHMARKS.md, issue 15 figures).
struct EmissiveBounds {
  double min_psnr = 0;
  double min_tile_psnr = 0;
  // |log2(energy_ratio)|: how many stops the virtual texture's emission may be off.
  double max_energy_stops = 0;
};
EmissiveBounds default_emissive_bounds();

Expected<EmissiveMetrics> compare_emissive(const ReferenceFrame& reference,
                                           const VirtualFrame& frame);
// One line per broken bound, each starting "emissive: "; empty when the view passes.
std::vector<std::string> check_emissive(const EmissiveMetrics& m, const EmissiveBounds& b);

nlohmann::json to_json(const EmissiveMetrics& m);

}  // namespace vt::render
