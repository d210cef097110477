#include "render/view_surfaces.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "bake/unwrap/texel_density.h"

namespace vt::render {
namespace {

// Union-find over the vertices of one primitive instance: the unwrapper gives each chart its own
// vertices, so faces that share a vertex index share a chart.
struct Charts {
  std::vector<uint32_t> parent;
  explicit Charts(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t find(uint32_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  void join(uint32_t a, uint32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

double uv_area(const scene::Vec2& a, const scene::Vec2& b, const scene::Vec2& c) {
  return std::abs((double(b[0]) - a[0]) * (double(c[1]) - a[1]) -
                  (double(b[1]) - a[1]) * (double(c[0]) - a[0])) /
         2;
}

// The base-colour texture of a primitive: texels per unit of UV area and its UV set, or
// {0, nullptr} when it has none (or its image gives no size).
struct BaseColour {
  double texels_per_uv_area = 0;
  const std::vector<scene::Vec2>* uv = nullptr;
};

}  // namespace

Expected<ViewSurfaces> gather_view_surfaces(const scene::Scene& baked, uint32_t atlas_width,
                                            uint32_t atlas_height) {
  ViewSurfaces out;
  // Image sizes read once; {0, 0} = unreadable.
  std::vector<std::array<int, 2>> size(baked.images.size(), {-1, -1});
  auto base_colour = [&](const scene::Primitive& p) {
    BaseColour bc;
    if (p.material < 0 || size_t(p.material) >= baked.materials.size()) return bc;
    const scene::TextureRef& t = baked.materials[p.material].base_color_texture;
    // The last UV set is the atlas's; the source sets come before it.
    if (!t.valid() || size_t(t.image) >= size.size() || t.texcoord < 0 ||
        size_t(t.texcoord) + 1 >= p.uvs.size() || p.uvs[t.texcoord].size() != p.positions.size())
      return bc;
    if (size[t.image][0] < 0) {
      auto wh = unwrap::image_size(baked.images[t.image]);
      size[t.image] = wh.ok() ? *wh : std::array<int, 2>{0, 0};
      if (!wh.ok()) {
        const scene::Image& im = baked.images[t.image];
        out.unreadable.push_back(
            (im.embedded() ? "embedded image " + std::to_string(t.image) : im.path) + ": " +
            wh.status().message());
      }
    }
    const auto m = t.transform.matrix();
    bc.texels_per_uv_area =
        double(size[t.image][0]) * size[t.image][1] * std::abs(m[0] * m[3] - m[1] * m[2]);
    if (bc.texels_per_uv_area > 0) bc.uv = &p.uvs[t.texcoord];
    return bc;
  };
  const float big = std::numeric_limits<float>::max();
  out.lo = {big, big, big};
  out.hi = {-big, -big, -big};
  const double atlas_texels = double(atlas_width) * atlas_height;
  for (const scene::Instance& inst : baked.instances()) {
    if (inst.mesh < 0 || size_t(inst.mesh) >= baked.meshes.size()) continue;
    const scene::Mesh& mesh = baked.meshes[inst.mesh];
    // The side a triangle faces: its moved edges' cross product, turned back under a mirror.
    const float facing = scene::mirrors(inst.world) ? -1.0f : 1.0f;
    for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const scene::Primitive& p = mesh.primitives[pi];
      if (p.indices.empty()) continue;
      if (p.uvs.empty() || p.uvs.back().size() != p.positions.size()) {
        return Error(ErrorCode::kInvalidArgument, baked.source_path + ": mesh '" + mesh.name +
                                                      "' primitive " + std::to_string(pi) +
                                                      " has no atlas UV set");
      }
      const std::vector<scene::Vec2>& atlas = p.uvs.back();
      const BaseColour bc = base_colour(p);
      std::vector<Vec3f> world(p.positions.size());
      for (size_t v = 0; v < world.size(); ++v) {
        const auto w = scene::transform_point(inst.world, p.positions[v]);
        world[v] = {float(w[0]), float(w[1]), float(w[2])};
      }
      Charts charts(p.positions.size());
      std::vector<uint32_t> first_vertex;  // per kept triangle
      const size_t first = out.triangles.size();
      for (size_t i = 0; i + 2 < p.indices.size(); i += 3) {
        const uint32_t a = p.indices[i], b = p.indices[i + 1], c = p.indices[i + 2];
        if (std::max({a, b, c}) >= p.positions.size()) continue;
        SurfaceTriangle t;
        t.p = {world[a], world[b], world[c]};
        const Vec3f n = cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
        const float len = length(n);
        if (!(len > 0) || !std::isfinite(len)) continue;
        t.normal = n / len * facing;
        t.world_area = len / 2;
        t.atlas_texels = float(uv_area(atlas[a], atlas[b], atlas[c]) * atlas_texels);
        if (bc.uv) {
          t.source_texels =
              float(uv_area((*bc.uv)[a], (*bc.uv)[b], (*bc.uv)[c]) * bc.texels_per_uv_area);
        }
        charts.join(a, b);
        charts.join(a, c);
        first_vertex.push_back(a);
        for (const Vec3f& q : t.p) {
          out.lo = {std::min(out.lo.x, q.x), std::min(out.lo.y, q.y), std::min(out.lo.z, q.z)};
          out.hi = {std::max(out.hi.x, q.x), std::max(out.hi.y, q.y), std::max(out.hi.z, q.z)};
        }
        out.triangles.push_back(t);
      }
      // Chart ids numbered in order of first appearance: deterministic.
      std::vector<uint32_t> id(p.positions.size(), ~0u);
      for (size_t k = 0; k < first_vertex.size(); ++k) {
        uint32_t& root = id[charts.find(first_vertex[k])];
        if (root == ~0u) root = out.chart_count++;
        out.triangles[first + k].chart = root;
      }
    }
  }
  if (out.triangles.empty()) {
    return Error(ErrorCode::kInvalidArgument,
                 baked.source_path + ": no triangle with area to plan views for");
  }
  return out;
}

}  // namespace vt::render
