#include "render/camera.h"

#include <algorithm>
#include <cmath>

namespace vt::render {
namespace {

Vec3 sub(Vec3 a, Vec3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
float dot(Vec3 a, Vec3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
Vec3 normalize(Vec3 a) {
  float l = std::sqrt(dot(a, a));
  return l > 0 ? Vec3{a.x / l, a.y / l, a.z / l} : Vec3{0, 0, 1};
}

}  // namespace

Mat4 Mat4::identity() {
  Mat4 r;
  r.m[0] = r.m[5] = r.m[10] = r.m[15] = 1.0f;
  return r;
}

Mat4 Mat4::operator*(const Mat4& b) const {
  Mat4 r;
  for (int c = 0; c < 4; ++c) {
    for (int row = 0; row < 4; ++row) {
      float s = 0;
      for (int k = 0; k < 4; ++k) s += m[k * 4 + row] * b.m[c * 4 + k];
      r.m[c * 4 + row] = s;
    }
  }
  return r;
}

Mat4 look_at(Vec3 eye, Vec3 target, Vec3 up) {
  Vec3 f = normalize(sub(target, eye));
  Vec3 s = normalize(cross(f, up));
  Vec3 u = cross(s, f);
  Mat4 r = Mat4::identity();
  r.m[0] = s.x, r.m[4] = s.y, r.m[8] = s.z;
  r.m[1] = u.x, r.m[5] = u.y, r.m[9] = u.z;
  r.m[2] = -f.x, r.m[6] = -f.y, r.m[10] = -f.z;
  r.m[12] = -dot(s, eye);
  r.m[13] = -dot(u, eye);
  r.m[14] = dot(f, eye);
  return r;
}

Mat4 perspective(float fov_y, float aspect, float n, float f) {
  float t = 1.0f / std::tan(fov_y * 0.5f);
  Mat4 r;
  r.m[0] = t / aspect;
  r.m[5] = -t;  // Vulkan clip space has y pointing down
  r.m[10] = f / (n - f);
  r.m[11] = -1.0f;
  r.m[14] = n * f / (n - f);
  return r;
}

Mat4 jitter(const Mat4& vp, float dx, float dy, int width, int height) {
  // clip.x += (2 dx / width) * clip.w: add a multiple of row 3 to row 0 (likewise y).
  Mat4 r = vp;
  float ox = 2.0f * dx / float(width);
  float oy = 2.0f * dy / float(height);
  for (int c = 0; c < 4; ++c) {
    r.m[c * 4 + 0] += ox * vp.m[c * 4 + 3];
    r.m[c * 4 + 1] += oy * vp.m[c * 4 + 3];
  }
  return r;
}

std::vector<Camera> orbit_views(Vec3 lo, Vec3 hi, int count, float aspect) {
  Vec3 c{(lo.x + hi.x) * 0.5f, (lo.y + hi.y) * 0.5f, (lo.z + hi.z) * 0.5f};
  Vec3 ext = sub(hi, lo);
  float radius = std::max(0.5f * std::sqrt(dot(ext, ext)), 1e-3f);
  const float fov = 0.9f;
  std::vector<Camera> views;
  for (int i = 0; i < count; ++i) {
    // Cycle through distance (frontal, close-up, distant) and elevation (grazing at low angles).
    float azimuth = 0.7f + 2.399963f * float(i);  // golden angle: no two views alike
    static const float kDist[] = {1.6f, 0.8f, 4.0f, 1.5f};
    static const float kElev[] = {0.6f, 0.9f, 0.5f, 0.12f};
    float d = radius * kDist[i % 4];
    float e = kElev[i % 4];
    Vec3 eye{c.x + d * std::cos(e) * std::cos(azimuth), c.y + d * std::sin(e),
             c.z + d * std::cos(e) * std::sin(azimuth)};
    Camera cam;
    cam.view_proj =
        perspective(fov, aspect, std::max(d - radius * 1.5f, d * 0.01f), d + radius * 2.0f) *
        look_at(eye, c, {0, 1, 0});
    views.push_back(cam);
  }
  return views;
}

}  // namespace vt::render
