// glTF 2.0 mesh primitives: attributes, indices (lists, strips, fans) and
// KHR_draco_mesh_compression.
#include "scene/gltf_document.h"
#include "scene/scene_io_util.h"

namespace vt::scene::detail {

using json = nlohmann::json;

Expected<Primitive> load_primitive(const Gltf& g, const json& p, const std::string& where) {
  Primitive prim;
  int mode = p.value("mode", 4);
  const json& attrs = p.value("attributes", json::object());
  if (p.contains("extensions") && p["extensions"].contains("KHR_draco_mesh_compression")) {
    const json& ext = p["extensions"]["KHR_draco_mesh_compression"];
    const uint8_t* data;
    size_t size;
    VT_RETURN_IF_ERROR(view_bytes(g, ext.value("bufferView", size_t{0}), &data, &size, nullptr));
    std::vector<DracoAttribute> ids;
    for (auto it = ext["attributes"].begin(); it != ext["attributes"].end(); ++it)
      ids.push_back({it.key(), it.value().get<int>()});
    auto decoded = decode_draco(data, size, ids);
    if (!decoded.ok()) return decoded.status().with_context(g.path + ": " + where);
    prim = std::move(decoded).value();
  } else {
    if (!attrs.contains("POSITION")) return g.fail(where + ": no POSITION attribute");
    VT_RETURN_IF_ERROR(read_vec<3>(g, attrs["POSITION"].get<size_t>(), &prim.positions));
    if (attrs.contains("NORMAL"))
      VT_RETURN_IF_ERROR(read_vec<3>(g, attrs["NORMAL"].get<size_t>(), &prim.normals));
    if (attrs.contains("TANGENT"))
      VT_RETURN_IF_ERROR(read_vec<4>(g, attrs["TANGENT"].get<size_t>(), &prim.tangents));
    if (attrs.contains("COLOR_0")) {
      const json& a = g.doc["accessors"][attrs["COLOR_0"].get<size_t>()];
      VT_RETURN_IF_ERROR(read_vec<4>(g, attrs["COLOR_0"].get<size_t>(), &prim.colors));
      if (a.value("type", std::string()) == "VEC3")
        for (auto& c : prim.colors) c[3] = 1.0f;
    }
    for (int n = 0; attrs.contains("TEXCOORD_" + std::to_string(n)); ++n) {
      prim.uvs.emplace_back();
      VT_RETURN_IF_ERROR(
          read_vec<2>(g, attrs["TEXCOORD_" + std::to_string(n)].get<size_t>(), &prim.uvs.back()));
    }
    std::vector<uint32_t> idx;
    if (p.contains("indices")) {
      std::vector<double> raw;
      size_t n;
      VT_RETURN_IF_ERROR(read_accessor(g, p["indices"].get<size_t>(), 1, &raw, &n));
      idx.resize(n);
      for (size_t i = 0; i < n; ++i) idx[i] = static_cast<uint32_t>(raw[i]);
    } else {
      idx.resize(prim.positions.size());
      for (size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<uint32_t>(i);
    }
    if (mode == 4) {
      idx.resize(idx.size() / 3 * 3);
      prim.indices = std::move(idx);
    } else if (mode == 5) {  // strip: alternate winding so every triangle faces the same way
      for (size_t i = 2; i < idx.size(); ++i) {
        if (i % 2 == 0)
          prim.indices.insert(prim.indices.end(), {idx[i - 2], idx[i - 1], idx[i]});
        else
          prim.indices.insert(prim.indices.end(), {idx[i - 1], idx[i - 2], idx[i]});
      }
    } else if (mode == 6) {
      for (size_t i = 2; i < idx.size(); ++i)
        prim.indices.insert(prim.indices.end(), {idx[0], idx[i - 1], idx[i]});
    } else {
      prim.indices.clear();  // points and lines carry no surface
    }
  }
  prim.material = p.value("material", -1);
  if (prim.material >= static_cast<int>(g.doc.value("materials", json::array()).size()))
    prim.material = -1;
  return prim;
}

}  // namespace vt::scene::detail
