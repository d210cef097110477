// What the scene fuzz targets share: a loaded scene is walked the way the baker walks it, and a
// refusal must be an input error naming the file.
#pragma once

#include <string>

#include "fuzz/fuzz_input.h"
#include "scene/scene.h"

namespace vt::fuzz {

// The contract scene.h states for every importer's output.
inline void check_primitive(const scene::Scene& scene, const scene::Primitive& p) {
  const size_t n = p.positions.size();
  auto sized = [n](size_t size) { return size == 0 || size == n; };
  if (!sized(p.normals.size()) || !sized(p.tangents.size()) || !sized(p.colors.size()))
    finding("attribute count differs from the positions'", scene.source_path);
  for (const auto& uv : p.uvs)
    if (!sized(uv.size())) finding("UV count differs from the positions'", scene.source_path);
  if (p.indices.size() % 3 != 0) finding("index count not a multiple of 3", scene.source_path);
  if (p.material < -1 || p.material >= int(scene.materials.size()))
    finding("material index out of range", scene.source_path);
}

inline void load_and_walk(const std::string& path) {
  auto scene = scene::load_scene(path);
  if (!scene.ok()) return check_refusal(scene.status(), path);
  for (const scene::Mesh& mesh : scene->meshes)
    for (const scene::Primitive& p : mesh.primitives) check_primitive(*scene, p);
  check_refusal(scene::validate_geometry(*scene), "");
  for (const scene::Instance& instance : scene->instances())
    if (instance.mesh < 0 || size_t(instance.mesh) >= scene->meshes.size())
      finding("instance of a mesh that does not exist", std::to_string(instance.mesh));
  (void)scene->triangle_count();
}

}  // namespace vt::fuzz
