// The glTF 2.0 material rules that the bake (bake/transfer.cpp) and the validator's reference
// pass (render/scene_draws.cpp) both follow, kept in one place so that validation measures the
// bake and not a second reading of the spec: which UV set a texture reads, KHR_texture_transform,
// the sampler's wrap modes, base colour from factor, texture and vertex colour, the alpha test.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace vt::scene {

// How messages name a material: "material 'NAME'", "material INDEX (unnamed)", or "the default
// material" (index < 0: a primitive without one). The second form finds `m` in `scene`.
std::string material_label(const std::string& name, int64_t index);
std::string material_label(const Scene& scene, const Material& m);

// The UV set a texture slot reads (TEXCOORD_n after KHR_texture_transform's texCoord override),
// or nullptr when the primitive lacks it or the set is shorter than the positions.
const std::vector<Vec2>* texture_uv_set(const Primitive& p, const TextureRef& ref);

// Where a slot samples for mesh UV (u, v): the slot's KHR_texture_transform applied. Affine, so
// transforming each vertex and interpolating equals transforming each sample.
std::array<double, 2> texture_uv(const TextureRef& ref, double u, double v);

// UV derivatives {du/dx, dv/dx, du/dy, dv/dy} through the transform's linear part.
std::array<double, 4> texture_uv_derivatives(const TextureRef& ref, std::array<double, 4> d);

// A texture coordinate brought into [0, 1] as the sampler's wrap mode addresses it: REPEAT keeps
// the fraction, MIRRORED_REPEAT reflects every other period, CLAMP_TO_EDGE clamps.
double wrap_coordinate(WrapMode mode, double x);
// Texel index i of a level n texels wide (n > 0), addressed as the wrap mode says: the integer
// form of wrap_coordinate for texel lookups.
int64_t wrap_texel(WrapMode mode, int64_t i, int64_t n);

// Base colour in linear light, as glTF 2.0 defines it: factor x texture x vertex colour (COLOR_0,
// {1, 1, 1, 1} when absent). Alpha is 1 for OPAQUE materials whatever the inputs hold.
// Inline: the transfer calls it for every sample.
inline Vec4 base_color(const Material& m, const Vec4& texture, const Vec4& vertex_color) {
  Vec4 c;
  for (int i = 0; i < 4; ++i) c[i] = texture[i] * m.base_color_factor[i] * vertex_color[i];
  if (m.alpha_mode == AlphaMode::kOpaque) c[3] = 1;
  return c;
}

// The alpha test a material asks for: its cutoff in MASK mode, negative otherwise.
float alpha_test_cutoff(const Material& m);

}  // namespace vt::scene
