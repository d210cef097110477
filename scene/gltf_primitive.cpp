// glTF 2.0 mesh primitives: attributes in the component formats glTF 2.0 and
// KHR_mesh_quantization allow, indices (lists, strips, fans) and KHR_draco_mesh_compression.
#include <new>
#include <stdexcept>

#include "scene/gltf_document.h"
#include "scene/scene_io_util.h"
#include "scene/tangent_frame.h"

namespace vt::scene::detail {
namespace {

using json = nlohmann::json;

// Component formats as bits, so that each attribute's allowed set is one mask.
enum FormatBit : unsigned {
  kF32 = 1u << 0,
  kI8 = 1u << 1,
  kI8N = 1u << 2,
  kU8 = 1u << 3,
  kU8N = 1u << 4,
  kI16 = 1u << 5,
  kI16N = 1u << 6,
  kU16 = 1u << 7,
  kU16N = 1u << 8,
  kU32 = 1u << 9,
};
constexpr unsigned kAnyQuantized = kF32 | kI8 | kI8N | kU8 | kU8N | kI16 | kI16N | kU16 | kU16N;

unsigned format_bit(const AccessorView& a) {
  switch (a.component_type) {
    case kFloat:
      return kF32;
    case kByte:
      return a.normalized ? kI8N : kI8;
    case kUnsignedByte:
      return a.normalized ? kU8N : kU8;
    case kShort:
      return a.normalized ? kI16N : kI16;
    case kUnsignedShort:
      return a.normalized ? kU16N : kU16;
    case kUnsignedInt:
      return kU32;
  }
  return 0;
}

// What an attribute may be: glTF 2.0's accessor table, widened by KHR_mesh_quantization for
// POSITION, NORMAL, TANGENT and TEXCOORD_n. The quantised types are accepted whether or not
// the file declares the extension: they are read exactly as it specifies.
constexpr const char* kQuantizedText = "float or (normalized) byte, short or their unsigned";
constexpr const char* kDirectionText = "float, normalized byte or normalized short";

struct AttributeRule {
  const char* types;  // for messages
  int min_components, max_components;
  unsigned formats;
  const char* formats_text;
};
constexpr AttributeRule kPositionRule{"VEC3", 3, 3, kAnyQuantized, kQuantizedText};
constexpr AttributeRule kDirectionRule3{"VEC3", 3, 3, kF32 | kI8N | kI16N, kDirectionText};
constexpr AttributeRule kDirectionRule4{"VEC4", 4, 4, kF32 | kI8N | kI16N, kDirectionText};
constexpr AttributeRule kTexcoordRule{"VEC2", 2, 2, kAnyQuantized, kQuantizedText};
constexpr AttributeRule kColorRule{"VEC3 or VEC4", 3, 4, kF32 | kU8N | kU16N,
                                   "float, normalized unsigned byte or normalized unsigned short"};
constexpr AttributeRule kIndexRule{"SCALAR", 1, 1, kU8 | kU16 | kU32,
                                   "unsigned byte, unsigned short or unsigned int"};

// Opens the accessor that `index` names for `name` and checks its type against `rule`.
Expected<AccessorView> open_as(const Gltf& g, const json& index, const std::string& name,
                               const AttributeRule& rule, uint64_t max_count,
                               const std::string& where) {
  if (!index.is_number_unsigned())
    return g.fail(where + ": " + name + " is not an accessor index: " + index.dump());
  VT_ASSIGN_OR_RETURN(AccessorView a,
                      open_accessor(g, index.get<size_t>(), max_count, where + ": " + name));
  if (a.components < rule.min_components || a.components > rule.max_components ||
      !(format_bit(a) & rule.formats))
    return g.fail(where + ": " + name + " (accessor " + std::to_string(a.index) + ") is " +
                  a.format_name() + "; glTF allows " + rule.types + " of " + rule.formats_text);
  return a;
}

// Reads attribute `name` (if the primitive has it) into out; it must have one entry per vertex.
// components receives the accessor's component count.
template <size_t N>
Status load_attribute(const Gltf& g, const json& attrs, const std::string& name,
                      const AttributeRule& rule, size_t vertices, const std::string& where,
                      std::vector<std::array<float, N>>* out, int* components = nullptr) {
  const json& index = member(attrs, name.c_str());
  if (index.is_null()) return Status::Ok();
  VT_ASSIGN_OR_RETURN(AccessorView a, open_as(g, index, name, rule, kMaxVertices, where));
  if (a.count != vertices)
    return g.fail(where + ": " + name + " (accessor " + std::to_string(a.index) + ") has " +
                  std::to_string(a.count) + " entries for " + std::to_string(vertices) +
                  " vertices");
  read_vec(a, out);
  if (components) *components = a.components;
  return Status::Ok();
}

// The triangle list of a primitive's `mode` over its index sequence.
Status triangulate(const Gltf& g, int mode, std::vector<uint32_t> idx, const std::string& where,
                   std::vector<uint32_t>* out) {
  if (mode == 4) {
    idx.resize(idx.size() / 3 * 3);
    *out = std::move(idx);
    return Status::Ok();
  }
  if (mode != 5 && mode != 6) {
    out->clear();  // points and lines carry no surface
    return Status::Ok();
  }
  size_t triangles = idx.size() < 3 ? 0 : idx.size() - 2;
  VT_RETURN_IF_ERROR(check_ceiling(g.path + ": " + where + ": triangulated indices",
                                   uint64_t{triangles} * 3, kMaxIndices, "indices"));
  out->reserve(triangles * 3);
  for (size_t i = 2; i < idx.size(); ++i) {
    if (mode == 6)
      out->insert(out->end(), {idx[0], idx[i - 1], idx[i]});
    else if (i % 2 == 0)  // strip: alternate winding so every triangle faces the same way
      out->insert(out->end(), {idx[i - 2], idx[i - 1], idx[i]});
    else
      out->insert(out->end(), {idx[i - 1], idx[i - 2], idx[i]});
  }
  return Status::Ok();
}

Status load_draco_primitive(const Gltf& g, const json& ext, const std::string& where,
                            Primitive* prim) {
  const uint8_t* data;
  size_t size;
  VT_ASSIGN_OR_RETURN(size_t view, size_field(g, ext, "bufferView", 0, where));
  VT_RETURN_IF_ERROR(view_bytes(g, view, &data, &size, nullptr));
  std::vector<DracoAttribute> ids;
  const json& attributes = member(ext, "attributes");
  for (auto it = attributes.begin(); attributes.is_object() && it != attributes.end(); ++it) {
    if (!it.value().is_number_integer())
      return g.fail(where + ": KHR_draco_mesh_compression attribute " + it.key() + " is not an id");
    ids.push_back({it.key(), it.value().get<int>()});
  }
  auto decoded = decode_draco(data, size, ids);
  if (!decoded.ok()) return decoded.status().with_context(g.path + ": " + where);
  *prim = std::move(decoded).value();
  return Status::Ok();
}

Expected<Primitive> read_primitive(const Gltf& g, const json& p, const std::string& where) {
  Primitive prim;
  const json& draco = member(member(p, "extensions"), "KHR_draco_mesh_compression");
  if (draco.is_object()) {
    VT_RETURN_IF_ERROR(load_draco_primitive(g, draco, where, &prim));
  } else {
    const json& attrs = member(p, "attributes");
    const json& position = member(attrs, "POSITION");
    if (position.is_null()) return g.fail(where + ": no POSITION attribute");
    VT_ASSIGN_OR_RETURN(AccessorView pa,
                        open_as(g, position, "POSITION", kPositionRule, kMaxVertices, where));
    read_vec(pa, &prim.positions);
    size_t n = prim.positions.size();
    VT_RETURN_IF_ERROR(
        load_attribute(g, attrs, "NORMAL", kDirectionRule3, n, where, &prim.normals));
    VT_RETURN_IF_ERROR(
        load_attribute(g, attrs, "TANGENT", kDirectionRule4, n, where, &prim.tangents));
    // vtbake's unwrapped glb: TANGENT is the atlas frame, the material's normal maps need this.
    if (attrs.contains("_SOURCE_TANGENT")) {
      VT_RETURN_IF_ERROR(
          load_attribute(g, attrs, "_SOURCE_TANGENT", kDirectionRule4, n, where, &prim.tangents));
    }
    int color_components = 4;
    VT_RETURN_IF_ERROR(
        load_attribute(g, attrs, "COLOR_0", kColorRule, n, where, &prim.colors, &color_components));
    if (color_components == 3)
      for (auto& c : prim.colors) c[3] = 1.0f;
    for (int t = 0; attrs.contains("TEXCOORD_" + std::to_string(t)); ++t) {
      prim.uvs.emplace_back();
      VT_RETURN_IF_ERROR(load_attribute(g, attrs, "TEXCOORD_" + std::to_string(t), kTexcoordRule, n,
                                        where, &prim.uvs.back()));
    }
    std::vector<uint32_t> idx;
    if (!member(p, "indices").is_null()) {
      VT_ASSIGN_OR_RETURN(AccessorView ia, open_as(g, member(p, "indices"), "indices", kIndexRule,
                                                   kMaxIndices, where));
      idx.resize(ia.count);
      for (size_t i = 0; i < ia.count; ++i) idx[i] = static_cast<uint32_t>(ia.value(i, 0));
    } else {
      idx.resize(n);
      for (size_t i = 0; i < n; ++i) idx[i] = static_cast<uint32_t>(i);
    }
    const json& mode = member(p, "mode");
    VT_RETURN_IF_ERROR(triangulate(g, mode.is_number_integer() ? mode.get<int>() : 4,
                                   std::move(idx), where, &prim.indices));
  }
  // glTF: "When normals are not specified, client implementations MUST calculate flat normals
  // and the provided tangents (if present) MUST be ignored."
  if (prim.normals.empty()) make_flat_normals(prim);
  const json& material = member(p, "material");
  prim.material = material.is_number_unsigned() ? material.get<int>() : -1;
  if (prim.material >= static_cast<int>(member(g.doc, "materials").size())) prim.material = -1;
  return prim;
}

}  // namespace

Expected<Primitive> load_primitive(const Gltf& g, const json& p, const std::string& where) {
  // Every count was checked against its bytes and the ceilings; what is left is a file within
  // them that still does not fit in this machine's memory.
  try {
    return read_primitive(g, p, where);
  } catch (const std::bad_alloc&) {
    return Error(ErrorCode::kResourceLimit, g.path + ": " + where + ": out of memory");
  } catch (const std::length_error&) {
    return Error(ErrorCode::kResourceLimit, g.path + ": " + where + ": out of memory");
  }
}

}  // namespace vt::scene::detail
