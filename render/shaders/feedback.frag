#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "virtual_texture.glsl"

// Feedback pass: one page request per pixel, bits 0-11 page x, 12-23 page y, 24-28 level.
// Each pixel reports one of its taps, rotated by pixel and frame, so that over f.taps frames
// every tap's page is requested. Alpha-tested as the virtual pass, with what is resident, so
// that surfaces seen through holes request their pages; a hole counts only once the level the
// pixel wants is resident (a coarser alpha may close or open it wrongly).
layout(set = 0, binding = 0) uniform sampler2D u_cache;
layout(set = 0, binding = 1) uniform usampler2D u_page_table;

layout(location = 0) in vec2 v_uv;
layout(location = 0) out uint out_request;

void main() {
  Footprint f = footprint(v_uv, pc.tex.z);
  int level = int(floor(f.lod));
  if (v_alpha_cutoff >= 0.0 && v_misc.w != 1) {
    int sampled;
    vec4 c = vt_filtered(u_cache, u_page_table, v_uv, f, sampled);
    if (sampled <= level && c.a < v_alpha_cutoff) discard;
  }
  int tap = (v_misc.x + int(gl_FragCoord.x) + 2 * int(gl_FragCoord.y)) % f.taps;
  ivec2 page = vt_page(tap_uv(v_uv, f, tap), level);
  out_request = uint(page.x) | (uint(page.y) << 12) | (uint(level) << 24);
}
