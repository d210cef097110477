// Cameras for the validation renderer: column-major 4x4 matrices in Vulkan's clip conventions
// (y down, depth 0..1), and the automatic views around a scene's bounds.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "common/status.h"
#include "common/vec.h"

namespace vt::render {

// Column-major: m[column * 4 + row], as GLSL's mat4 reads it from push constants.
struct Mat4 {
  std::array<float, 16> m{};
  static Mat4 identity();
  Mat4 operator*(const Mat4& b) const;
};

// Right-handed view looking from `eye` towards `target`.
Mat4 look_at(Vec3f eye, Vec3f target, Vec3f up);
// Right-handed perspective with Vulkan's y-down clip space and depth in [0, 1].
Mat4 perspective(float fov_y_radians, float aspect, float z_near, float z_far);
// Shifts the image by (dx, dy) pixels of a width x height target (sub-pixel jitter).
Mat4 jitter(const Mat4& view_proj, float dx, float dy, int width, int height);

struct Camera {
  Mat4 view_proj = Mat4::identity();
};

// Views around an axis-aligned box, +Y up: a frontal view, close-ups (fine levels), grazing
// views (anisotropic footprints) and a distant view (coarse levels). Deterministic. For the
// renderer's own tests; scenes get render/view_planner.h (up axis from the data, views framed on
// the surfaces).
std::vector<Camera> orbit_views(Vec3f bounds_min, Vec3f bounds_max, int count, float aspect);

// Camera file (`vtbake validate --cameras FILE.json`), in the scene's world units:
//
//   {"cameras": [{"eye": [0, 6, 8], "target": [0, 0, 0], "up": [0, 1, 0],
//                 "fov_y_deg": 50, "near": 0.1, "far": 100}]}
//
// "eye" and "target" are required; "up" defaults to [0, 1, 0], "fov_y_deg" (vertical field of
// view, degrees, in (0, 180)) to 50, "near" to 1/100 and "far" to 100 times the eye-target
// distance. 1 to 256 cameras. Unknown keys are errors, so a misspelt key is not silently
// replaced by its default. The aspect ratio comes from the render size.
struct CameraSpec {
  Vec3f eye, target, up{0, 1, 0};
  float fov_y_deg = 50.0f;
  float z_near = 0, z_far = 0;  // 0 = derived from the eye-target distance
};
inline constexpr size_t kMaxFileCameras = 256;

// The camera of a spec, or kInvalidArgument naming the problem (eye == target, up parallel to
// the view direction, fov outside (0, 180), near <= 0, far <= near, non-finite matrix).
Expected<Camera> camera_from_spec(const CameraSpec& spec, float aspect);
// Parses a camera file's text; errors start with `name` (the file name) and the camera index.
Expected<std::vector<Camera>> parse_cameras_json(std::string_view text, const std::string& name,
                                                 float aspect);
// Reads and parses a camera file (at most 1 MiB).
Expected<std::vector<Camera>> load_cameras_json(const std::string& path, float aspect);

}  // namespace vt::render
