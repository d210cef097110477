// Error metrics. Sums are accumulated in 64-bit integers where exact, so results do not depend
// on summation order.
#include "codec/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

namespace vt {
namespace {

Status check(const void* a, const void* b, int width, int height, int channels, int min_size,
             int min_channels) {
  if (a == nullptr || b == nullptr) return Error(ErrorCode::kInvalidArgument, "null image");
  if (width < min_size || height < min_size || channels < min_channels || channels > 4) {
    return Error(ErrorCode::kInvalidArgument,
                 "image " + std::to_string(width) + "x" + std::to_string(height) + "x" +
                     std::to_string(channels) + " is outside what the metric accepts (at least " +
                     std::to_string(min_size) + "x" + std::to_string(min_size) + ", " +
                     std::to_string(min_channels) + "..4 channels)");
  }
  return Status::Ok();
}

}  // namespace

double psnr_from_mse(double mse) {
  if (!(mse > 0)) return kPsnrIdentical;
  return std::min(kPsnrIdentical, 10.0 * std::log10(255.0 * 255.0 / mse));
}

Expected<ImageError> compare_images(const uint8_t* ref, const uint8_t* test, int width, int height,
                                    int channels) {
  VT_RETURN_IF_ERROR(check(ref, test, width, height, channels, 1, 1));
  const size_t n = size_t(width) * size_t(height);
  uint64_t sq[4] = {0, 0, 0, 0};
  ImageError e;
  e.channels = channels;
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < channels; ++c) {
      const int d = std::abs(int(ref[i * channels + c]) - int(test[i * channels + c]));
      sq[c] += uint64_t(d * d);
      e.max_abs[c] = std::max(e.max_abs[c], d);
    }
  }
  const int colour = std::min(channels, 3);
  uint64_t sq_rgb = 0;
  for (int c = 0; c < channels; ++c) {
    e.mse[c] = double(sq[c]) / double(n);
    e.psnr[c] = psnr_from_mse(e.mse[c]);
    e.max_abs_all = std::max(e.max_abs_all, e.max_abs[c]);
    if (c < colour) {
      sq_rgb += sq[c];
      e.max_abs_rgb = std::max(e.max_abs_rgb, e.max_abs[c]);
    }
  }
  e.mse_rgb = double(sq_rgb) / (double(n) * colour);
  e.psnr_rgb = psnr_from_mse(e.mse_rgb);
  return e;
}

Expected<double> ssim(const uint8_t* ref, const uint8_t* test, int width, int height,
                      int channels) {
  VT_RETURN_IF_ERROR(check(ref, test, width, height, channels, 8, 1));
  const double c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
  const int colour = std::min(channels, 3);
  double total = 0;
  size_t windows = 0;
  for (int c = 0; c < colour; ++c) {
    for (int y0 = 0; y0 + 8 <= height; y0 += 4) {
      for (int x0 = 0; x0 + 8 <= width; x0 += 4) {
        int64_t sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
        for (int y = y0; y < y0 + 8; ++y) {
          for (int x = x0; x < x0 + 8; ++x) {
            const size_t i = (size_t(y) * size_t(width) + size_t(x)) * size_t(channels) + c;
            const int a = ref[i], b = test[i];
            sa += a, sb += b, saa += a * a, sbb += b * b, sab += a * b;
          }
        }
        const double n = 64.0;
        const double ma = double(sa) / n, mb = double(sb) / n;
        // Sample (n - 1) variances, as in the reference implementation.
        const double va = (double(saa) - double(sa) * ma) / (n - 1);
        const double vb = (double(sbb) - double(sb) * mb) / (n - 1);
        const double cov = (double(sab) - double(sa) * mb) / (n - 1);
        total +=
            ((2 * ma * mb + c1) * (2 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
        ++windows;
      }
    }
  }
  return total / double(windows);
}

Expected<AngularError> normal_angular_error(const uint8_t* ref, const uint8_t* test, int width,
                                            int height, int channels) {
  VT_RETURN_IF_ERROR(check(ref, test, width, height, channels, 1, 2));
  const size_t n = size_t(width) * size_t(height);
  auto normal = [](const uint8_t* p, double v[3]) {
    v[0] = p[0] / 127.5 - 1.0;
    v[1] = p[1] / 127.5 - 1.0;
    v[2] = std::sqrt(std::max(0.0, 1.0 - v[0] * v[0] - v[1] * v[1]));
  };
  std::vector<float> angles(n);
  double sum = 0;
  AngularError e;
  for (size_t i = 0; i < n; ++i) {
    double a[3], b[3];
    normal(ref + i * channels, a);
    normal(test + i * channels, b);
    const double cx = a[1] * b[2] - a[2] * b[1], cy = a[2] * b[0] - a[0] * b[2],
                 cz = a[0] * b[1] - a[1] * b[0];
    const double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    // atan2 stays accurate for tiny angles, where acos(dot) loses precision.
    const double deg =
        std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), dot) * (180.0 / std::numbers::pi);
    angles[i] = float(deg);
    sum += deg;
    e.max_deg = std::max(e.max_deg, deg);
  }
  e.mean_deg = sum / double(n);
  const size_t k = std::min(n - 1, size_t(std::ceil(0.99 * double(n))) - 1);
  std::nth_element(angles.begin(), angles.begin() + k, angles.end());
  e.p99_deg = angles[k];
  return e;
}

}  // namespace vt
