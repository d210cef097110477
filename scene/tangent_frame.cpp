#include "scene/tangent_frame.h"

#include <cmath>

#include "common/vec.h"

namespace vt::scene {
namespace {

Vec3d v3(const Vec3& a) {
  return {a[0], a[1], a[2]};
}

}  // namespace

std::vector<Vec4> compute_tangents(const Primitive& p, const std::vector<Vec3>& normals,
                                   int uv_set) {
  size_t n = p.positions.size();
  std::vector<Vec3d> tsum(n), bsum(n);
  const auto& uv = p.uvs[uv_set];
  for (size_t f = 0; f + 2 < p.indices.size(); f += 3) {
    uint32_t i0 = p.indices[f], i1 = p.indices[f + 1], i2 = p.indices[f + 2];
    Vec3d e1 = v3(p.positions[i1]) - v3(p.positions[i0]),
          e2 = v3(p.positions[i2]) - v3(p.positions[i0]);
    double du1 = uv[i1][0] - uv[i0][0], dv1 = uv[i1][1] - uv[i0][1];
    double du2 = uv[i2][0] - uv[i0][0], dv2 = uv[i2][1] - uv[i0][1];
    double det = du1 * dv2 - du2 * dv1;
    if (!(std::abs(det) > 1e-20)) continue;
    Vec3d dpdu = (e1 * dv2 - e2 * dv1) * (1.0 / det);
    Vec3d dpdv = (e2 * du1 - e1 * du2) * (1.0 / det);
    double area = std::sqrt(dot(cross(e1, e2), cross(e1, e2)));
    Vec3d tu = normalized(dpdu, {}) * area, tv = normalized(dpdv, {}) * area;
    for (uint32_t i : {i0, i1, i2}) tsum[i] = tsum[i] + tu, bsum[i] = bsum[i] - tv;
  }
  std::vector<Vec4> out(n);
  for (size_t i = 0; i < n; ++i) {
    Vec3d nn = normalized(v3(normals[i]), {0, 0, 1});
    Vec3d t = normalized(tsum[i] - nn * dot(nn, tsum[i]), {});
    if (dot(t, t) == 0) {  // no UV gradient: any tangent perpendicular to the normal
      t = normalized(cross(std::abs(nn.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0}, nn), {1, 0, 0});
    }
    double w = dot(cross(nn, t), bsum[i]) < 0 ? -1.0 : 1.0;
    out[i] = {float(t.x), float(t.y), float(t.z), float(w)};
  }
  return out;
}

std::vector<Vec3> compute_normals(const Primitive& p) {
  std::vector<Vec3d> sum(p.positions.size());
  for (size_t f = 0; f + 2 < p.indices.size(); f += 3) {
    uint32_t i0 = p.indices[f], i1 = p.indices[f + 1], i2 = p.indices[f + 2];
    Vec3d n =
        cross(v3(p.positions[i1]) - v3(p.positions[i0]), v3(p.positions[i2]) - v3(p.positions[i0]));
    for (uint32_t i : {i0, i1, i2}) sum[i] = sum[i] + n;
  }
  std::vector<Vec3> out(sum.size());
  for (size_t i = 0; i < sum.size(); ++i) {
    Vec3d n = normalized(sum[i], {0, 0, 1});
    out[i] = {float(n.x), float(n.y), float(n.z)};
  }
  return out;
}

}  // namespace vt::scene
