// Reference atlas texels by brute force, for the transfer tests and benchmarks: no gtest here.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include "scene/scene.h"

namespace vt::test {

// For each texel of a W x H atlas (the primitive's last UV set), the mean of f(u, v) (u, v in
// TEXCOORD_0) over samples x samples points spread inside the texel, where every point lies in
// some triangle's atlas footprint; NaN for texels that reach past the footprint.
inline std::vector<double> atlas_reference(const scene::Primitive& p, uint32_t W, uint32_t H,
                                           int samples,
                                           const std::function<double(double u, double v)>& f) {
  std::vector<double> out(size_t(W) * H, NAN);
  const auto& atlas = p.uvs.back();
  const auto& uv = p.uvs[0];
  for (uint32_t y = 0; y < H; ++y) {
    for (uint32_t x = 0; x < W; ++x) {
      double sum = 0;
      bool all_in = true;
      for (int j = 0; j < samples && all_in; ++j) {
        for (int i = 0; i < samples && all_in; ++i) {
          double px = (x + (i + 0.5) / samples) / W, py = (y + (j + 0.5) / samples) / H;
          all_in = false;
          for (size_t t = 0; t + 2 < p.indices.size(); t += 3) {
            const auto &a = atlas[p.indices[t]], &b = atlas[p.indices[t + 1]],
                       &c = atlas[p.indices[t + 2]];
            double d = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            double l1 = ((px - a[0]) * (c[1] - a[1]) - (py - a[1]) * (c[0] - a[0])) / d;
            double l2 = ((b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0])) / d;
            if (l1 < 0 || l2 < 0 || l1 + l2 > 1) continue;
            const auto &ua = uv[p.indices[t]], &ub = uv[p.indices[t + 1]],
                       &uc = uv[p.indices[t + 2]];
            sum += f(ua[0] + l1 * (ub[0] - ua[0]) + l2 * (uc[0] - ua[0]),
                     ua[1] + l1 * (ub[1] - ua[1]) + l2 * (uc[1] - ua[1]));
            all_in = true;
            break;
          }
        }
      }
      if (all_in) out[size_t(y) * W + x] = sum / (samples * samples);
    }
  }
  return out;
}

}  // namespace vt::test
