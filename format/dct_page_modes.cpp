// The per-page mode decision (see dct_page_modes.h).
#include "format/dct_page_modes.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

#include "format/zstd_frame.h"

namespace vt {
namespace {

// The distortion-rate slope at the page's own operating point: D(R) ~ 2^(-2R) at high rate, so
// dSSE/dbit = 2 ln 2 * MSE of the default mode; bounded below by the layer's slope, the same for
// every page (dct_layer_slope). A page's own MSE is small where the page is smooth or mostly
// padding (the edge pages and coarse levels of an image), and a lambda that small bought lossless
// or finer forms for them at a worse rate-distortion trade than the rest of the layer (whole
// Kodak pyramids: +1.5% bytes at equal PSNR, q50-q95); the step's uniform-quantiser slope alone
// underestimates it several times where 4:2:0 chroma dominates the error (on photographs at
// quality 90 it chose lossless pages 5.7x larger).
constexpr double kTwoLn2 = 2.0 * std::numbers::ln2;
// Only pages whose lossless form is within this factor of their default DCT form (content that is
// not a photograph) or that miss the floor try the other DCT modes: photographs keep their
// encoding time and bytes.
constexpr double kHardContentRatio = 3.0;

struct Candidate {
  uint8_t mode = 0;
  std::vector<uint8_t> bytes;
  std::vector<uint8_t> decoded;
  double sse = 0;
};

double page_sse(const uint8_t* a, const uint8_t* b, size_t n) {
  uint64_t sse = 0;
  for (size_t i = 0; i < n; ++i) {
    const int d = int(a[i]) - int(b[i]);
    sse += uint64_t(d * d);
  }
  return double(sse);
}

double psnr_of(double sse, size_t n) {
  return sse <= 0 ? INFINITY : 10.0 * std::log10(255.0 * 255.0 * double(n) / sse);
}

Status code_dct(const DctTables& t, const uint8_t* texels, int size, DctPageMode mode, size_t n,
                Candidate& c) {
  c.mode = uint8_t((mode.full_chroma ? 1 : 0) | (mode.finer << 1));
  VT_RETURN_IF_ERROR(dct_encode_page(t, texels, size, size, c.bytes, mode));
  c.decoded.resize(n);
  VT_RETURN_IF_ERROR(dct_decode_page(t, c.bytes, size, size, std::span<uint8_t>(c.decoded)));
  c.sse = page_sse(texels, c.decoded.data(), n);
  return Status::Ok();
}

}  // namespace

Expected<uint8_t> dct_encode_page_modes(const DctTables& tables, const uint8_t* texels, int size,
                                        int channels, const DctModeSettings& settings,
                                        std::vector<uint8_t>& out, uint8_t* decoded) {
  const size_t n = size_t(size) * size * size_t(channels);
  thread_local Candidate best, trial;
  VT_RETURN_IF_ERROR(code_dct(tables, texels, size, {}, n, best));
  if (!settings.enabled || dct_tables_version(tables) < 4) {
    out.swap(best.bytes);
    if (decoded) std::memcpy(decoded, best.decoded.data(), n);
    return uint8_t(0);
  }
  const int step = dct_base_step(tables);
  const double lambda = std::max(dct_layer_slope(tables), kTwoLn2 * best.sse / double(n));
  auto cost = [&](const Candidate& c) { return c.sse + lambda * 8.0 * double(c.bytes.size()); };
  auto meets_floor = [&](const Candidate& c) {
    return settings.min_psnr <= 0 || psnr_of(c.sse, n) >= settings.min_psnr;
  };
  std::vector<uint8_t> lossless;
  VT_RETURN_IF_ERROR(zstd_compress({texels, n}, settings.zstd_level, lossless));
  const size_t lossless_size = lossless.size() + 1;
  const bool base_ok = meets_floor(best);
  // Lossless has no distortion: it wins over any form at least as large.
  double best_cost = base_ok ? cost(best) : INFINITY;
  if (!base_ok || double(best.bytes.size()) * kHardContentRatio >= double(lossless_size)) {
    for (int finer = 0; finer <= kDctMaxFiner; ++finer) {
      // A finer step than 1 is the same quantiser again.
      if (finer > 0 && (step >> (finer - 1)) <= 1) break;
      for (int full = 0; full < 2; ++full) {
        const DctPageMode mode{full == 1, uint8_t(finer)};
        if ((finer == 0 && !full) || !dct_mode_applies(tables, mode)) continue;
        VT_RETURN_IF_ERROR(code_dct(tables, texels, size, mode, n, trial));
        if (!meets_floor(trial) || cost(trial) >= best_cost) continue;
        best_cost = cost(trial);
        std::swap(best, trial);
      }
    }
  }
  // Lossless also wins ties: no distortion, and never more bytes than the chosen form.
  if (lambda * 8.0 * double(lossless_size) < best_cost || best.bytes.size() >= lossless_size) {
    out.resize(lossless_size);
    out[0] = kDctPageLossless;
    std::memcpy(out.data() + 1, lossless.data(), lossless.size());
    if (decoded) std::memcpy(decoded, texels, n);
    return kDctModeLossless;
  }
  out = best.bytes;
  if (decoded) std::memcpy(decoded, best.decoded.data(), n);
  return best.mode;
}

Status dct_decode_page_modes(const DctTables& tables, std::span<const uint8_t> data, int size,
                             std::span<uint8_t> texels) {
  if (!data.empty() && data[0] == kDctPageLossless) {
    const DctTablesShape shape = dct_tables_shape(tables);
    const size_t n = size_t(size) * size * size_t(shape.channels);
    if (texels.size() != n)
      return Error(ErrorCode::kInvalidArgument, "dct: output of " + std::to_string(texels.size()) +
                                                    " bytes, a page has " + std::to_string(n));
    Status s = zstd_decompress_exact(data.subspan(1), texels);
    return s.ok() ? s : s.with_context("dct lossless page");
  }
  return dct_decode_page(tables, data, size, size, texels);
}

const char* dct_mode_name(uint8_t mode) {
  static const char* const kNames[kDctModeKinds] = {"default",     "4:4:4",       "fine1",
                                                    "fine1 4:4:4", "fine2",       "fine2 4:4:4",
                                                    "fine3",       "fine3 4:4:4", "lossless"};
  return mode < kDctModeKinds ? kNames[mode] : "?";
}

}  // namespace vt
