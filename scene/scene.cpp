// Scene hierarchy flattening, geometry validation and matrix helpers.
#include "scene/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string>

namespace vt::scene {

const char* Image::embedded_extension() const {
  const auto starts = [&](std::initializer_list<uint8_t> magic, size_t at = 0) {
    if (bytes.size() < at + magic.size()) return false;
    return std::equal(magic.begin(), magic.end(), bytes.begin() + std::ptrdiff_t(at));
  };
  if (mime_type == "image/jpeg" || starts({0xFF, 0xD8})) return ".jpg";
  if (mime_type == "image/x-exr" || starts({0x76, 0x2F, 0x31, 0x01})) return ".exr";
  if (mime_type == "image/webp" ||
      (starts({'R', 'I', 'F', 'F'}) && starts({'W', 'E', 'B', 'P'}, 8)))
    return ".webp";
  return ".png";
}

std::array<double, 6> TextureTransform::matrix() const {
  double c = std::cos(double(rotation)), s = std::sin(double(rotation));
  // Rotation [c s; -s c] (row-major) after the scale: the sign that makes the extension's own
  // example (offset [0, 1], rotation pi/2, scale 0.5) pick the lower-left quadrant.
  return {c * scale[0], -s * scale[0], s * scale[1], c * scale[1], offset[0], offset[1]};
}

std::array<double, 2> TextureTransform::apply(double u, double v) const {
  if (identity()) return {u, v};
  auto m = matrix();
  return {m[0] * u + m[2] * v + m[4], m[1] * u + m[3] * v + m[5]};
}

Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[c * 4 + k];
      r[c * 4 + row] = s;
    }
  return r;
}

std::array<double, 3> transform_point(const Mat4& m, const Vec3& p) {
  std::array<double, 3> r;
  for (int i = 0; i < 3; ++i) r[i] = m[i] * p[0] + m[4 + i] * p[1] + m[8 + i] * p[2] + m[12 + i];
  return r;
}

std::array<double, 3> transform_direction(const Mat4& m, const Vec3& d) {
  // Cofactor matrix of the upper 3x3 = inverse-transpose times the determinant: defined for
  // singular matrices too, and the scale does not matter for a direction, but the
  // determinant's sign does: a mirror's cofactors would turn the normal to the other side.
  auto a = [&](int row, int col) { return m[col * 4 + row]; };
  double c[3][3];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) {
      int r1 = (r + 1) % 3, r2 = (r + 2) % 3, k1 = (k + 1) % 3, k2 = (k + 2) % 3;
      c[r][k] = a(r1, k1) * a(r2, k2) - a(r1, k2) * a(r2, k1);
    }
  const double sign = mirrors(m) ? -1.0 : 1.0;
  std::array<double, 3> out;
  for (int r = 0; r < 3; ++r) out[r] = sign * (c[r][0] * d[0] + c[r][1] * d[1] + c[r][2] * d[2]);
  double len = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
  if (len > 0)
    for (double& v : out) v /= len;
  return out;
}

bool mirrors(const Mat4& m) {
  return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
             m[8] * (m[1] * m[6] - m[5] * m[2]) <
         0;
}

std::array<double, 3> transform_vector(const Mat4& m, const Vec3& d) {
  std::array<double, 3> out;
  for (int i = 0; i < 3; ++i) out[i] = m[i] * d[0] + m[4 + i] * d[1] + m[8 + i] * d[2];
  double len = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
  if (len > 0 && std::isfinite(len))
    for (double& v : out) v /= len;
  else
    out = {0, 0, 0};
  return out;
}

namespace {

// Calls visit(node index, world matrix) for every node below `roots`, depth first, once each
// (a node reached twice or a cycle is visited once).
template <class Visit>
void walk_nodes(const Scene& scene, Visit&& visit) {
  const std::vector<Node>& nodes = scene.nodes;
  std::vector<char> visited(nodes.size(), 0);
  struct Item {
    int node;
    Mat4 parent;
  };
  std::vector<Item> stack;
  for (auto it = scene.roots.rbegin(); it != scene.roots.rend(); ++it)
    stack.push_back({*it, kIdentity});
  while (!stack.empty()) {
    Item item = stack.back();
    stack.pop_back();
    if (item.node < 0 || item.node >= static_cast<int>(nodes.size()) || visited[item.node])
      continue;
    visited[item.node] = 1;
    const Node& node = nodes[item.node];
    Mat4 world = multiply(item.parent, node.local);
    visit(item.node, world);
    for (auto it = node.children.rbegin(); it != node.children.rend(); ++it)
      stack.push_back({*it, world});
  }
}

}  // namespace

std::vector<Instance> Scene::instances() const {
  std::vector<Instance> result;
  walk_nodes(*this, [&](int n, const Mat4& world) {
    const int mesh = nodes[n].mesh;
    if (mesh >= 0 && mesh < static_cast<int>(meshes.size())) result.push_back({mesh, n, world});
  });
  return result;
}

std::vector<PlacedLight> Scene::placed_lights() const {
  std::vector<PlacedLight> result;
  walk_nodes(*this, [&](int n, const Mat4& world) {
    const int light = nodes[n].light;
    if (light < 0 || light >= static_cast<int>(lights.size())) return;
    PlacedLight p;
    p.light = light, p.node = n;
    p.position = {world[12], world[13], world[14]};
    p.direction = transform_vector(world, {0, 0, -1});
    result.push_back(p);
  });
  return result;
}

Status check_light(const Light& l) {
  auto bad = [](const std::string& what) { return Error(ErrorCode::kInvalidArgument, what); };
  auto num = [](double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", v);
    return std::string(b);
  };
  for (float c : l.color)
    if (!std::isfinite(c) || c < 0) return bad("color component " + num(c) + " is not >= 0");
  if (!std::isfinite(l.intensity) || l.intensity < 0)
    return bad("intensity " + num(l.intensity) + " is not a number >= 0");
  if (l.type == LightType::kDirectional) return Status::Ok();
  if (!(l.range > 0)) return bad("range " + num(l.range) + " is not > 0");
  if (l.type != LightType::kSpot) return Status::Ok();
  const double kHalfPi = 1.57079632679489661923;
  if (!std::isfinite(l.inner_cone_angle) || l.inner_cone_angle < 0)
    return bad("innerConeAngle " + num(l.inner_cone_angle) + " is not >= 0");
  if (!std::isfinite(l.outer_cone_angle) || l.outer_cone_angle > kHalfPi + 1e-6)
    return bad("outerConeAngle " + num(l.outer_cone_angle) + " is not <= pi / 2");
  if (!(l.inner_cone_angle < l.outer_cone_angle))
    return bad("innerConeAngle " + num(l.inner_cone_angle) + " is not below outerConeAngle " +
               num(l.outer_cone_angle));
  return Status::Ok();
}

size_t Scene::triangle_count() const {
  size_t n = 0;
  for (const Mesh& m : meshes)
    for (const Primitive& p : m.primitives) n += p.triangle_count();
  return n;
}

Status validate_geometry(const Scene& scene) {
  for (size_t mi = 0; mi < scene.meshes.size(); ++mi) {
    const Mesh& mesh = scene.meshes[mi];
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const Primitive& p = mesh.primitives[pi];
      std::string where = "mesh '" + (mesh.name.empty() ? std::to_string(mi) : mesh.name) +
                          "' primitive " + std::to_string(pi);
      if (!scene.source_path.empty()) where = scene.source_path + ": " + where;
      for (size_t v = 0; v < p.positions.size(); ++v)
        for (float c : p.positions[v])
          if (!std::isfinite(c))
            return Error(ErrorCode::kCorrupt,
                         where + ": vertex " + std::to_string(v) + " has a non-finite position");
      if (p.indices.size() % 3 != 0)
        return Error(ErrorCode::kCorrupt, where + ": index count " +
                                              std::to_string(p.indices.size()) +
                                              " is not a multiple of 3");
      for (size_t i = 0; i < p.indices.size(); ++i)
        if (p.indices[i] >= p.positions.size())
          return Error(ErrorCode::kCorrupt, where + ": triangle " + std::to_string(i / 3) +
                                                " uses vertex " + std::to_string(p.indices[i]) +
                                                " of " + std::to_string(p.positions.size()));
      auto check = [&](size_t n, const char* what) -> Status {
        if (n != 0 && n != p.positions.size())
          return Error(ErrorCode::kCorrupt, where + ": " + what + " has " + std::to_string(n) +
                                                " entries for " +
                                                std::to_string(p.positions.size()) + " vertices");
        return Status::Ok();
      };
      VT_RETURN_IF_ERROR(check(p.normals.size(), "NORMAL"));
      VT_RETURN_IF_ERROR(check(p.tangents.size(), "TANGENT"));
      VT_RETURN_IF_ERROR(check(p.colors.size(), "COLOR_0"));
      for (const auto& uv : p.uvs) VT_RETURN_IF_ERROR(check(uv.size(), "TEXCOORD"));
      for (size_t set = 0; set < p.uvs.size(); ++set)
        for (size_t v = 0; v < p.uvs[set].size(); ++v)
          if (!std::isfinite(p.uvs[set][v][0]) || !std::isfinite(p.uvs[set][v][1]))
            return Error(ErrorCode::kCorrupt,
                         where + ": vertex " + std::to_string(v) + " has a non-finite TEXCOORD_" +
                             std::to_string(set) + " (it would sample nothing: fix the UVs)");
    }
  }
  return Status::Ok();
}

}  // namespace vt::scene
