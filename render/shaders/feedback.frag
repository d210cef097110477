#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// Feedback pass: one page request per pixel, bits 0-11 page x, 12-23 page y, 24-28 level.
// Each pixel reports one of its taps, rotated by pixel and frame, so that over kTaps frames
// every tap's page is requested.
layout(location = 0) in vec2 v_uv;
layout(location = 0) out uint out_request;

void main() {
  Footprint f = footprint(v_uv, pc.tex.z);
  int level = int(floor(f.lod));
  int tap = (pc.misc.x + int(gl_FragCoord.x) + 2 * int(gl_FragCoord.y)) & (kTaps - 1);
  vec2 uv = tap_uv(v_uv, f, tap);
  ivec2 size = max(ivec2(1), (ivec2(pc.tex.xy) + (1 << level) - 1) >> level);
  ivec2 pages = (size + pc.vt.y - 1) / pc.vt.y;
  ivec2 page = clamp(ivec2(floor(uv * vec2(size) / float(pc.vt.y))), ivec2(0), pages - 1);
  out_request = uint(page.x) | (uint(page.y) << 12) | (uint(level) << 24);
}
