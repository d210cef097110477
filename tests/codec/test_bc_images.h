// Procedural test images for the BC tests (no test data files): deterministic content with
// known structure, so error bounds are measured on the same pixels every run.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

namespace vt::test {

// Small deterministic generator (xorshift32): the same sequence on every platform.
struct Rng {
  uint32_t s;
  explicit Rng(uint32_t seed) : s(seed ? seed : 1) {}
  uint32_t next() {
    s ^= s << 13;
    s ^= s >> 17;
    s ^= s << 5;
    return s;
  }
  int below(int n) { return int(next() % uint32_t(n)); }
};

// Smooth "photographic" content: a few sine waves per channel plus mild noise.
inline std::vector<uint8_t> smooth_image(int w, int h, int channels, uint32_t seed) {
  std::vector<uint8_t> img(size_t(w) * h * channels);
  Rng rng(seed);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < channels; ++c) {
        const double v = 128 + 60 * std::sin(0.07 * x + 0.9 * c) * std::cos(0.05 * y - 0.4 * c) +
                         40 * std::sin(0.013 * (x + 2 * y) + c) + rng.below(9) - 4;
        img[(size_t(y) * w + x) * channels + c] =
            uint8_t(std::lround(std::fmin(255, std::fmax(0, v))));
      }
    }
  }
  return img;
}

// Uniform noise: the worst case for every block format.
inline std::vector<uint8_t> noise_image(int w, int h, int channels, uint32_t seed) {
  std::vector<uint8_t> img(size_t(w) * h * channels);
  Rng rng(seed);
  for (auto& v : img) v = uint8_t(rng.next() >> 24);
  return img;
}

// Diagonal gradients, a different direction per channel.
inline std::vector<uint8_t> gradient_image(int w, int h, int channels) {
  std::vector<uint8_t> img(size_t(w) * h * channels);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < channels; ++c) {
        const int v = c == 0   ? x * 255 / (w - 1)
                      : c == 1 ? y * 255 / (h - 1)
                               : (x + y) * 255 / (w + h - 2);
        img[(size_t(y) * w + x) * channels + c] = uint8_t(c == 3 ? 255 - v : v);
      }
    }
  }
  return img;
}

inline double mse(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, int channels,
                  int use_channels) {
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < a.size(); i += channels) {
    for (int c = 0; c < use_channels; ++c) {
      const double d = double(a[i + c]) - double(b[i + c]);
      sum += d * d;
      ++n;
    }
  }
  return sum / double(n);
}

inline double psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, int channels,
                   int use_channels) {
  const double m = mse(a, b, channels, use_channels);
  return m > 0 ? 10 * std::log10(255.0 * 255.0 / m) : 100.0;
}

inline int max_abs(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, int channels,
                   int use_channels) {
  int worst = 0;
  for (size_t i = 0; i < a.size(); i += channels) {
    for (int c = 0; c < use_channels; ++c) {
      worst = std::max(worst, std::abs(int(a[i + c]) - int(b[i + c])));
    }
  }
  return worst;
}

}  // namespace vt::test
