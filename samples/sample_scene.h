// The sample scene the project makes itself: procedural meshes (ground, boxes instanced three
// times, a UV sphere, a torus, an alpha-masked card) and procedural textures with fine detail
// (sRGB PNG base colours, a linear EXR base colour, normal, metallic-roughness, occlusion and
// emissive maps), so `vtbake bake` has something real to bake with no download.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "common/status.h"
#include "scene/scene.h"

namespace vt {

struct SampleSceneOptions {
  uint32_t ground_cells = 16;     // ground grid cells per side (2 triangles each)
  uint32_t sphere_segments = 48;  // UV sphere: segments around, segments / 2 rings
  uint32_t texture_size = 512;    // side of every generated texture
  // The lit variant: a sun, a point light and a spot light (KHR_lights_punctual, listed in
  // extensionsRequired as a lit level's export lists it), so a bake gets a lighting layer.
  bool lights = false;
};

// Writes DIR/scene.gltf, DIR/scene.bin and the textures (PNG, one EXR). Creates DIR.
Status write_sample_scene(const std::string& dir, const SampleSceneOptions& options = {});

// Procedural meshes (normals and TEXCOORD_0, glTF orientation: v down), material index 0.
scene::Primitive make_grid(float size, uint32_t cells, float uv_repeat);  // y = 0, facing +y
scene::Primitive make_box(float sx, float sy, float sz);  // each face maps the whole [0,1]^2
scene::Primitive make_uv_sphere(float radius, uint32_t segments);
scene::Primitive make_torus(float major, float minor, uint32_t segments);

// A texture function sampled at texel centres, values in [0,1] (or above for HDR), written
// with OpenImageIO (format from the extension; 8-bit formats are rounded).
Status write_texture(const std::string& path, uint32_t width, uint32_t height, uint32_t channels,
                     const std::function<void(double u, double v, float* out)>& texel);

}  // namespace vt
