#include "scene/material_rules.h"

#include <algorithm>
#include <cmath>
#include <functional>

namespace vt::scene {

std::string material_label(const std::string& name, int64_t index) {
  if (!name.empty()) return "material '" + name + "'";
  if (index < 0) return "the default material";
  return "material " + std::to_string(index) + " (unnamed)";
}

std::string material_label(const Scene& scene, const Material& m) {
  const Material* first = scene.materials.data();
  const bool listed =
      !std::less<>()(&m, first) && std::less<>()(&m, first + scene.materials.size());
  return material_label(m.name, listed ? &m - first : -1);
}

const std::vector<Vec2>* texture_uv_set(const Primitive& p, const TextureRef& ref) {
  if (ref.texcoord < 0 || size_t(ref.texcoord) >= p.uvs.size()) return nullptr;
  const std::vector<Vec2>& set = p.uvs[ref.texcoord];
  return set.size() == p.positions.size() ? &set : nullptr;
}

std::array<double, 2> texture_uv(const TextureRef& ref, double u, double v) {
  return ref.transform.apply(u, v);
}

std::array<double, 4> texture_uv_derivatives(const TextureRef& ref, std::array<double, 4> d) {
  if (ref.transform.identity()) return d;
  const auto m = ref.transform.matrix();
  for (int k = 0; k < 4; k += 2) {
    const double du = d[k], dv = d[k + 1];
    d[k] = m[0] * du + m[2] * dv, d[k + 1] = m[1] * du + m[3] * dv;
  }
  return d;
}

double wrap_coordinate(WrapMode mode, double x) {
  switch (mode) {
    case WrapMode::kClampToEdge:
      return std::fmin(std::fmax(x, 0.0), 1.0);
    case WrapMode::kMirroredRepeat: {
      const double period = x - 2.0 * std::floor(x * 0.5);  // [0, 2)
      return period <= 1.0 ? period : 2.0 - period;
    }
    case WrapMode::kRepeat:
      break;
  }
  return x - std::floor(x);
}

int64_t wrap_texel(WrapMode mode, int64_t i, int64_t n) {
  switch (mode) {
    case WrapMode::kClampToEdge:
      return std::clamp<int64_t>(i, 0, n - 1);
    case WrapMode::kMirroredRepeat: {
      int64_t m = i % (2 * n);
      if (m < 0) m += 2 * n;
      return m < n ? m : 2 * n - 1 - m;
    }
    case WrapMode::kRepeat:
      break;
  }
  const int64_t m = i % n;
  return m < 0 ? m + n : m;
}

float alpha_test_cutoff(const Material& m) {
  return m.alpha_mode == AlphaMode::kMask ? m.alpha_cutoff : -1.0f;
}

}  // namespace vt::scene
