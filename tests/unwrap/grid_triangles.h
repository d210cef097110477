// Test meshes in atlas texel space shared by the rasteriser and transfer tests.
#pragma once

#include <array>
#include <vector>

namespace vt::test {

// The triangles of an n x n grid of quads over (n + 1)^2 row-major vertices, each quad split
// along alternating diagonals with alternating winding so both orientations are exercised.
// Neighbouring triangles share edges exactly.
inline std::vector<std::array<double, 6>> grid_triangles(
    const std::vector<std::array<double, 2>>& v, int n) {
  std::vector<std::array<double, 6>> t;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      auto a = v[j * (n + 1) + i], b = v[j * (n + 1) + i + 1], c = v[(j + 1) * (n + 1) + i],
           e = v[(j + 1) * (n + 1) + i + 1];
      if ((i + j) % 2) {
        t.push_back({a[0], a[1], b[0], b[1], e[0], e[1]});
        t.push_back({a[0], a[1], c[0], c[1], e[0], e[1]});
      } else {
        t.push_back({a[0], a[1], c[0], c[1], b[0], b[1]});
        t.push_back({b[0], b[1], c[0], c[1], e[0], e[1]});
      }
    }
  }
  return t;
}

}  // namespace vt::test
