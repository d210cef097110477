#include "scene/tangent_frame.h"

#include <algorithm>
#include <cmath>

#include "common/vec.h"

namespace vt::scene {
namespace {

Vec3d v3(const Vec3& a) {
  return {a[0], a[1], a[2]};
}

// A primitive's positions in units of unit_scale.
struct ScaledPositions {
  const std::vector<Vec3>& positions;
  double scale;
  explicit ScaledPositions(const Primitive& p)
      : positions(p.positions), scale(unit_scale(p.positions)) {}
  Vec3d operator[](uint32_t i) const { return v3(positions[i]) * scale; }
  // The face's normal scaled by twice its area (in these units).
  Vec3d face_cross(const uint32_t* t) const {
    const Vec3d o = (*this)[t[0]];
    return cross((*this)[t[1]] - o, (*this)[t[2]] - o);
  }
};

}  // namespace

double unit_scale(const std::vector<Vec3>& positions) {
  double largest = 0;
  for (const Vec3& q : positions)
    for (float c : q) largest = std::max(largest, std::abs(double(c)));
  // A power of two: exact, so that a model in ordinary units gets the same bits as unscaled.
  return largest > 0 && std::isfinite(largest) ? std::ldexp(1.0, -std::ilogb(largest)) : 1.0;
}

std::vector<Vec4> compute_tangents(const Primitive& p, const std::vector<Vec3>& normals,
                                   int uv_set) {
  size_t n = p.positions.size();
  std::vector<Vec3d> tsum(n), bsum(n);
  const auto& uv = p.uvs[uv_set];
  const ScaledPositions at(p);
  for (size_t f = 0; f + 2 < p.indices.size(); f += 3) {
    uint32_t i0 = p.indices[f], i1 = p.indices[f + 1], i2 = p.indices[f + 2];
    Vec3d e1 = at[i1] - at[i0], e2 = at[i2] - at[i0];
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
  const ScaledPositions at(p);
  for (size_t f = 0; f + 2 < p.indices.size(); f += 3) {
    const Vec3d n = at.face_cross(&p.indices[f]);
    for (int c = 0; c < 3; ++c) sum[p.indices[f + c]] = sum[p.indices[f + c]] + n;
  }
  std::vector<Vec3> out(sum.size());
  for (size_t i = 0; i < sum.size(); ++i) {
    Vec3d n = normalized(sum[i], {0, 0, 1});
    out[i] = {float(n.x), float(n.y), float(n.z)};
  }
  return out;
}

void make_flat_normals(Primitive& p) {
  const size_t faces = p.indices.size() / 3, n = p.positions.size();
  // Faces naming a vertex past the end are left as they are, for the geometry check to name.
  auto in_range = [&](size_t f) {
    return std::max({p.indices[3 * f], p.indices[3 * f + 1], p.indices[3 * f + 2]}) < n;
  };
  std::vector<Vec3d> face_normal(faces);
  {
    const ScaledPositions at(p);  // before copies are appended to the positions
    for (size_t f = 0; f < faces; ++f)
      if (in_range(f)) face_normal[f] = normalized(at.face_cross(&p.indices[3 * f]), {});
  }
  // Each vertex's normals so far, as a chain of (normal, vertex) through `next`: the vertex
  // itself, then its copies, newest first. The search stops after kSearched of them, so that a
  // vertex shared by a million faces that all turn (a crafted fan) costs no more than that.
  constexpr int kSearched = 64;
  struct Version {
    Vec3d normal;
    uint32_t vertex;
    int64_t next;
  };
  constexpr double kSameWay = 1 - 1.5e-8;  // cos(0.01 degrees)
  std::vector<int64_t> first(n, -1);
  std::vector<Version> versions;
  auto copy_vertex = [&p](uint32_t v) {
    auto copy = [v](auto& values) {
      if (values.size() > v) values.push_back(values[v]);
    };
    copy(p.positions);
    for (auto& uv : p.uvs) copy(uv);
    copy(p.colors);
    return static_cast<uint32_t>(p.positions.size() - 1);
  };
  auto vertex_for = [&](uint32_t v, const Vec3d& normal, bool degenerate) {
    if (first[v] < 0) {
      first[v] = static_cast<int64_t>(versions.size());
      versions.push_back({degenerate ? Vec3d{0, 0, 1} : normal, v, -1});
      return v;
    }
    Version& own = versions[size_t(first[v])];
    if (degenerate) return own.vertex;
    int searched = 0;
    for (int64_t k = first[v]; k >= 0 && searched < kSearched;
         k = versions[size_t(k)].next, ++searched)
      if (dot(versions[size_t(k)].normal, normal) >= kSameWay) return versions[size_t(k)].vertex;
    const int64_t after_own = own.next;
    own.next = static_cast<int64_t>(versions.size());
    versions.push_back({normal, copy_vertex(v), after_own});
    return versions.back().vertex;
  };
  // Faces with a normal first, so that a degenerate face never decides a vertex's first normal.
  for (bool degenerate : {false, true})
    for (size_t f = 0; f < faces; ++f) {
      if (!in_range(f) || (dot(face_normal[f], face_normal[f]) == 0) != degenerate) continue;
      for (int c = 0; c < 3; ++c)
        p.indices[3 * f + c] = vertex_for(p.indices[3 * f + c], face_normal[f], degenerate);
    }
  p.normals.assign(p.positions.size(), {0, 0, 1});
  for (const Version& version : versions)
    p.normals[version.vertex] = {float(version.normal.x), float(version.normal.y),
                                 float(version.normal.z)};
  p.tangents.clear();
}

}  // namespace vt::scene
