#include "render/camera.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

namespace vt::render {
namespace {

// Unit length by division, +z for a zero vector (the renderer's own rule: common/vec.h's
// normalized multiplies by the reciprocal).
Vec3f normalize(Vec3f a) {
  float l = length(a);
  return l > 0 ? a / l : Vec3f{0, 0, 1};
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

Mat4 look_at(Vec3f eye, Vec3f target, Vec3f up) {
  Vec3f f = normalize(target - eye);
  Vec3f s = normalize(cross(f, up));
  Vec3f u = cross(s, f);
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

std::vector<Camera> orbit_views(Vec3f lo, Vec3f hi, int count, float aspect) {
  Vec3f c{(lo.x + hi.x) * 0.5f, (lo.y + hi.y) * 0.5f, (lo.z + hi.z) * 0.5f};
  Vec3f ext = hi - lo;
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
    Vec3f eye{c.x + d * std::cos(e) * std::cos(azimuth), c.y + d * std::sin(e),
              c.z + d * std::cos(e) * std::sin(azimuth)};
    Camera cam;
    cam.view_proj =
        perspective(fov, aspect, std::max(d - radius * 1.5f, d * 0.01f), d + radius * 2.0f) *
        look_at(eye, c, {0, 1, 0});
    views.push_back(cam);
  }
  return views;
}

namespace {

constexpr size_t kMaxCameraFileBytes = 1 << 20;

bool finite(Vec3f v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

std::string fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// A finite number that also fits a float (JSON's doubles go up to 1.8e308).
Status read_number(const nlohmann::json& j, const char* key, float* out) {
  if (!j.is_number())
    return Error(ErrorCode::kInvalidArgument, std::string(key) + ": not a number");
  const double d = j.get<double>();
  if (!std::isfinite(d) || !std::isfinite(float(d))) {
    return Error(ErrorCode::kInvalidArgument,
                 std::string(key) + ": not a finite float (" + fmt(d) + ")");
  }
  *out = float(d);
  return Status::Ok();
}

Status read_vec3(const nlohmann::json& j, const char* key, Vec3f* out) {
  if (!j.is_array() || j.size() != 3) {
    return Error(ErrorCode::kInvalidArgument, std::string(key) + ": expected [x, y, z]");
  }
  float v[3];
  for (int i = 0; i < 3; ++i) {
    VT_RETURN_IF_ERROR(read_number(j[i], key, &v[i]));
  }
  *out = {v[0], v[1], v[2]};
  return Status::Ok();
}

Expected<CameraSpec> read_spec(const nlohmann::json& j) {
  if (!j.is_object()) return Error(ErrorCode::kInvalidArgument, "not an object");
  for (const auto& [key, value] : j.items()) {
    static const char* const kKeys[] = {"eye", "target", "up", "fov_y_deg", "near", "far"};
    if (std::find(std::begin(kKeys), std::end(kKeys), key) == std::end(kKeys)) {
      return Error(ErrorCode::kInvalidArgument,
                   "unknown key \"" + key + "\" (expected eye, target, up, fov_y_deg, near, far)");
    }
  }
  CameraSpec spec;
  for (const char* key : {"eye", "target"}) {
    if (!j.contains(key)) {
      return Error(ErrorCode::kInvalidArgument, std::string("missing \"") + key + "\"");
    }
  }
  VT_RETURN_IF_ERROR(read_vec3(j["eye"], "eye", &spec.eye));
  VT_RETURN_IF_ERROR(read_vec3(j["target"], "target", &spec.target));
  if (j.contains("up")) VT_RETURN_IF_ERROR(read_vec3(j["up"], "up", &spec.up));
  if (j.contains("fov_y_deg"))
    VT_RETURN_IF_ERROR(read_number(j["fov_y_deg"], "fov_y_deg", &spec.fov_y_deg));
  if (j.contains("near")) {
    VT_RETURN_IF_ERROR(read_number(j["near"], "near", &spec.z_near));
    if (!(spec.z_near > 0)) return Error(ErrorCode::kInvalidArgument, "near must be > 0");
  }
  if (j.contains("far")) {
    VT_RETURN_IF_ERROR(read_number(j["far"], "far", &spec.z_far));
    if (!(spec.z_far > 0)) return Error(ErrorCode::kInvalidArgument, "far must be > 0");
  }
  return spec;
}

}  // namespace

Expected<Camera> camera_from_spec(const CameraSpec& spec, float aspect) {
  auto bad = [](const std::string& why) { return Error(ErrorCode::kInvalidArgument, why); };
  if (!finite(spec.eye) || !finite(spec.target) || !finite(spec.up)) {
    return bad("eye, target and up must be finite");
  }
  if (!(aspect > 0) || !std::isfinite(aspect)) return bad("aspect ratio must be positive");
  if (!(spec.fov_y_deg > 0 && spec.fov_y_deg < 180)) {
    return bad("fov_y_deg must be in (0, 180), got " + fmt(spec.fov_y_deg));
  }
  // In double: coordinates near FLT_MAX would overflow the float difference.
  const double dx = double(spec.target.x) - spec.eye.x, dy = double(spec.target.y) - spec.eye.y,
               dz = double(spec.target.z) - spec.eye.z;
  const double dist = std::sqrt(dx * dx + dy * dy + dz * dz);
  const double scale = std::max({std::abs(double(spec.eye.x)), std::abs(double(spec.eye.y)),
                                 std::abs(double(spec.eye.z)), 1e-30});
  // Closer than float resolution at the eye's magnitude: no usable view direction.
  if (!(dist > scale * 1e-6)) return bad("eye and target coincide");
  const double ul = std::sqrt(double(spec.up.x) * spec.up.x + double(spec.up.y) * spec.up.y +
                              double(spec.up.z) * spec.up.z);
  if (!(ul > 0)) return bad("up must not be zero");
  const double cx = dy * spec.up.z - dz * spec.up.y, cy = dz * spec.up.x - dx * spec.up.z,
               cz = dx * spec.up.y - dy * spec.up.x;
  // sin(angle between up and the view direction) below ~0.06 degrees: the roll is undefined.
  if (!(std::sqrt(cx * cx + cy * cy + cz * cz) > 1e-3 * dist * ul)) {
    return bad("up is parallel to the view direction");
  }
  const float z_near = spec.z_near > 0 ? spec.z_near : float(dist * 0.01);
  const float z_far = spec.z_far > 0 ? spec.z_far : float(dist * 100.0);
  if (!(z_near > 0)) return bad("near must be > 0");
  if (!(z_far > z_near)) {
    return bad("far (" + fmt(z_far) + ") must be greater than near (" + fmt(z_near) + ")");
  }
  Camera cam;
  cam.view_proj =
      perspective(spec.fov_y_deg * std::numbers::pi_v<float> / 180.0f, aspect, z_near, z_far) *
      look_at(spec.eye, spec.target, spec.up);
  for (float v : cam.view_proj.m) {
    if (!std::isfinite(v))
      return bad("the view-projection matrix is not finite (values too large?)");
  }
  return cam;
}

Expected<std::vector<Camera>> parse_cameras_json(std::string_view text, const std::string& name,
                                                 float aspect) {
  auto bad = [&](const std::string& why) {
    return Error(ErrorCode::kInvalidArgument, name + ": " + why);
  };
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text.begin(), text.end());
  } catch (const nlohmann::json::exception& e) {
    return bad(std::string("not valid JSON: ") + e.what());
  }
  if (!doc.is_object() || !doc.contains("cameras")) {
    return bad("expected an object {\"cameras\": [...]}");
  }
  for (const auto& [key, value] : doc.items()) {
    if (key != "cameras") return bad("unknown key \"" + key + "\" (expected \"cameras\")");
  }
  const nlohmann::json& list = doc["cameras"];
  if (!list.is_array()) return bad("\"cameras\" must be an array");
  if (list.empty()) return bad("\"cameras\" is empty");
  if (list.size() > kMaxFileCameras) {
    return bad(std::to_string(list.size()) + " cameras, at most " +
               std::to_string(kMaxFileCameras));
  }
  std::vector<Camera> cameras;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string where = "camera " + std::to_string(i);
    auto spec = read_spec(list[i]);
    if (!spec.ok()) return spec.status().with_context(name + ": " + where);
    auto cam = camera_from_spec(*spec, aspect);
    if (!cam.ok()) return cam.status().with_context(name + ": " + where);
    cameras.push_back(*cam);
  }
  return cameras;
}

Expected<std::vector<Camera>> load_cameras_json(const std::string& path, float aspect) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return Error(ErrorCode::kNotFound, path + ": cannot open camera file");
  std::string text;
  char buf[65536];
  while (f.read(buf, sizeof buf) || f.gcount() > 0) {
    text.append(buf, size_t(f.gcount()));
    if (text.size() > kMaxCameraFileBytes) {
      return Error(ErrorCode::kInvalidArgument, path + ": camera file larger than 1 MiB");
    }
  }
  if (f.bad()) return Error(ErrorCode::kIo, path + ": read failed");
  return parse_cameras_json(text, path, aspect);
}

}  // namespace vt::render
