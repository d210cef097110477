// Error metrics for 8-bit images: PSNR (per channel and over the colour channels), maximum
// absolute error, SSIM, and the angular error of tangent-space normal maps stored as XY.
// Images are row-major, `channels` interleaved 8-bit channels; a reference and a test image
// of the same size are compared. Every result is finite: identical images give a PSNR of
// kPsnrIdentical rather than infinity, so reports and JSON stay numeric.
#pragma once

#include <cstdint>

#include "common/status.h"

namespace vt {

inline constexpr double kPsnrIdentical = 100.0;

// PSNR in dB of a mean squared error on the 0..255 scale; kPsnrIdentical when mse <= 0.
double psnr_from_mse(double mse);

struct ImageError {
  int channels = 0;
  double mse[4] = {0, 0, 0, 0};
  double psnr[4] = {0, 0, 0, 0};
  int max_abs[4] = {0, 0, 0, 0};
  // Over channels 0..2 (or all of them when there are fewer than 3): the MSE of all their
  // samples together, its PSNR, and the largest absolute difference.
  double mse_rgb = 0;
  double psnr_rgb = 0;
  int max_abs_rgb = 0;
  int max_abs_all = 0;  // over every channel
};

// Per-channel and combined errors of `test` against `ref`.
Expected<ImageError> compare_images(const uint8_t* ref, const uint8_t* test, int width, int height,
                                    int channels);

// Mean SSIM (Wang et al. 2004, K1 = 0.01, K2 = 0.03) over 8x8 windows placed every 4 texels,
// averaged over channels 0..min(channels, 3)-1. 1.0 for identical images. Images must be at
// least 8x8.
Expected<double> ssim(const uint8_t* ref, const uint8_t* test, int width, int height, int channels);

struct AngularError {
  double mean_deg = 0;
  double max_deg = 0;
  double p99_deg = 0;  // 99th percentile
};

// Normal maps stored as X, Y in channels 0 and 1 (0..255 maps to -1..1; other channels
// ignored): Z is rebuilt as sqrt(max(0, 1 - x^2 - y^2)), as a shader does after BC5, and the
// angle between the reference and test normals is measured per texel. channels >= 2.
Expected<AngularError> normal_angular_error(const uint8_t* ref, const uint8_t* test, int width,
                                            int height, int channels);

}  // namespace vt
