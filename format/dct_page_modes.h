// The per-page mode decision of DCT layers: each page is coded in the DctPageMode (4:4:4 chroma,
// finer quantiser) or lossless form (raw texels + zstd, first byte kDctPageLossless) that costs
// least by rate and distortion, J = SSE + lambda * bits with lambda from the tables' quantiser
// step, among the forms that meet the layer's error floor. Lossless is always a candidate, so no
// page costs more than its lossless form and none falls below the floor.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "codec/dct.h"
#include "common/status.h"

namespace vt {

struct DctModeSettings {
  bool enabled = true;  // false: every page in mode {} (the old behaviour, fastest to encode)
  double min_psnr = 0;  // per page over all channels, stored codec; 0: no floor
  int zstd_level = 3;
};

// What a page was coded as: a DCT mode byte (0..kDctPageModes-1) or kDctModeLossless.
inline constexpr uint8_t kDctModeLossless = kDctPageModes;
inline constexpr int kDctModeKinds = kDctPageModes + 1;

// Codes one page (size x size texels of `channels` bytes) into `out` (replaced); `decoded`, when
// not null, receives the texels decoding gives back. Returns the chosen mode (kDctModeLossless or
// a DCT mode byte).
Expected<uint8_t> dct_encode_page_modes(const DctTables& tables, const uint8_t* texels, int size,
                                        int channels, const DctModeSettings& settings,
                                        std::vector<uint8_t>& out, uint8_t* decoded);

// Decodes a DCT layer's page of any mode, lossless ones included. Bounds-safe as
// dct_decode_page.
Status dct_decode_page_modes(const DctTables& tables, std::span<const uint8_t> data, int size,
                             std::span<uint8_t> texels);

// The mode names for reports: "default" (the tables' own), "4:4:4" (full chroma on 4:2:0
// tables), "fine1" (steps / 2), "fine1 4:4:4", ..., "fine3 4:4:4", "lossless".
const char* dct_mode_name(uint8_t mode);

}  // namespace vt
