#version 450
#extension GL_GOOGLE_include_directive : require
#define VT_VERTEX_STAGE
#include "common.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec2 in_uv;
layout(location = 0) out vec2 v_uv;

void main() {
  gl_Position = pc.mvp * vec4(in_position, 1.0);
  v_uv = in_uv;
}
