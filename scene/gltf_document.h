// The pieces of the glTF 2.0 importer shared by its files: the parsed document with its
// buffers, bounds-checked buffer views (EXT_meshopt_compression views decoded in
// gltf_meshopt.cpp) and accessors (gltf_accessors.cpp: sparse, KHR_mesh_quantization types),
// and primitives (gltf_primitive.cpp). Every count is checked against the bytes behind it and
// the ceilings of import_budget.h before anything is allocated. Internal to vt_scene.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/import_budget.h"
#include "scene/scene.h"

namespace vt::scene::detail {

// The asset.version of a glTF document as text ("" when absent): 1.0 files often write it as a
// number.
std::string gltf_version_text(const nlohmann::json& doc);
// glTF 1.0 or a 0.x draft: top-level collections in objects keyed by id (2.0 uses arrays), or
// an asset.version of 1.x or 0.x. The own importer reads 2.0 only; assimp reads 1.0.
bool is_gltf1_document(const nlohmann::json& doc);

struct Gltf {
  std::string path;
  SceneLoadOptions options;
  nlohmann::json doc;
  std::vector<std::vector<uint8_t>> buffers;  // a placeholder buffer (no uri) is empty
  // bufferView index -> its bytes decoded from EXT_meshopt_compression.
  std::map<size_t, std::vector<uint8_t>> decoded_views;

  Status fail(const std::string& what) const {
    return Error(ErrorCode::kCorrupt, path + ": " + what);
  }
};

// obj[key], or null when obj is no object or lacks the key (never throws, never inserts).
const nlohmann::json& member(const nlohmann::json& obj, const char* key);

// obj[key] as a non-negative integer; `fallback` when absent. Anything else (negative,
// fractional, a string) is an error naming `where` and the key.
Expected<size_t> size_field(const Gltf& g, const nlohmann::json& obj, const char* key,
                            size_t fallback, const std::string& where);

// Loads every buffer of g->doc: the .glb's BIN chunk (glb_bin, moved from), data: URIs and
// files next to the document; a buffer without uri (the EXT_meshopt_compression fallback) stays
// empty. Then decodes the EXT_meshopt_compression buffer views.
Status load_buffers(Gltf* g, std::vector<uint8_t>* glb_bin);

// Decodes every bufferView that has EXT_meshopt_compression into g->decoded_views
// (gltf_meshopt.cpp).
Status decode_meshopt_views(Gltf* g);

// The bytes of a buffer view (decoded when compressed), bounds-checked; stride 0 = tightly
// packed.
Status view_bytes(const Gltf& g, size_t view_index, const uint8_t** data, size_t* size,
                  size_t* stride);

// glTF componentType values.
enum ComponentType : int {
  kByte = 5120,
  kUnsignedByte = 5121,
  kShort = 5122,
  kUnsignedShort = 5123,
  kUnsignedInt = 5125,
  kFloat = 5126,
};

// A checked accessor: `count` elements of `components` values. Sparse substitution is already
// applied (into `owned`); data is null for an accessor of zeros (no bufferView, no sparse).
// Move-only: data may point into owned.
struct AccessorView {
  size_t index = 0;
  size_t count = 0;
  int components = 0;  // SCALAR 1 .. VEC4 4, MAT4 16
  int component_type = 0;
  bool normalized = false;
  const uint8_t* data = nullptr;
  size_t stride = 0;
  std::vector<uint8_t> owned;

  AccessorView() = default;
  AccessorView(AccessorView&&) = default;
  AccessorView& operator=(AccessorView&&) = default;
  AccessorView(const AccessorView&) = delete;
  AccessorView& operator=(const AccessorView&) = delete;

  // Component k of element i; normalised integers map to [0, 1] or [-1, 1] as glTF says.
  double value(size_t i, int k) const;
  // "5126" as the spec's words: "float", "normalized unsigned byte", ...
  std::string format_name() const;
};

// Opens accessor `index`, refusing a count above max_count (kMaxVertices for attributes,
// kMaxIndices for indices) or one its bytes cannot back, before allocating. Errors read
// "FILE: CONTEXT: accessor N: ..." (context: who reads it, e.g. "mesh 0 primitive 1: NORMAL").
Expected<AccessorView> open_accessor(const Gltf& g, size_t index, uint64_t max_count,
                                     const std::string& context = "");

// Reads a checked accessor as N floats per element (missing components left 0).
template <size_t N>
void read_vec(const AccessorView& a, std::vector<std::array<float, N>>* out) {
  out->assign(a.count, {});
  int take = std::min(static_cast<int>(N), a.components);
  for (size_t i = 0; i < a.count; ++i)
    for (int k = 0; k < take; ++k) (*out)[i][k] = static_cast<float>(a.value(i, k));
}

// Opens accessor `index` as a vertex attribute and reads it as N floats per element.
template <size_t N>
Status read_vec(const Gltf& g, size_t index, std::vector<std::array<float, N>>* out) {
  VT_ASSIGN_OR_RETURN(AccessorView a, open_accessor(g, index, kMaxVertices));
  read_vec(a, out);
  return Status::Ok();
}

// One mesh primitive (attributes, indices as a triangle list, Draco-compressed or not).
Expected<Primitive> load_primitive(const Gltf& g, const nlohmann::json& p,
                                   const std::string& where);

}  // namespace vt::scene::detail
