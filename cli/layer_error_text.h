// The text form of a layer's error after the runtime format and of its DCT page modes, for the
// build and bake summaries.
#pragma once

#include <string>

#include "bake/build.h"
#include "common/status.h"

namespace vt::cli {

// ", after BC1: PSNR 38.20 dB, max error 31" (normal layers: "..., angle mean/p99/max 0.8/2.9/7.1
// deg"), then "; pages 120 default, 4 lossless" for DCT layers; empty when there is nothing to say.
// Half-float layers after BC6H: ", after bc6h_uf16: log2 error mean 0.0123 max 0.456, relative
// max 0.5, tone-mapped PSNR 47.10 dB" (codec/hdr_metrics.h).
std::string runtime_error_text(const LayerSummary& layer);
// "log2 error mean M max X, relative max R, tone-mapped PSNR P dB", or "exact".
std::string hdr_error_text(const HdrError& error);

// --min-psnr DB or LAYER=DB (repeatable) into the encoder options.
Status parse_min_psnr(const std::string& text, PageEncoderOptions* options);

}  // namespace vt::cli
