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

// One bilinear tap of a page file's level (v_misc.w == 1): it lies in the top-left corner of
// mip `level`, which the padding makes a little larger (render/streaming_check.cpp). The mip's
// size is level 0's shifted (the padded sizes halve exactly), not textureSize(u_texture, level):
// lavapipe answers that query for one pixel's level per group of pixels, and at silhouettes,
// where neighbours want different levels, taps landed up to 60 steps off.
vec4 file_level_tap(vec2 uv, int level) {
  vec2 scale = vec2(vt_level_size(level)) / vec2(textureSize(u_texture, 0) >> level);
  return textureLod(u_texture, uv * scale, float(level));
}

void main() {
  Footprint f = footprint(v_uv, 1.0);
  vec4 c = vec4(0.0);
  if (v_misc.w == 1) {
    // Two levels blended as the virtual texture's taps are (virtual_texture.glsl, vt_filtered).
    int l0 = int(floor(f.lod));
    int l1 = min(l0 + 1, v_misc.z);
    float blend = f.lod - float(l0);
    for (int i = 0; i < f.taps; ++i) {
      vec2 t = tap_uv(v_uv, f, i);
      vec4 a = file_level_tap(t, l0);
      c += l1 != l0 ? mix(a, file_level_tap(t, l1), blend) : a;
    }
  } else {
    for (int i = 0; i < f.taps; ++i) c += textureLod(u_texture, tap_uv(v_uv, f, i), f.lod);
  }
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
