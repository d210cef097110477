// The one file that includes CGAL: building a Surface_mesh for a chart and running
// Surface_mesh_parameterization's LSCM or ARAP on it. CGAL headers are slow to compile, so
// nothing else in vt_unwrap includes them.
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_parameterization/ARAP_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/LSCM_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/Two_vertices_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>
#include <cmath>

#include "bake/unwrap/unwrap_internal.h"

namespace vt::unwrap::detail {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using VertexIndex = SurfaceMesh::Vertex_index;
using HalfedgeIndex = SurfaceMesh::Halfedge_index;
namespace SMP = CGAL::Surface_mesh_parameterization;

}  // namespace

ParamStatus parameterize_chart(const std::vector<Vec3d>& vertices,
                               const std::vector<std::array<uint32_t, 3>>& faces, Method method,
                               std::vector<Vec2d>* uv) {
  SurfaceMesh mesh;
  mesh.reserve(vertices.size(), faces.size() * 3 / 2 + 3, faces.size());
  for (const Vec3d& p : vertices) mesh.add_vertex(Kernel::Point_3(p.x, p.y, p.z));
  for (const auto& f : faces) {
    if (mesh.add_face(VertexIndex(f[0]), VertexIndex(f[1]), VertexIndex(f[2])) ==
        SurfaceMesh::null_face())
      return ParamStatus::kNotDisk;  // non-manifold configuration CGAL refuses
  }
  // A disk: connected (the caller guarantees it), Euler characteristic 1, one border cycle,
  // and no isolated vertex.
  int64_t v = static_cast<int64_t>(mesh.number_of_vertices());
  int64_t e = static_cast<int64_t>(mesh.number_of_edges());
  int64_t fcount = static_cast<int64_t>(mesh.number_of_faces());
  if (v - e + fcount != 1) return ParamStatus::kNotDisk;
  std::vector<HalfedgeIndex> borders;
  CGAL::Polygon_mesh_processing::extract_boundary_cycles(mesh, std::back_inserter(borders));
  if (borders.size() != 1) return ParamStatus::kNotDisk;
  for (VertexIndex vi : mesh.vertices())
    if (mesh.is_isolated(vi)) return ParamStatus::kNotDisk;

  auto uv_map = mesh.add_property_map<VertexIndex, Kernel::Point_2>("v:uv").first;
  SMP::Error_code err;
  if (method == Method::kArap) {
    using Param = SMP::ARAP_parameterizer_3<SurfaceMesh>;
    err = SMP::parameterize(mesh, Param(), borders[0], uv_map);
  } else {
    using Border = SMP::Two_vertices_parameterizer_3<SurfaceMesh>;
    using Param = SMP::LSCM_parameterizer_3<SurfaceMesh, Border>;
    err = SMP::parameterize(mesh, Param(), borders[0], uv_map);
  }
  if (err != SMP::OK) return ParamStatus::kFailed;
  uv->resize(vertices.size());
  for (VertexIndex vi : mesh.vertices()) {
    const auto& p = uv_map[vi];
    (*uv)[vi.idx()] = {p.x(), p.y()};
  }
  return ParamStatus::kOk;
}

}  // namespace vt::unwrap::detail
