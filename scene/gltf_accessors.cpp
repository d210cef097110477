// glTF 2.0 buffers, buffer views and accessors. Every offset, size and count from the file is
// checked against the bytes behind it before use.
#include <algorithm>
#include <cstring>

#include "scene/gltf_document.h"
#include "scene/scene_io_util.h"

namespace vt::scene::detail {

using json = nlohmann::json;

uint32_t read_u32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

Status load_buffers(Gltf* g, std::vector<uint8_t>* glb_bin) {
  std::string folder = parent_folder(g->path);
  for (const json& b : g->doc.value("buffers", json::array())) {
    if (!b.contains("uri")) {
      if (!glb_bin) return g->fail("buffer without uri outside a .glb");
      g->buffers.push_back(std::move(*glb_bin));
      glb_bin = nullptr;
      continue;
    }
    std::string uri = b["uri"].get<std::string>();
    if (uri.rfind("data:", 0) == 0) {
      auto data = decode_data_uri(uri, nullptr);
      if (!data.ok()) return data.status().with_context(g->path);
      g->buffers.push_back(std::move(data).value());
    } else {
      auto data = read_file(folder + percent_decode(uri));
      if (!data.ok()) return data.status().with_context(g->path + ": buffer");
      g->buffers.push_back(std::move(data).value());
    }
    size_t declared = b.value("byteLength", size_t{0});
    if (g->buffers.back().size() < declared)
      return g->fail("buffer '" + uri.substr(0, 64) + "' is shorter than its byteLength");
  }
  return Status::Ok();
}

Status view_bytes(const Gltf& g, size_t view_index, const uint8_t** data, size_t* size,
                  size_t* stride) {
  const json& views = g.doc["bufferViews"];
  if (!views.is_array() || view_index >= views.size())
    return g.fail("bufferView " + std::to_string(view_index) + " does not exist");
  const json& v = views[view_index];
  size_t buffer = v.value("buffer", size_t{0});
  size_t offset = v.value("byteOffset", size_t{0});
  size_t length = v.value("byteLength", size_t{0});
  if (buffer >= g.buffers.size())
    return g.fail("bufferView " + std::to_string(view_index) + ": no buffer");
  if (offset > g.buffers[buffer].size() || length > g.buffers[buffer].size() - offset)
    return g.fail("bufferView " + std::to_string(view_index) + " runs past its buffer");
  *data = g.buffers[buffer].data() + offset;
  *size = length;
  if (stride) *stride = v.value("byteStride", size_t{0});
  return Status::Ok();
}

namespace {

int component_count(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4") return 4;
  if (type == "MAT4") return 16;
  return 0;
}

size_t component_size(int ct) {
  switch (ct) {
    case 5120:
    case 5121:
      return 1;
    case 5122:
    case 5123:
      return 2;
    case 5125:
    case 5126:
      return 4;
  }
  return 0;
}

double read_component(const uint8_t* p, int ct, bool normalized) {
  switch (ct) {
    case 5120: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case 5121:
      return normalized ? *p / 255.0 : *p;
    case 5122: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case 5123: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case 5125:
      return read_u32(p);
    case 5126: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
  return 0;
}

}  // namespace

Status read_accessor(const Gltf& g, size_t index, int comps, std::vector<double>* out,
                     size_t* count) {
  const json& accessors = g.doc["accessors"];
  if (!accessors.is_array() || index >= accessors.size())
    return g.fail("accessor " + std::to_string(index) + " does not exist");
  const json& a = accessors[index];
  std::string where = "accessor " + std::to_string(index);
  size_t n = a.value("count", size_t{0});
  int ct = a.value("componentType", 0);
  int nc = component_count(a.value("type", std::string()));
  size_t cs = component_size(ct);
  if (nc == 0 || cs == 0) return g.fail(where + ": unknown type or componentType");
  if (a.contains("sparse"))
    return Error(ErrorCode::kUnsupported,
                 g.path + ": " + where + ": sparse accessors are not supported");
  bool normalized = a.value("normalized", false);
  *count = n;
  if (n > (size_t{1} << 31)) return g.fail(where + ": count too large");
  out->assign(n * comps, 0.0);
  if (!a.contains("bufferView")) return Status::Ok();  // all zeros, per the spec
  const uint8_t* data;
  size_t size, stride;
  VT_RETURN_IF_ERROR(view_bytes(g, a["bufferView"].get<size_t>(), &data, &size, &stride));
  size_t offset = a.value("byteOffset", size_t{0});
  size_t elem = cs * nc;
  if (stride == 0) stride = elem;
  if (n > 0 && (offset > size || (n - 1) > (size - offset) / stride ||
                (n - 1) * stride + elem > size - offset))
    return g.fail(where + " runs past its bufferView");
  int take = std::min(comps, nc);
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* e = data + offset + i * stride;
    for (int k = 0; k < take; ++k)
      (*out)[i * comps + k] = read_component(e + k * cs, ct, normalized);
  }
  return Status::Ok();
}

}  // namespace vt::scene::detail
