// glTF 2.0 export: one document built from a Scene, written in either container. A .glb holds
// the JSON and one BIN chunk; a .gltf is the JSON as text with that same buffer in a .bin file
// beside it. The buffer holds every attribute, index list and embedded image.
#pragma once

#include <string>

#include "common/status.h"
#include "scene/scene.h"

namespace vt::scene {

// Choices the scene does not make: every setting gives valid glTF. A caller keeps its
// settings fixed so that writing a scene again gives the same bytes (users hash these files).
struct GltfWriteOptions {
  std::string generator = "vtbake";  // asset.generator
  bool write_texcoord_0 = false;     // "texCoord": 0 in texture references (glTF's default)
  bool write_single_sided = false;   // "doubleSided": false on materials (glTF's default)
  bool write_opaque = true;          // "alphaMode": "OPAQUE" on materials (glTF's default)
  bool sampler_filters = false;      // LINEAR magnification, LINEAR_MIPMAP_LINEAR minification
  // TANGENT from each primitive's last UV set (the atlas set the unwrapper appends), in the
  // frame the bake's normal layer is expressed in (compute_tangents on the atlas UVs), so an
  // engine sampling the baked normal layer decodes it right. Tangents the primitive carried
  // for its source normal map are kept as the application attribute _SOURCE_TANGENT.
  bool atlas_tangents = false;
  // KHR_lights_punctual in extensionsRequired too, not only extensionsUsed (as level exports
  // whose look depends on their lights list it).
  bool lights_required = false;
};

// Writes the document as glTF 2.0 text at PATH and its buffer at PATH's stem + ".bin" in the
// same folder. File images keep their uri, rewritten relative to PATH's folder when possible;
// embedded images go into the buffer. Each file appears under its name only once complete.
// save_glb (scene.h) writes the same document, with the default options, as one .glb.
Status save_gltf(const Scene& scene, const std::string& path, const GltfWriteOptions& options = {});

// save_glb (scene.h) with options: the unwrapped scene of a bake is written with atlas_tangents.
Status save_glb(const Scene& scene, const std::string& path, const GltfWriteOptions& options);

}  // namespace vt::scene
