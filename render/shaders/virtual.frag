#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// Virtual-texture final pass: page-table lookup (texelFetch on the RGBA8 mip chain: R, G =
// physical slot, B = resident level, A bit 0 = valid), bilinear taps in the bordered physical
// cache, trilinear as two levels and a blend, the same 4x anisotropic taps as the reference.
layout(set = 0, binding = 0) uniform sampler2D u_cache;  // linear, one mip, clamp
layout(set = 0, binding = 1) uniform usampler2D u_page_table;

layout(location = 0) in vec2 v_uv;
layout(location = 0) out vec4 out_color;
// bit 31 covered; bits 0-7 wanted level; bits 8-15 coarsest level a fine tap sampled.
layout(location = 1) out uint out_status;

ivec2 level_size(int level) {
  return max(ivec2(1), (ivec2(pc.tex.xy) + (1 << level) - 1) >> level);
}

vec4 sample_level(vec2 uv, int level, inout int sampled) {
  float payload = float(pc.vt.y);
  ivec2 size = level_size(level);
  ivec2 pages = (size + pc.vt.y - 1) / pc.vt.y;
  ivec2 page = clamp(ivec2(floor(uv * vec2(size) / payload)), ivec2(0), pages - 1);
  uvec4 e = texelFetch(u_page_table, page, level);
  if ((e.a & 1u) == 0u) {
    sampled = 31;
    return vec4(1.0, 0.0, 1.0, 1.0);  // nothing resident at all: a loud colour
  }
  int resident = int(e.b);
  int up = max(resident - level, 0);
  // The slot holds the ancestor page; address its texels in the resident level.
  ivec2 rpage = page >> up;
  vec2 local = uv * vec2(level_size(resident)) - vec2(rpage) * payload;
  float lo = 0.5 - float(pc.vt.z);
  local = clamp(local, vec2(lo), vec2(payload - lo));
  vec2 phys = vec2(e.rg) * float(pc.vt.w) + float(pc.vt.z) + local;
  sampled = max(sampled, resident);
  return textureLod(u_cache, phys / vec2(textureSize(u_cache, 0)), 0.0);
}

void main() {
  Footprint f = footprint(v_uv, 1.0);
  int l0 = int(floor(f.lod));
  int l1 = min(l0 + 1, pc.misc.z);
  float blend = f.lod - float(l0);
  int sampled = 0;
  int ignored = 0;
  vec4 c = vec4(0.0);
  for (int i = 0; i < kTaps; ++i) {
    vec2 uv = tap_uv(v_uv, f, i);
    vec4 a = sample_level(uv, l0, sampled);
    vec4 b = l1 != l0 ? sample_level(uv, l1, ignored) : a;
    c += mix(a, b, blend);
  }
  c /= float(kTaps);
  if (pc.tex.w >= 0.0 && c.a < pc.tex.w) discard;
  out_color = c;
  out_status = 0x80000000u | uint(l0) | (uint(sampled) << 8);
}
