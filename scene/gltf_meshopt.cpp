// EXT_meshopt_compression: buffer views stored as meshoptimizer's vertex codec (ATTRIBUTES,
// with the OCTAHEDRAL, QUATERNION and EXPONENTIAL filters) or index codecs (TRIANGLES,
// INDICES), decoded once when the buffers load. Every size is checked before decoding, so
// meshoptimizer's preconditions (asserts) hold and the output is bounded by the input: the
// vertex codec spends at least one header byte per 64 bytes it decodes (2 bits per 16 bytes
// per byte channel), the triangle codec one byte per triangle, the index codec one per index.
#include <meshoptimizer.h>

#include "scene/gltf_document.h"

namespace vt::scene::detail {
namespace {

using json = nlohmann::json;

struct Compressed {
  std::string mode, filter;
  size_t count = 0, stride = 0;
  const uint8_t* data = nullptr;
  size_t size = 0;
};

// The extension's fields and the compressed bytes, checked against the spec's rules.
Status parse(const Gltf& g, const json& view, const json& ext, const std::string& where,
             Compressed* c) {
  VT_ASSIGN_OR_RETURN(size_t buffer, size_field(g, ext, "buffer", 0, where));
  VT_ASSIGN_OR_RETURN(size_t offset, size_field(g, ext, "byteOffset", 0, where));
  VT_ASSIGN_OR_RETURN(c->size, size_field(g, ext, "byteLength", 0, where));
  VT_ASSIGN_OR_RETURN(c->stride, size_field(g, ext, "byteStride", 0, where));
  VT_ASSIGN_OR_RETURN(c->count, size_field(g, ext, "count", 0, where));
  VT_ASSIGN_OR_RETURN(size_t view_length, size_field(g, view, "byteLength", 0, where));
  VT_ASSIGN_OR_RETURN(size_t view_stride, size_field(g, view, "byteStride", 0, where));
  c->mode = ext.value("mode", std::string());
  c->filter = ext.value("filter", std::string("NONE"));
  if (buffer >= g.buffers.size())
    return g.fail(where + ": buffer " + std::to_string(buffer) + " does not exist");
  const std::vector<uint8_t>& bytes = g.buffers[buffer];
  if (offset > bytes.size() || c->size > bytes.size() - offset)
    return g.fail(where + ": compressed bytes " + std::to_string(offset) + " + " +
                  std::to_string(c->size) + " run past buffer " + std::to_string(buffer) + " (" +
                  format_bytes(static_cast<double>(bytes.size())) + ")");
  c->data = bytes.data() + offset;
  if (view_stride != 0 && view_stride != c->stride)
    return g.fail(where + ": byteStride " + std::to_string(c->stride) +
                  " differs from the bufferView's " + std::to_string(view_stride));
  bool attributes = c->mode == "ATTRIBUTES";
  if (!attributes && c->mode != "TRIANGLES" && c->mode != "INDICES")
    return g.fail(where + ": unknown mode '" + c->mode.substr(0, 32) + "'");
  if (attributes ? (c->stride == 0 || c->stride % 4 != 0 || c->stride > 256)
                 : (c->stride != 2 && c->stride != 4))
    return g.fail(where + ": byteStride " + std::to_string(c->stride) + " is not allowed in " +
                  c->mode + " mode");
  if (c->mode == "TRIANGLES" && c->count % 3 != 0)
    return g.fail(where + ": TRIANGLES count " + std::to_string(c->count) +
                  " is not a multiple of 3");
  bool filter_ok =
      c->filter == "NONE" ||
      (attributes && ((c->filter == "OCTAHEDRAL" && (c->stride == 4 || c->stride == 8)) ||
                      (c->filter == "QUATERNION" && c->stride == 8) || c->filter == "EXPONENTIAL"));
  if (!filter_ok)
    return g.fail(where + ": filter '" + c->filter.substr(0, 32) + "' is not allowed with " +
                  c->mode + " mode and byteStride " + std::to_string(c->stride));
  VT_RETURN_IF_ERROR(check_ceiling(g.path + ": " + where, c->count, kMaxIndices, "elements"));
  // The decoded size is bounded by the compressed bytes (see the file comment).
  uint64_t most = attributes               ? uint64_t{c->size} * 64 / c->stride
                  : c->mode == "TRIANGLES" ? uint64_t{c->size} * 3
                                           : uint64_t{c->size};
  if (c->count > most)
    return g.fail(
        where + ": count " + std::to_string(c->count) + " x " + std::to_string(c->stride) +
        " bytes needs " + format_bytes(static_cast<double>(c->count) * c->stride) + " but its " +
        format_bytes(static_cast<double>(c->size)) + " of compressed data decode to at most " +
        format_bytes(static_cast<double>(most) * c->stride));
  if (view_length != c->count * c->stride)
    return g.fail(where + ": the bufferView's byteLength " + std::to_string(view_length) +
                  " is not count x byteStride = " + std::to_string(c->count * c->stride));
  return Status::Ok();
}

Status decode(const Gltf& g, const Compressed& c, const std::string& where,
              std::vector<uint8_t>* out) {
  out->assign(c.count * c.stride, 0);
  if (c.count == 0) return Status::Ok();
  int rc;
  if (c.mode == "ATTRIBUTES")
    rc = meshopt_decodeVertexBuffer(out->data(), c.count, c.stride, c.data, c.size);
  else if (c.mode == "TRIANGLES")
    rc = meshopt_decodeIndexBuffer(out->data(), c.count, c.stride, c.data, c.size);
  else
    rc = meshopt_decodeIndexSequence(out->data(), c.count, c.stride, c.data, c.size);
  if (rc != 0)
    return g.fail(where + ": " + c.mode + " data does not decode (meshoptimizer error " +
                  std::to_string(rc) + ")");
  if (c.filter == "OCTAHEDRAL")
    meshopt_decodeFilterOct(out->data(), c.count, c.stride);
  else if (c.filter == "QUATERNION")
    meshopt_decodeFilterQuat(out->data(), c.count, c.stride);
  else if (c.filter == "EXPONENTIAL")
    meshopt_decodeFilterExp(out->data(), c.count, c.stride);
  return Status::Ok();
}

}  // namespace

Status decode_meshopt_views(Gltf* g) {
  const json& views = member(g->doc, "bufferViews");
  for (size_t i = 0; views.is_array() && i < views.size(); ++i) {
    const json& ext = member(member(views[i], "extensions"), "EXT_meshopt_compression");
    if (!ext.is_object()) continue;
    std::string where = "bufferView " + std::to_string(i) + ": EXT_meshopt_compression";
    Compressed c;
    VT_RETURN_IF_ERROR(parse(*g, views[i], ext, where, &c));
    VT_RETURN_IF_ERROR(decode(*g, c, where, &g->decoded_views[i]));
  }
  return Status::Ok();
}

}  // namespace vt::scene::detail
