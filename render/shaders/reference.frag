#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// Reference path: the original texture with an ordinary mip chain and a trilinear sampler.
layout(set = 0, binding = 0) uniform sampler2D u_texture;

layout(location = 0) in vec2 v_uv;
layout(location = 0) out vec4 out_color;
layout(location = 1) out uint out_covered;  // 1 where a fragment survived the alpha test

void main() {
  Footprint f = footprint(v_uv, 1.0);
  vec4 c = vec4(0.0);
  for (int i = 0; i < kTaps; ++i) c += textureLod(u_texture, tap_uv(v_uv, f, i), f.lod);
  c /= float(kTaps);
  if (pc.tex.w >= 0.0 && c.a < pc.tex.w) discard;
  out_color = c;
  out_covered = 1u;
}
