// Cameras for the validation renderer: column-major 4x4 matrices in Vulkan's clip conventions
// (y down, depth 0..1), and the automatic views around a scene's bounds.
#pragma once

#include <array>
#include <vector>

namespace vt::render {

struct Vec3 {
  float x = 0, y = 0, z = 0;
};

// Column-major: m[column * 4 + row], as GLSL's mat4 reads it from push constants.
struct Mat4 {
  std::array<float, 16> m{};
  static Mat4 identity();
  Mat4 operator*(const Mat4& b) const;
};

// Right-handed view looking from `eye` towards `target`.
Mat4 look_at(Vec3 eye, Vec3 target, Vec3 up);
// Right-handed perspective with Vulkan's y-down clip space and depth in [0, 1].
Mat4 perspective(float fov_y_radians, float aspect, float z_near, float z_far);
// Shifts the image by (dx, dy) pixels of a width x height target (sub-pixel jitter).
Mat4 jitter(const Mat4& view_proj, float dx, float dy, int width, int height);

struct Camera {
  Mat4 view_proj = Mat4::identity();
};

// Views around an axis-aligned box: a frontal view, close-ups (fine levels), grazing views
// (anisotropic footprints) and a distant view (coarse levels). Deterministic.
std::vector<Camera> orbit_views(Vec3 bounds_min, Vec3 bounds_max, int count, float aspect);

}  // namespace vt::render
