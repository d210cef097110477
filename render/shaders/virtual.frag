#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "virtual_texture.glsl"

// Virtual-texture final pass: page-table lookup and bilinear taps in the bordered physical cache
// (virtual_texture.glsl), trilinear as two levels and a blend, the same 4x anisotropic taps as
// the reference.
layout(set = 0, binding = 0) uniform sampler2D u_cache;  // linear, one mip, clamp
layout(set = 0, binding = 1) uniform usampler2D u_page_table;

layout(location = 0) in vec2 v_uv;
layout(location = 0) out vec4 out_color;
// bit 31 covered; bit 30 alpha-tested with alpha within kAlphaEdge of the cutoff; bit 29 a tap
// read page border texels; bit 28 a coarse-level tap read an ancestor; bits 0-7 wanted level;
// bits 8-15 coarsest level a fine tap sampled.
layout(location = 1) out uint out_status;

void main() {
  Footprint f = footprint(v_uv, 1.0);
  int sampled;
  vec4 c = vt_filtered(u_cache, u_page_table, v_uv, f, sampled);
  const bool tested = v_alpha_cutoff >= 0.0 && v_misc.w != 1;
  if (tested && c.a < v_alpha_cutoff) discard;
  bool edge = tested && c.a < v_alpha_cutoff + kAlphaEdge;
  if (v_misc.w == 1) c.rgb = max(c.rgb, vec3(0.0)) / (1.0 + max(c.rgb, vec3(0.0)));
  else if (alpha_blended()) c.rgb *= c.a;
  out_color = c;
  // The status bits: VirtualFrame::kStatus* (render/renderer.h).
  out_status = 0x80000000u | (edge ? 0x40000000u : 0u) |
               (vt_border_read ? 0x20000000u : 0u) | (vt_coarse_fallback ? 0x10000000u : 0u) | uint(int(floor(f.lod))) |
               (uint(sampled) << 8);
}
