#version 450
#extension GL_GOOGLE_include_directive : require
#define VT_VERTEX_STAGE
#include "common.glsl"

// Positions and frames are already in world space (instances flattened on the CPU).
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec2 in_uv;
layout(location = 2) in vec4 in_color;
layout(location = 3) in vec3 in_normal;
layout(location = 4) in vec4 in_tangent;
layout(location = 5) in vec4 in_tex_uv01;  // the lit reference's normal and occlusion UVs
layout(location = 6) in vec4 in_tex_uv23;  // its metallic-roughness and emissive UVs
layout(location = 0) out vec2 v_uv;
layout(location = 1) out vec4 v_color;
layout(location = 2) out vec3 v_normal;
layout(location = 3) out vec4 v_tangent;
layout(location = 4) out vec3 v_world;
layout(location = 5) out vec4 v_tex_uv01;
layout(location = 6) out vec4 v_tex_uv23;
layout(location = 7) flat out ivec4 v_misc;  // common.glsl: the fragment stages branch on these
layout(location = 8) flat out float v_alpha_cutoff;

void main() {
  gl_Position = pc.mvp * vec4(in_position, 1.0);
  v_uv = in_uv;
  v_color = in_color;
  v_normal = in_normal;
  v_tangent = in_tangent;
  v_world = in_position;
  v_tex_uv01 = in_tex_uv01;
  v_tex_uv23 = in_tex_uv23;
  v_misc = pc.misc;
  v_alpha_cutoff = pc.tex.w;
}
