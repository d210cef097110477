// glTF 2.0 buffers, buffer views and accessors (sparse ones included). Every offset, size and
// count from the file is checked against the bytes behind it, and every count against the
// ceilings of import_budget.h, before anything is allocated for it.
#include <algorithm>
#include <cstring>

#include "scene/gltf_document.h"
#include "scene/scene_io_util.h"

namespace vt::scene::detail {

using json = nlohmann::json;

const json& member(const json& obj, const char* key) {
  static const json kNull;
  if (!obj.is_object()) return kNull;
  auto it = obj.find(key);
  return it == obj.end() ? kNull : *it;
}

Expected<size_t> size_field(const Gltf& g, const json& obj, const char* key, size_t fallback,
                            const std::string& where) {
  const json& v = member(obj, key);
  if (v.is_null()) return fallback;
  if (!v.is_number_unsigned())
    return g.fail(where + ": " + key + " is not a non-negative integer: " + v.dump());
  return v.get<size_t>();
}

Status load_buffers(Gltf* g, std::vector<uint8_t>* glb_bin) {
  std::string folder = parent_folder(g->path);
  const json& buffers = member(g->doc, "buffers");
  for (size_t i = 0; buffers.is_array() && i < buffers.size(); ++i) {
    const json& b = buffers[i];
    const json& uri_field = member(b, "uri");
    if (!uri_field.is_string()) {
      // The .glb's first buffer without uri is its BIN chunk; any other is a placeholder that
      // only EXT_meshopt_compression views may use (view_bytes refuses other readers).
      g->buffers.emplace_back();
      if (glb_bin) g->buffers.back() = std::move(*glb_bin);
      glb_bin = nullptr;
      continue;
    }
    std::string uri = uri_field.get<std::string>();
    if (uri.rfind("data:", 0) == 0) {
      auto data = decode_data_uri(uri, nullptr);
      if (!data.ok()) return data.status().with_context(g->path);
      g->buffers.push_back(std::move(data).value());
    } else {
      const std::string file = folder + percent_decode(uri);
      VT_RETURN_IF_ERROR(
          check_inside_scene_tree(g->path, file, "buffer " + std::to_string(i), g->options));
      auto data = read_file(file);
      if (!data.ok()) return data.status().with_context(g->path + ": buffer");
      g->buffers.push_back(std::move(data).value());
    }
    VT_ASSIGN_OR_RETURN(size_t declared,
                        size_field(*g, b, "byteLength", 0, "buffer " + std::to_string(i)));
    if (g->buffers.back().size() < declared)
      return g->fail("buffer '" + uri.substr(0, 64) + "' is shorter than its byteLength");
  }
  return decode_meshopt_views(g);
}

Status view_bytes(const Gltf& g, size_t view_index, const uint8_t** data, size_t* size,
                  size_t* stride) {
  const json& views = member(g.doc, "bufferViews");
  std::string where = "bufferView " + std::to_string(view_index);
  if (!views.is_array() || view_index >= views.size() || !views[view_index].is_object())
    return g.fail(where + " does not exist");
  const json& v = views[view_index];
  VT_ASSIGN_OR_RETURN(size_t buffer, size_field(g, v, "buffer", 0, where));
  VT_ASSIGN_OR_RETURN(size_t offset, size_field(g, v, "byteOffset", 0, where));
  VT_ASSIGN_OR_RETURN(size_t length, size_field(g, v, "byteLength", 0, where));
  VT_ASSIGN_OR_RETURN(size_t byte_stride, size_field(g, v, "byteStride", 0, where));
  if (stride) *stride = byte_stride;
  if (auto it = g.decoded_views.find(view_index); it != g.decoded_views.end()) {
    *data = it->second.data();
    *size = it->second.size();
    return Status::Ok();
  }
  if (buffer >= g.buffers.size())
    return g.fail(where + ": buffer " + std::to_string(buffer) + " does not exist");
  const std::vector<uint8_t>& bytes = g.buffers[buffer];
  if (offset > bytes.size() || length > bytes.size() - offset) {
    std::string held = bytes.empty() && !member(member(g.doc, "buffers")[buffer], "uri").is_string()
                           ? " (a placeholder without uri: only compressed views may use it)"
                           : "";
    return g.fail(where + " (bytes " + std::to_string(offset) + " + " + std::to_string(length) +
                  ") runs past buffer " + std::to_string(buffer) + ", which holds " +
                  format_bytes(static_cast<double>(bytes.size())) + held);
  }
  *data = bytes.data() + offset;
  *size = length;
  return Status::Ok();
}

namespace {

int component_count(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4") return 4;
  if (type == "MAT4") return 16;
  return 0;  // MAT2 and MAT3 (column padding) are no attribute vtbake reads
}

size_t component_size(int ct) {
  switch (ct) {
    case kByte:
    case kUnsignedByte:
      return 1;
    case kShort:
    case kUnsignedShort:
      return 2;
    case kUnsignedInt:
    case kFloat:
      return 4;
  }
  return 0;
}

const char* component_name(int ct) {
  switch (ct) {
    case kByte:
      return "byte";
    case kUnsignedByte:
      return "unsigned byte";
    case kShort:
      return "short";
    case kUnsignedShort:
      return "unsigned short";
    case kUnsignedInt:
      return "unsigned int";
    case kFloat:
      return "float";
  }
  return "unknown";
}

// The view's bytes an accessor (or a sparse part) reads: `count` elements of `elem` bytes every
// `stride` from `offset`, checked to lie inside the view.
Status accessor_bytes(const Gltf& g, const std::string& where, size_t view, size_t offset,
                      size_t count, size_t elem, size_t* stride, const uint8_t** data) {
  size_t size, view_stride;
  VT_RETURN_IF_ERROR(view_bytes(g, view, data, &size, &view_stride));
  if (stride) *stride = view_stride == 0 ? elem : view_stride;
  size_t step = stride ? *stride : elem;
  std::string view_name = "bufferView " + std::to_string(view);
  if (step < elem)
    return g.fail(where + ": " + view_name + "'s byteStride " + std::to_string(step) +
                  " is smaller than the element size " + std::to_string(elem));
  if (offset > size)
    return g.fail(where + ": byteOffset " + std::to_string(offset) + " is past the end of " +
                  view_name + " (" + format_bytes(static_cast<double>(size)) + ")");
  size_t held = size - offset;
  bool fits = count == 0 || (held >= elem && (count - 1) <= (held - elem) / step);
  if (!fits)
    return g.fail(where + ": " + needs_but_holds(count, step, view_name, held) +
                  (offset ? " after byteOffset " + std::to_string(offset) : ""));
  *data += offset;
  return Status::Ok();
}

uint32_t read_index(const uint8_t* p, int ct) {
  if (ct == kUnsignedByte) return *p;
  if (ct == kUnsignedShort) {
    uint16_t v;
    std::memcpy(&v, p, 2);
    return v;
  }
  return read_u32(p);
}

// Replaces the accessor's elements by a tight copy (the base view's, or zeros) with the
// sparse values substituted at their indices.
Status apply_sparse(const Gltf& g, const json& sparse, const std::string& where, AccessorView* v) {
  size_t elem = v->components * component_size(v->component_type);
  std::string sw = where + ": sparse";
  VT_ASSIGN_OR_RETURN(size_t n, size_field(g, sparse, "count", 0, sw));
  if (n == 0 || n > v->count)
    return g.fail(sw + " count " + std::to_string(n) + " is not in 1.." + std::to_string(v->count) +
                  " (the accessor's count)");
  const json& indices = member(sparse, "indices");
  const json& values = member(sparse, "values");
  if (!indices.contains("bufferView") || !values.contains("bufferView"))
    return g.fail(sw + ": indices and values need a bufferView each");
  int ict = indices.value("componentType", 0);
  if (ict != kUnsignedByte && ict != kUnsignedShort && ict != kUnsignedInt)
    return g.fail(sw + " indices: componentType " + std::to_string(ict) +
                  " is not unsigned byte, short or int");
  const uint8_t *idx, *val;
  VT_ASSIGN_OR_RETURN(size_t iview, size_field(g, indices, "bufferView", 0, sw));
  VT_ASSIGN_OR_RETURN(size_t ioffset, size_field(g, indices, "byteOffset", 0, sw));
  VT_ASSIGN_OR_RETURN(size_t vview, size_field(g, values, "bufferView", 0, sw));
  VT_ASSIGN_OR_RETURN(size_t voffset, size_field(g, values, "byteOffset", 0, sw));
  VT_RETURN_IF_ERROR(
      accessor_bytes(g, sw + " indices", iview, ioffset, n, component_size(ict), nullptr, &idx));
  VT_RETURN_IF_ERROR(accessor_bytes(g, sw + " values", vview, voffset, n, elem, nullptr, &val));
  std::vector<uint8_t> dense(v->count * elem, 0);
  if (v->data)
    for (size_t i = 0; i < v->count; ++i)
      std::memcpy(dense.data() + i * elem, v->data + i * v->stride, elem);
  for (size_t j = 0; j < n; ++j) {
    uint32_t at = read_index(idx + j * component_size(ict), ict);
    if (at >= v->count)
      return g.fail(sw + " index " + std::to_string(at) + " (entry " + std::to_string(j) +
                    ") is outside the accessor's " + std::to_string(v->count) + " elements");
    std::memcpy(dense.data() + size_t{at} * elem, val + j * elem, elem);
  }
  v->owned = std::move(dense);
  v->data = v->owned.data();
  v->stride = elem;
  return Status::Ok();
}

}  // namespace

double AccessorView::value(size_t i, int k) const {
  if (!data) return 0;
  const uint8_t* p = data + i * stride + k * component_size(component_type);
  switch (component_type) {
    case kByte: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case kUnsignedByte:
      return normalized ? *p / 255.0 : *p;
    case kShort: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case kUnsignedShort: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case kUnsignedInt:
      return read_u32(p);
    case kFloat: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
  return 0;
}

std::string AccessorView::format_name() const {
  static const char* kTypes[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
  std::string type = components <= 4 ? kTypes[components] : "MAT4";
  return type + " of " + (normalized ? "normalized " : "") + component_name(component_type);
}

Expected<AccessorView> open_accessor(const Gltf& g, size_t index, uint64_t max_count,
                                     const std::string& context) {
  const json& accessors = member(g.doc, "accessors");
  std::string where = (context.empty() ? "" : context + ": ") + "accessor " + std::to_string(index);
  if (!accessors.is_array() || index >= accessors.size() || !accessors[index].is_object())
    return g.fail(where + " does not exist");
  const json& a = accessors[index];
  AccessorView v;
  v.index = index;
  if (!a.contains("count")) return g.fail(where + " has no count");
  VT_ASSIGN_OR_RETURN(v.count, size_field(g, a, "count", 0, where));
  v.component_type = a.value("componentType", 0);
  std::string type = a.value("type", std::string());
  v.components = component_count(type);
  v.normalized = a.value("normalized", false);
  size_t cs = component_size(v.component_type);
  if (v.components == 0 || cs == 0)
    return g.fail(where + ": unknown type '" + type.substr(0, 16) + "' or componentType " +
                  std::to_string(v.component_type));
  if (v.normalized && (v.component_type == kFloat || v.component_type == kUnsignedInt))
    return g.fail(where + ": a " + component_name(v.component_type) + " cannot be normalized");
  VT_RETURN_IF_ERROR(check_ceiling(g.path + ": " + where, v.count, max_count,
                                   max_count == kMaxIndices ? "indices" : "vertices"));
  size_t elem = cs * v.components;
  if (a.contains("bufferView")) {
    VT_ASSIGN_OR_RETURN(size_t view, size_field(g, a, "bufferView", 0, where));
    VT_ASSIGN_OR_RETURN(size_t offset, size_field(g, a, "byteOffset", 0, where));
    VT_RETURN_IF_ERROR(accessor_bytes(g, where, view, offset, v.count, elem, &v.stride, &v.data));
  }
  if (a.contains("sparse")) VT_RETURN_IF_ERROR(apply_sparse(g, a["sparse"], where, &v));
  return v;
}

}  // namespace vt::scene::detail
