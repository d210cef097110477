// The pieces of the glTF 2.0 importer shared by its files: the parsed document with its
// buffers, bounds-checked buffer views and accessors (gltf_accessors.cpp), and primitives
// (gltf_primitive.cpp). Internal to vt_scene.
#pragma once

#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace vt::scene::detail {

struct Gltf {
  std::string path;
  nlohmann::json doc;
  std::vector<std::vector<uint8_t>> buffers;

  Status fail(const std::string& what) const {
    return Error(ErrorCode::kCorrupt, path + ": " + what);
  }
};

uint32_t read_u32(const uint8_t* p);

// Loads every buffer of g->doc: the .glb's BIN chunk (glb_bin, moved from), data: URIs and
// files next to the document.
Status load_buffers(Gltf* g, std::vector<uint8_t>* glb_bin);

// The bytes of a buffer view, bounds-checked; stride 0 = tightly packed.
Status view_bytes(const Gltf& g, size_t view_index, const uint8_t** data, size_t* size,
                  size_t* stride);

// Reads accessor `index` as doubles, `comps` per element (missing components left 0).
Status read_accessor(const Gltf& g, size_t index, int comps, std::vector<double>* out,
                     size_t* count);

template <int N>
Status read_vec(const Gltf& g, size_t index, std::vector<std::array<float, N>>* out) {
  std::vector<double> raw;
  size_t n;
  VT_RETURN_IF_ERROR(read_accessor(g, index, N, &raw, &n));
  out->resize(n);
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < N; ++k) (*out)[i][k] = static_cast<float>(raw[i * N + k]);
  return Status::Ok();
}

// One mesh primitive (attributes, indices as a triangle list, Draco-compressed or not).
Expected<Primitive> load_primitive(const Gltf& g, const nlohmann::json& p,
                                   const std::string& where);

}  // namespace vt::scene::detail
