#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// Reference path: the original texture (base colour x factor, sRGB) with an ordinary mip chain,
// a trilinear sampler (the material's own where it has one) and the vertex colour (linear RGBA),
// which multiplies in linear light as the bake does (scene::base_color).
layout(set = 0, binding = 0) uniform sampler2D u_texture;

layout(location = 0) in vec2 v_uv;
layout(location = 1) in vec4 v_color;
layout(location = 0) out vec4 out_color;
layout(location = 1) out uint out_covered;  // bit 0 where a fragment survived the alpha test

// The sRGB curve of common/srgb.h (IEC 61966-2-1).
vec3 srgb_to_linear(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}
vec3 linear_to_srgb(vec3 c) {
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, greaterThan(c, vec3(0.0031308)));
}

void main() {
  Footprint f = footprint(v_uv, 1.0);
  vec4 c = vec4(0.0);
  for (int i = 0; i < f.taps; ++i) c += textureLod(u_texture, tap_uv(v_uv, f, i), f.lod);
  c /= float(f.taps);
  // Skipped for white so that scenes without vertex colours render exactly as before.
  if (v_color.rgb != vec3(1.0)) {
    c.rgb = linear_to_srgb(clamp(srgb_to_linear(c.rgb) * v_color.rgb, 0.0, 1.0));
  }
  c.a *= v_color.a;
  if (v_alpha_cutoff >= 0.0 && c.a < v_alpha_cutoff) discard;
  if (alpha_blended()) c.rgb *= c.a;
  out_color = c;
  // Bit 1: alpha-tested with alpha within kAlphaEdge of the cutoff (virtual.frag's bit 30).
  out_covered = v_alpha_cutoff >= 0.0 && c.a < v_alpha_cutoff + kAlphaEdge ? 3u : 1u;
}
