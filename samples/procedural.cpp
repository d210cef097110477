#include "samples/procedural.h"

#include <algorithm>
#include <cmath>

#include <xxhash.h>

#include "common/hash.h"

namespace vt {
namespace {

inline float unorm8(int v) {
  return float(std::clamp(v, 0, 255)) / 255.0f;
}

}  // namespace

ProceduralImageSource::ProceduralImageSource(ProceduralPattern pattern, uint32_t width,
                                             uint32_t height, uint32_t channels, uint32_t seed)
    : pattern_(pattern), seed_(seed) {
  info_.width = width;
  info_.height = height;
  info_.channels = std::clamp<uint32_t>(channels, 1, 4);
  info_.is_float = false;
  info_.alpha_channel = info_.channels == 4 ? 3 : -1;
  info_.color_space = pattern == ProceduralPattern::kAlbedo ? "sRGB" : "raw";
}

Expected<uint64_t> ProceduralImageSource::content_hash() {
  const uint32_t parts[5] = {uint32_t(pattern_), info_.width, info_.height, info_.channels, seed_};
  return XXH3_64bits(parts, sizeof parts);
}

Status ProceduralImageSource::read_rows(uint32_t y0, uint32_t y1, float* out) {
  if (y0 > y1 || y1 > info_.height) {
    return Error(ErrorCode::kInvalidArgument, "procedural image: rows out of range");
  }
  const uint32_t w = info_.width, h = info_.height, ch = info_.channels;
  for (uint32_t y = y0; y < y1; ++y) {
    float* row = out + size_t(y - y0) * w * ch;
    for (uint32_t x = 0; x < w; ++x) {
      float* t = row + size_t(x) * ch;
      int v[4];
      if (pattern_ == ProceduralPattern::kAlbedo) {
        // Flat region (constant pages), then gradient + cells + lines + texel noise.
        if (x < w / 8 && y < h / 8) {
          v[0] = 200, v[1] = 120, v[2] = 40;
        } else {
          int gx = int(uint64_t(x) * 160 / w), gy = int(uint64_t(y) * 160 / h);
          uint32_t cell = hash2d(x / 37, y / 37, seed_);
          int noise = int(hash2d(x, y, seed_ + 1) & 31) - 16;
          bool line = (x % 16) == 0 || (y % 16) == 0;
          v[0] = gx + int(cell & 63) + noise;
          v[1] = gy + int((cell >> 8) & 63) + noise;
          v[2] = 96 + int((cell >> 16) & 63) - noise;
          if (line) v[0] /= 2, v[1] /= 2, v[2] /= 2;
        }
        uint64_t dx = x > w / 2 ? x - w / 2 : w / 2 - x, dy = y > h / 2 ? y - h / 2 : h / 2 - y;
        v[3] = 255 - int(std::min<uint64_t>(255, (dx + dy) * 255 / (uint64_t(w + h) / 2 + 1)));
        for (uint32_t c = 0; c < ch; ++c) t[c] = unorm8(ch <= 2 && c == 1 ? v[3] : v[c]);
      } else {
        // Height field of hashed bumps per 64-texel cell plus ridges; normal from its slope.
        auto height_at = [&](double fx, double fy) {
          return 6.0 * std::sin(fx * 0.05) * std::cos(fy * 0.07) + 2.0 * std::sin((fx + fy) * 0.4);
        };
        double dhx = height_at(x + 1.0, y) - height_at(x - 1.0, y);
        double dhy = height_at(x, y + 1.0) - height_at(x, y - 1.0);
        double nx = -dhx * 0.5, ny = -dhy * 0.5, nz = 1.0;
        double len = std::sqrt(nx * nx + ny * ny + nz * nz);
        double n[3] = {nx / len, ny / len, nz / len};
        for (uint32_t c = 0; c < ch; ++c) {
          t[c] = c < 3 ? unorm8(int(std::lround((n[c] * 0.5 + 0.5) * 255.0))) : 1.0f;
        }
      }
    }
  }
  return Status::Ok();
}

}  // namespace vt
