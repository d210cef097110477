// The error of a page where it lands: its stored texels decoded, encoded to the layer's BC format
// as the runtime transcodes them (BcQuality::kRealtime, runtime/page_source.h) or taken as the
// stored BC blocks, decoded, and compared with the texels the page was made from. Normal layers
// (BC5) also give the angle between source and landed normals in degrees.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "codec/bc.h"
#include "codec/hdr_metrics.h"
#include "common/status.h"

namespace vt {

struct RuntimeError {
  double squared_error = 0;  // over the channels the BC format keeps, 8-bit units
  uint64_t samples = 0;
  uint32_t max_error = 0;
  // Normal layers: texels compared, the sum and largest angle, and a histogram of angles in
  // kAngleBinDeg bins (the last bin holds everything above) for the 99th percentile.
  static constexpr double kAngleBinDeg = 0.02;
  static constexpr int kAngleBins = 4096;
  uint64_t normals = 0;
  double angle_sum_deg = 0, angle_max_deg = 0;
  std::vector<uint32_t> angle_histogram;
  // Half-float layers (BC6H): log-space and tone-mapped errors (codec/hdr_metrics.h) instead of
  // the 8-bit figures above, which then have no samples.
  HdrError hdr;

  void add(const RuntimeError& other);
  double psnr_db() const;  // infinite when nothing differs
  double angle_mean_deg() const { return normals ? angle_sum_deg / double(normals) : 0; }
  double angle_p99_deg() const;
};

// `source` and `stored` are size x size texels of `channels` bytes (stored: what the page
// decodes to). `bc_blocks`, when not null, are the page's own BC blocks (a BC layer), used as
// they are instead of encoding `stored`. `reference`, when not null, is what the source was
// before it was clipped to 8 bits (size * size * channels values in 8-bit code units): the
// squared and largest errors are measured against it instead (the angles against `source`).
Status measure_runtime_error(BcFormat format, bool normal, const uint8_t* source,
                             const uint8_t* stored, const uint8_t* bc_blocks, int size,
                             int channels, RuntimeError& out, const float* reference = nullptr);

// The same for half-float pages and BC6H (`format` kBc6hUf16 or kBc6hSf16): `source` and
// `stored` are size x size texels of `channels` halves; fills out.hdr over the RGB channels.
// `reference`, when not null, holds the float values the halves were rounded from (size * size *
// channels): the error is measured against them instead of `source`.
Status measure_runtime_hdr_error(BcFormat format, const uint8_t* source, const uint8_t* stored,
                                 const uint8_t* bc_blocks, int size, int channels,
                                 RuntimeError& out, const float* reference = nullptr);

}  // namespace vt
