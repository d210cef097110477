// The page encoder's default DCT floor: a page the mode decision would store below the page
// bound the validator holds its layer to (format/page_error_bounds.h) is lifted to the bound
// plus its margin; --min-psnr 0 turns the floor off, a layer's own value overrides it. Thin
// lines of alternating colour under grain: the 4:2:0 mode halves their chroma, and without a
// floor the rate-distortion choice kept it at 13-16 dB.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "bake/page_encoder.h"
#include "format/page_error_bounds.h"

namespace vt {
namespace {

constexpr uint32_t kPage = 128;

// Thin coloured lines on a smooth ground (`period` texels apart, alternating red and blue),
// plus grain of +-`amplitude` in each channel apart: the chroma the default 4:2:0 mode halves.
std::vector<uint8_t> lines(int period, int amplitude) {
  std::vector<uint8_t> t(size_t(kPage) * kPage * 3);
  uint32_t s = 12345;
  for (uint32_t y = 0; y < kPage; ++y)
    for (uint32_t x = 0; x < kPage; ++x) {
      uint8_t* p = &t[(size_t(y) * kPage + x) * 3];
      const bool line = x % period == 0, red = (x / period) % 2 == 0;
      for (int c = 0; c < 3; ++c) {
        s = s * 1664525u + 1013904223u;
        int v = 96 + int(y) / 2 + int(s >> 24) % (2 * amplitude + 1) - amplitude;
        if (line) v = c == (red ? 0 : 2) ? 240 : 20;
        p[c] = uint8_t(std::clamp(v, 0, 255));
      }
    }
  return t;
}

double stored_psnr(const PageEncoderOptions& o, const std::vector<uint8_t>& texels) {
  LayerSpec layer;
  layer.name = "albedo";
  layer.semantic = LayerSemantic::kAlbedo;
  layer.channels = 3;
  layer.texel_type = TexelType::kU8;
  auto e = PageEncoder::create(layer, o, kPage);
  EXPECT_TRUE(e.ok()) << e.status().message();
  EncodedPage page;
  EXPECT_TRUE(e->encode(texels.data(), page).ok());
  const double mse = page.squared_error / double(page.samples);
  return mse > 0 ? 10 * std::log10(255.0 * 255.0 / mse) : 99.0;
}

TEST(PageEncoderFloor, DefaultBakesStoreNoPageBelowTheirLayersBound) {
  const double floor = kDctPagePsnr.albedo + kDctFloorMarginDb;
  for (const auto [period, amplitude] : {std::pair{2, 16}, std::pair{4, 40}}) {
    const std::vector<uint8_t> page = lines(period, amplitude);
    PageEncoderOptions none;
    none.min_psnr = 0;
    const double without = stored_psnr(none, page);
    EXPECT_LT(without, kDctPagePsnr.albedo) << period;  // 12.9 and 15.5 dB measured
    const double with = stored_psnr(PageEncoderOptions{}, page);
    EXPECT_GE(with, floor) << period;
    PageEncoderOptions own;
    own.layer_min_psnr["albedo"] = 40;
    EXPECT_GE(stored_psnr(own, page), 40.0) << period;
    std::printf("lines %d apart, grain +-%d: %.2f dB without a floor, %.2f dB by default\n", period,
                amplitude, without, with);
  }
}

}  // namespace
}  // namespace vt
