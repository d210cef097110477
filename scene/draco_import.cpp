// Draco: .drc files and KHR_draco_mesh_compression buffer views. (PLY has its own reader,
// ply_import.cpp: Draco's trusts the header's counts.) Draco sizes its own buffers from the
// stream, before vtbake can see a count, so its allocation failures are caught here; the
// decoded mesh is then checked against the ceilings before it is converted.
#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include <new>

#include "scene/import_budget.h"
#include "scene/scene_io_util.h"

namespace vt::scene::detail {
namespace {

template <int N>
bool read_attribute(const draco::PointAttribute* att, const draco::Mesh& mesh,
                    std::vector<std::array<float, N>>* out) {
  out->assign(mesh.num_points(), {});
  for (draco::PointIndex i(0); i < mesh.num_points(); ++i) {
    std::array<float, N> v{};
    if constexpr (N == 4) v[3] = 1.0f;  // colours without alpha are opaque
    int comps = std::min<int>(N, att->num_components());
    if (!att->ConvertValue<float>(att->mapped_index(i), static_cast<int8_t>(comps), v.data()))
      return false;
    (*out)[i.value()] = v;
  }
  return true;
}

Expected<Primitive> convert(const draco::Mesh& mesh, const std::vector<DracoAttribute>& ids) {
  VT_RETURN_IF_ERROR(check_ceiling("Draco mesh", mesh.num_points(), kMaxVertices, "vertices"));
  VT_RETURN_IF_ERROR(
      check_ceiling("Draco mesh", uint64_t{mesh.num_faces()} * 3, kMaxIndices, "indices"));
  Primitive prim;
  auto by_name = [&](const std::string& name) -> const draco::PointAttribute* {
    for (const auto& a : ids)
      if (a.name == name) return mesh.GetAttributeByUniqueId(static_cast<uint32_t>(a.unique_id));
    return nullptr;
  };
  const draco::PointAttribute* pos =
      ids.empty() ? mesh.GetNamedAttribute(draco::GeometryAttribute::POSITION)
                  : by_name("POSITION");
  if (!pos) return Error(ErrorCode::kCorrupt, "Draco mesh has no POSITION attribute");
  if (!read_attribute<3>(pos, mesh, &prim.positions))
    return Error(ErrorCode::kCorrupt, "Draco POSITION attribute cannot be converted to float");
  const draco::PointAttribute* nrm =
      ids.empty() ? mesh.GetNamedAttribute(draco::GeometryAttribute::NORMAL) : by_name("NORMAL");
  if (nrm && !read_attribute<3>(nrm, mesh, &prim.normals)) prim.normals.clear();
  const draco::PointAttribute* col =
      ids.empty() ? mesh.GetNamedAttribute(draco::GeometryAttribute::COLOR) : by_name("COLOR_0");
  if (col) {
    if (!read_attribute<4>(col, mesh, &prim.colors)) prim.colors.clear();
    // Integer colours are normalised in glTF; draco converts the raw value, so rescale.
    float scale = col->data_type() == draco::DT_UINT8    ? 1.0f / 255.0f
                  : col->data_type() == draco::DT_UINT16 ? 1.0f / 65535.0f
                                                         : 1.0f;
    if (scale != 1.0f)
      for (auto& c : prim.colors)
        for (int k = 0; k < 4; ++k)
          c[k] = (k == 3 && col->num_components() < 4) ? 1.0f : c[k] * scale;
  }
  if (!ids.empty()) {
    if (const auto* tan = by_name("TANGENT"); tan && !read_attribute<4>(tan, mesh, &prim.tangents))
      prim.tangents.clear();
    for (int n = 0;; ++n) {
      const auto* uv = by_name("TEXCOORD_" + std::to_string(n));
      if (!uv) break;
      prim.uvs.emplace_back();
      if (!read_attribute<2>(uv, mesh, &prim.uvs.back()))
        return Error(ErrorCode::kCorrupt, "Draco TEXCOORD attribute cannot be converted");
    }
  } else {
    for (int n = 0; n < mesh.NumNamedAttributes(draco::GeometryAttribute::TEX_COORD); ++n) {
      prim.uvs.emplace_back();
      if (!read_attribute<2>(mesh.GetNamedAttribute(draco::GeometryAttribute::TEX_COORD, n), mesh,
                             &prim.uvs.back()))
        return Error(ErrorCode::kCorrupt, "Draco TEX_COORD attribute cannot be converted");
    }
  }
  prim.indices.reserve(static_cast<size_t>(mesh.num_faces()) * 3);
  for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) prim.indices.push_back(mesh.face(f)[k].value());
  return prim;
}

}  // namespace

Expected<Primitive> decode_draco(const uint8_t* data, size_t size,
                                 const std::vector<DracoAttribute>& attribute_ids) {
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(data), size);
  draco::Decoder decoder;
  try {
    auto result = decoder.DecodeMeshFromBuffer(&buffer);
    if (!result.ok())
      return Error(ErrorCode::kCorrupt,
                   "Draco decode failed: " + result.status().error_msg_string());
    return convert(*result.value(), attribute_ids);
  } catch (const std::bad_alloc&) {
    return Error(ErrorCode::kResourceLimit, "Draco decode ran out of memory (" +
                                                format_bytes(static_cast<double>(size)) +
                                                " of compressed data)");
  }
}

Expected<Scene> load_drc(const std::string& path) {
  VT_ASSIGN_OR_RETURN(auto bytes, read_file(path));
  auto prim = decode_draco(bytes.data(), bytes.size(), {});
  if (!prim.ok()) return prim.status().with_context(path);
  std::vector<Primitive> prims;
  prims.push_back(std::move(prim).value());
  return single_mesh_scene(path, "drc", std::move(prims));
}

}  // namespace vt::scene::detail
